// Internal: where a computation's time goes, by the stages its progress names. StageClock wraps
// a ProgressCallback (the caller's, which may be empty) so that each change of the stage's name
// closes the last stage's wall-clock time and opens the next; a stage met again (each piece of
// a mesh of several pieces passes through the same stages) adds to its sum, keeping the order
// in which stages first came. Callbacks may come from any thread: the clock takes a lock.
#pragma once

#include <chrono>
#include <memory>
#include <mutex>
#include <vector>

#include "specdeform/spectral/manifold_harmonics.h"

namespace specdeform::detail {

class StageClock {
 public:
  // The callback to hand down in place of `inner`; it forwards to `inner` after noting the time.
  // Valid while this clock lives.
  ProgressCallback wrap(ProgressCallback inner);
  // Closes the stage under way and returns them all.
  std::vector<StageTime> stop();

 private:
  void enter(std::string_view stage);

  using Clock = std::chrono::steady_clock;
  std::mutex mutex_;
  std::vector<StageTime> stages_;
  int current_ = -1;
  Clock::time_point since_ = Clock::now();
};

}  // namespace specdeform::detail
