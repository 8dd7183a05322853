// Internal: a two-way split of a per-frame loop over the machine's (at least) two cores.
#pragma once

#include <thread>

#include <Eigen/Core>

namespace specdeform::detail {

// Runs body(begin, end) on [0, n) in two halves, the first half on a helper thread.
template <typename Body>
void split_in_two(Eigen::Index n, Body&& body) {
  const Eigen::Index half = n / 2;
  std::thread helper([&] { body(Eigen::Index{0}, half); });
  body(half, n);
  helper.join();
}

}  // namespace specdeform::detail
