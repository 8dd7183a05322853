#include "linalg/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <thread>

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

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

int thread_nice() {
  return getpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)));
}

// Each half runs at its caller's priority: a background thread that lowered its own (the
// transfer's) is helped by a helper as low, and a caller at the normal priority afterwards is not
// helped by that one (which a busy machine would starve).
TEST(RunPair, RunsTheOtherHalfAtTheCallersPriority) {
  const int normal = thread_nice();
  int low_half = -100, normal_half = -100;
  std::thread background([&] {
    ASSERT_EQ(setpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)), normal + 5), 0);
    detail::run_pair([] {}, [&] { low_half = thread_nice(); });
  });
  background.join();
  detail::run_pair([] {}, [&] { normal_half = thread_nice(); });
  EXPECT_EQ(low_half, normal + 5);
  EXPECT_EQ(normal_half, normal);
}

}  // namespace
}  // namespace specdeform
