#include "spectral/stage_clock.h"

#include <algorithm>

namespace specdeform::detail {

ProgressCallback StageClock::wrap(ProgressCallback inner) {
  return [this, inner = std::move(inner)](double fraction, std::string_view stage) {
    enter(stage);
    if (inner) inner(fraction, stage);
  };
}

void StageClock::enter(std::string_view stage) {
  const std::scoped_lock lock(mutex_);
  const Clock::time_point now = Clock::now();
  if (current_ >= 0 && stages_[current_].stage == stage) return;
  if (current_ >= 0)
    stages_[current_].seconds += std::chrono::duration<double>(now - since_).count();
  since_ = now;
  const auto known = std::ranges::find(stages_, stage, &StageTime::stage);
  current_ = static_cast<int>(known - stages_.begin());
  if (known == stages_.end()) stages_.push_back({std::string(stage), 0.0});
}

std::vector<StageTime> StageClock::stop() {
  const std::scoped_lock lock(mutex_);
  if (current_ >= 0) {
    stages_[current_].seconds += std::chrono::duration<double>(Clock::now() - since_).count();
  }
  current_ = -1;
  return stages_;
}

}  // namespace specdeform::detail
