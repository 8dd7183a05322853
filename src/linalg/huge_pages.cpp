#include "linalg/huge_pages.h"

#include <sys/mman.h>

#include <cstdint>
#include <cstring>

namespace specdeform::detail {

namespace {
constexpr std::uintptr_t kHugePage = std::uintptr_t{2} << 20;
}  // namespace

void advise_huge_pages(void* data, std::size_t bytes) {
  const auto begin = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t first = (begin + kHugePage - 1) & ~(kHugePage - 1);
  const std::uintptr_t last = (begin + bytes) & ~(kHugePage - 1);
  // Advice only: where the kernel refuses (no transparent huge pages), small pages serve.
  if (last > first) madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);
}

Eigen::MatrixXd large_matrix(Eigen::Index rows, Eigen::Index cols) {
  Eigen::MatrixXd X(rows, cols);
  advise_huge_pages(X.data(), sizeof(double) * static_cast<std::size_t>(X.size()));
  return X;
}

Eigen::MatrixXd touched_matrix(Eigen::Index rows, Eigen::Index cols) {
  Eigen::MatrixXd X = large_matrix(rows, cols);
  std::memset(X.data(), 0, sizeof(double) * static_cast<std::size_t>(X.size()));
  return X;
}

}  // namespace specdeform::detail
