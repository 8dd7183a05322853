// linalg/huge_pages.h: a large matrix gets the kernel's 2 MB pages where the kernel lends them on
// request, and the advice is harmless on any range.
#include "linalg/huge_pages.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace specdeform::detail {
namespace {

// A field's kilobytes (e.g. "AnonHugePages:", "Rss:") of the mapping that holds `address`
// (/proc/self/smaps).
long kilobytes_at(const void* address, const std::string& field) {
  const auto at = reinterpret_cast<std::uintptr_t>(address);
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    std::uintptr_t begin = 0, end = 0;
    char dash = 0;
    std::istringstream range(line);
    if (range >> std::hex >> begin >> dash >> end && dash == '-') {
      inside = begin <= at && at < end;
    } else if (inside && line.rfind(field, 0) == 0) {
      return std::stol(line.substr(field.size()));
    }
  }
  return -1;
}

bool kernel_lends_on_request() {
  std::ifstream f("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string modes;
  std::getline(f, modes);
  return modes.find("[madvise]") != std::string::npos ||
         modes.find("[always]") != std::string::npos;
}

TEST(HugePages, ALargeMatrixIsOnHugePages) {
  Eigen::MatrixXd X = large_matrix(1 << 20, 8);  // 64 MB
  ASSERT_EQ(X.rows(), 1 << 20);
  ASSERT_EQ(X.cols(), 8);
  X.setConstant(1.0);
  EXPECT_EQ(X.sum(), 8.0 * (1 << 20));
  if (!kernel_lends_on_request()) GTEST_SKIP() << "transparent huge pages are off";
  EXPECT_GT(kilobytes_at(X.data() + X.size() / 2, "AnonHugePages:"), 0);
}

// A touched matrix is zeros, its memory resident before anything is written to it.
TEST(HugePages, ATouchedMatrixIsResidentBeforeItIsWritten) {
  const Eigen::MatrixXd X = touched_matrix(1 << 20, 8);  // 64 MB
  ASSERT_EQ(X.rows(), 1 << 20);
  ASSERT_EQ(X.cols(), 8);
  EXPECT_EQ(X.cwiseAbs().maxCoeff(), 0.0);
  const double* middle = X.data() + X.size() / 2;  // in the advised part's own mapping
  EXPECT_GE(kilobytes_at(middle, "Rss:"), kilobytes_at(middle, "Size:") - 4);
  const Eigen::MatrixXd untouched = large_matrix(1 << 20, 8);
  EXPECT_LT(kilobytes_at(untouched.data() + untouched.size() / 2, "Rss:"), 8 << 10);
}

TEST(HugePages, AdviceOnAnyRangeIsHarmless) {
  std::vector<char> small(100, 'a');
  advise_huge_pages(small.data() + 1, 3);
  advise_huge_pages(small.data(), 0);
  EXPECT_EQ(small[50], 'a');
  const Eigen::MatrixXd empty = large_matrix(0, 0);
  EXPECT_EQ(empty.size(), 0);
}

}  // namespace
}  // namespace specdeform::detail
