#include "linalg/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>

namespace specdeform {
namespace {

// An exception of either half comes back to the caller once both halves have run, and the
// helper thread serves the next pair.
TEST(RunPair, CarriesEitherHalfsExceptionBack) {
  std::atomic<int> ran = 0;
  EXPECT_THROW(detail::run_pair([&] { ++ran; }, [&] { throw std::runtime_error("second"); }),
               std::runtime_error);
  EXPECT_EQ(ran, 1);
  EXPECT_THROW(detail::run_pair([] { throw std::invalid_argument("first"); }, [&] { ++ran; }),
               std::invalid_argument);
  EXPECT_EQ(ran, 2);
  try {
    detail::run_pair([] { throw std::invalid_argument("first"); },
                     [] { throw std::runtime_error("second"); });
    ADD_FAILURE() << "nothing thrown";
  } catch (const std::invalid_argument&) {
  }
  int halves = 0;
  detail::split_in_two(10, [&](Eigen::Index begin, Eigen::Index end) {
    if (begin == 0) halves += static_cast<int>(end);
  });
  EXPECT_EQ(halves, 5);
}

}  // namespace
}  // namespace specdeform
