#include "mailbox.h"

#include <string>
#include <thread>

#include <gtest/gtest.h>

namespace specdeform::server {
namespace {

TEST(Mailbox, FramesCoalesceAndNothingElseIsDropped) {
  Mailbox box;
  std::string ran;
  const auto job = [&](char c) { return [&ran, c] { ran += c; }; };
  box.push(job('s'), false);  // a selection
  box.push(job('1'), true);   // frames 1..3 arrive while nothing runs: only 3 survives
  box.push(job('2'), true);
  box.push(job('3'), true);
  box.push(job('x'), false);  // a settings change
  box.push(job('4'), true);
  box.push(job('5'), true);
  for (int i = 0; i < 4; ++i) (*box.pop())();
  EXPECT_EQ(ran, "s3x5");
  EXPECT_EQ(box.coalesced(), 3);
}

TEST(Mailbox, CloseWakesAWaitingWorker) {
  Mailbox box;
  std::thread worker([&] { EXPECT_FALSE(box.pop().has_value()); });
  box.close();
  worker.join();
  box.push([] {}, false);  // ignored after close
  EXPECT_FALSE(box.pop().has_value());
}

}  // namespace
}  // namespace specdeform::server
