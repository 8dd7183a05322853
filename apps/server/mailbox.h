// The worker thread's queue. Jobs run in the order they arrive, except that a frame waiting in
// the queue is replaced by a newer frame (latest wins): a drag never makes the solver fall
// behind the mouse, and nothing else (a selection, a settings change) is ever dropped.
#pragma once

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>

namespace specdeform::server {

class Mailbox {
 public:
  using Job = std::function<void()>;

  // `is_frame`: the job may be replaced by a later frame while it waits.
  void push(Job job, bool is_frame) {
    {
      std::lock_guard lock(mutex_);
      if (closed_) return;
      if (is_frame && !jobs_.empty() && jobs_.back().is_frame) {
        jobs_.back().job = std::move(job);
        ++coalesced_;
      } else {
        jobs_.push_back({std::move(job), is_frame});
      }
    }
    ready_.notify_one();
  }

  // The next job; waits for one. Empty once close() was called.
  std::optional<Job> pop() {
    std::unique_lock lock(mutex_);
    ready_.wait(lock, [&] { return closed_ || !jobs_.empty(); });
    if (closed_) return std::nullopt;
    Job job = std::move(jobs_.front().job);
    jobs_.pop_front();
    return job;
  }

  void close() {
    {
      std::lock_guard lock(mutex_);
      closed_ = true;
      jobs_.clear();
    }
    ready_.notify_all();
  }

  // Frames replaced before they ran.
  long coalesced() const {
    std::lock_guard lock(mutex_);
    return coalesced_;
  }

 private:
  struct Entry {
    Job job;
    bool is_frame;
  };
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<Entry> jobs_;
  bool closed_ = false;
  long coalesced_ = 0;
};

}  // namespace specdeform::server
