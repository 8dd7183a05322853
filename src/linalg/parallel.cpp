#include "parallel.h"

#include <cerrno>
#include <chrono>
#include <map>
#include <memory>

#if defined(__linux__)
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

namespace specdeform::detail {

namespace {

// How long the helper keeps polling for the next job, and the caller for the helper's half,
// before it sleeps: a frame's parallel loops come a few hundred microseconds apart, and waking a
// sleeping thread costs tens of them; polling longer burns a core another program could use
// (sched_yield was 3-4% of a 692k bind's samples).
constexpr auto kPoll = std::chrono::microseconds(300);

// The calling thread's nice value (0 where threads have no priority of their own).
int thread_nice() {
#if defined(__linux__)
  errno = 0;
  const int nice = getpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)));
  return errno == 0 ? nice : 0;
#else
  return 0;
#endif
}

}  // namespace

HelperThread& HelperThread::instance() {
  static std::mutex mutex;
  static std::map<int, std::unique_ptr<HelperThread>> helpers;  // by nice value
  const int nice = thread_nice();
  std::lock_guard lock(mutex);
  std::unique_ptr<HelperThread>& helper = helpers[nice];
  if (!helper) helper.reset(new HelperThread());  // started here: it inherits this priority
  return *helper;
}

HelperThread::HelperThread() : thread_([this] { loop(); }) {}

HelperThread::~HelperThread() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

void HelperThread::loop() {
  for (;;) {
    const auto until = std::chrono::steady_clock::now() + kPoll;
    while (job_.load(std::memory_order_acquire) == nullptr &&
           std::chrono::steady_clock::now() < until) {
      std::this_thread::yield();
    }
    if (job_.load(std::memory_order_acquire) == nullptr) {
      std::unique_lock lock(mutex_);
      sleeping_ = true;
      wake_.wait(lock, [&] { return stop_ || job_.load() != nullptr; });
      sleeping_ = false;
      if (stop_) return;
    }
    (*job_.load())();
    bool notify = false;
    {
      std::lock_guard lock(mutex_);
      job_.store(nullptr, std::memory_order_release);
      notify = waiting_;
    }
    if (notify) done_.notify_one();
  }
}

void HelperThread::run(const std::function<void()>& here, const std::function<void()>& there) {
  std::unique_lock busy(busy_, std::try_to_lock);
  if (!busy) {
    std::thread other(there);
    here();
    other.join();
    return;
  }
  {
    std::lock_guard lock(mutex_);
    job_.store(&there, std::memory_order_release);
    if (sleeping_) wake_.notify_one();
  }
  here();
  const auto until = std::chrono::steady_clock::now() + kPoll;
  while (job_.load(std::memory_order_acquire) != nullptr &&
         std::chrono::steady_clock::now() < until) {
    std::this_thread::yield();
  }
  if (job_.load(std::memory_order_acquire) != nullptr) {
    std::unique_lock lock(mutex_);
    waiting_ = true;
    done_.wait(lock, [&] { return job_.load() == nullptr; });
    waiting_ = false;
  }
}

}  // namespace specdeform::detail
