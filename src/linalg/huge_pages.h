// Internal: large dense matrices on the kernel's 2 MB pages. Linux lends transparent huge pages
// to the memory a program asks for them (madvise, the default mode of Debian's kernels): a pass
// over a 553 MB basis (692k vertices, m = 100) at 4 KB pages takes 135,000 page faults the first
// time and a TLB miss on every 4 KB after; on a virtual machine, whose every miss walks two page
// tables, that was most of the multilevel basis's time (docs/results.md, "Large meshes"). A no-op
// where the kernel does not lend them or the memory is smaller than a few pages.
#pragma once

#include <cstddef>

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace specdeform::detail {

// Asks for huge pages on the whole 2 MB pages inside [data, data + bytes), before it is written.
void advise_huge_pages(void* data, std::size_t bytes);

// A sparse matrix's entries (indices and values) as resizeNonZeros left them, advised so before
// they are written (its outer index need not be filled yet: nonZeros() would read it).
template <int Options>
void advise_huge_pages(Eigen::SparseMatrix<double, Options, int>& A) {
  advise_huge_pages(A.innerIndexPtr(), sizeof(int) * A.data().size());
  advise_huge_pages(A.valuePtr(), sizeof(double) * A.data().size());
}

// An uninitialised rows x cols matrix, advised so.
Eigen::MatrixXd large_matrix(Eigen::Index rows, Eigen::Index cols);

// The same with every page written once (zeros): the first touch's cost (the kernel finding and
// zeroing each page) paid now, on a thread that has nothing else to do, not by the writer later.
Eigen::MatrixXd touched_matrix(Eigen::Index rows, Eigen::Index cols);

}  // namespace specdeform::detail
