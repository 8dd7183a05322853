#include "parallel.h"

#include <chrono>

namespace specdeform::detail {

namespace {

// How long the helper keeps polling for the next job before it sleeps: a frame's parallel loops
// come a few hundred microseconds apart, and waking a sleeping thread costs tens of them.
constexpr auto kPoll = std::chrono::microseconds(300);

}  // namespace

HelperThread& HelperThread::instance() {
  static HelperThread helper;
  return helper;
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
    job_.store(nullptr, std::memory_order_release);
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
  while (job_.load(std::memory_order_acquire) != nullptr) std::this_thread::yield();
}

}  // namespace specdeform::detail
