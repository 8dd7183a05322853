// Internal: the two-way parallelism of the per-frame loops (this library targets two cores).
//
// A helper thread is kept for them: starting a thread costs about 50 us, a frame's loop about
// 500 us. Between jobs it polls (yielding) for a short while, then sleeps. It runs one job at a
// time; a caller that finds it busy (another deformer on another
// thread) starts a thread of its own. There is one helper per scheduling priority (Linux's nice
// value, a thread's own, which the threads it starts inherit): a background thread that lowered
// its priority (the transfer's factorisation) is helped at its priority, and a caller at the
// normal one never waits for a helper that a busy machine starves. Either way the two halves run at
// the same time, so they may synchronise with each other (a std::barrier). HelperThread's jobs must
// not throw; run_pair and split_in_two carry their functions' exceptions back to the caller.
#pragma once

#include <atomic>
#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

#include <Eigen/Core>

namespace specdeform::detail {

class HelperThread {
 public:
  // The helper of the calling thread's priority, started by the first caller of that priority.
  static HelperThread& instance();
  ~HelperThread();

  // Runs `here` on the calling thread and `there` on the helper, at the same time.
  void run(const std::function<void()>& here, const std::function<void()>& there);

 private:
  HelperThread();
  void loop();

  std::mutex busy_;  // held by the caller of run()
  std::atomic<const std::function<void()>*> job_{nullptr};
  std::mutex mutex_;              // guards the sleeps
  std::condition_variable wake_;  // the helper's, for a job
  std::condition_variable done_;  // the caller's, for the helper's half
  bool sleeping_ = false;
  bool waiting_ = false;
  bool stop_ = false;
  std::thread thread_;
};

// Runs first() and second() at the same time, on two threads. An exception of either is
// rethrown once both have ended (first()'s where both throw).
template <typename First, typename Second>
void run_pair(First&& first, Second&& second) {
  std::exception_ptr failed[2];
  HelperThread::instance().run(
      [&] {
        try {
          first();
        } catch (...) {
          failed[0] = std::current_exception();
        }
      },
      [&] {
        try {
          second();
        } catch (...) {
          failed[1] = std::current_exception();
        }
      });
  for (const std::exception_ptr& e : failed)
    if (e) std::rethrow_exception(e);
}

// Runs body(begin, end) on [0, n) in two halves at the same time.
template <typename Body>
void split_in_two(Eigen::Index n, Body&& body) {
  const Eigen::Index half = n / 2;
  run_pair([&] { body(half, n); }, [&] { body(Eigen::Index{0}, half); });
}

}  // namespace specdeform::detail
