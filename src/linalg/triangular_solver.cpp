#include "triangular_solver.h"

#include <cholmod.h>

#include <algorithm>
#include <barrier>
#include <cmath>
#include <cstring>
#include <queue>
#include <type_traits>
#include <utility>

#include "parallel.h"
#include "specdeform/exceptions.h"

namespace specdeform::detail {

namespace {

// Below this many entries of L one thread solves everything: a thread start costs more than
// the parallel work saves.
constexpr long kParallelEntries = 150'000;
// Subtrees are split while one holds more than this share of the work, as long as the
// separator stays below its cap.
constexpr double kLargestShare = 0.2;
constexpr double kSeparatorCap = 0.25;
constexpr int kMaxWidth = TriangularSolver::kMaxWidth;

// The kernels' view of the factor.
struct Factor {
  const Supernode* nodes;
  const int* row;
  const double* value;
  const double* inv_diagonal;
};

long triangle(int width) {
  return static_cast<long>(width) * (width - 1) / 2;
}

// One row of the right-hand sides (W values) in a vector register of GCC's vector extension,
// padded to a power of two lanes. (Passed by reference: a vector by value would have a
// different ABI in each clone.)
using Lanes2 = double __attribute__((vector_size(16)));
using Lanes4 = double __attribute__((vector_size(32)));
using Lanes8 = double __attribute__((vector_size(64)));

template <int W>
struct Row {
  using Vector = std::conditional_t<W <= 2, Lanes2, std::conditional_t<W <= 4, Lanes4, Lanes8>>;
  static constexpr int kLanes = sizeof(Vector) / sizeof(double);
  // Lane by lane below a full vector: a partial copy would stall store-to-load forwarding.
  [[gnu::always_inline]] static void load(Vector& v, const double* p) {
    if constexpr (W == kLanes) {
      std::memcpy(&v, p, sizeof(Vector));
    } else {
      v = Vector{};
      for (int k = 0; k < W; ++k) v[k] = p[k];
    }
  }
  [[gnu::always_inline]] static void store(double* p, const Vector& v) {
    if constexpr (W == kLanes) {
      std::memcpy(p, &v, sizeof(Vector));
    } else {
      for (int k = 0; k < W; ++k) p[k] = v[k];
    }
  }
  // p -= v
  [[gnu::always_inline]] static void subtract(double* p, const Vector& v) {
    Vector x;
    load(x, p);
    store(p, x - v);
  }
};

// L y = b over `nodes` (ascending): per supernode, its unit lower triangular diagonal block by
// rows, then its update of the rows below, four rows at a time (four independent sums, each
// of the supernode's own rows loaded once for them).
template <int W>
[[gnu::always_inline]] inline void forward(const Factor& L, const std::vector<int>& nodes,
                                           double* x) {
  using R = Row<W>;
  using Vector = typename R::Vector;
  for (const int s : nodes) {
    const Supernode& node = L.nodes[s];
    const int width = node.width;
    double* xc = x + static_cast<size_t>(node.first) * W;
    const double* v = L.value + node.values;
    Vector xj;
    for (int j = 1; j < width; ++j) {
      Vector sum{};
      for (int i = 0; i < j; ++i, ++v) {
        R::load(xj, xc + i * W);
        sum += *v * xj;
      }
      R::subtract(xc + j * W, sum);
    }
    int e = node.rows;
    for (; e + 4 <= node.rows_end; e += 4, v += 4 * width) {
      Vector sum[4] = {};
      for (int j = 0; j < width; ++j) {
        R::load(xj, xc + j * W);
        for (int r = 0; r < 4; ++r) sum[r] += v[r * width + j] * xj;
      }
      for (int r = 0; r < 4; ++r) R::subtract(x + static_cast<size_t>(L.row[e + r]) * W, sum[r]);
    }
    for (; e < node.rows_end; ++e) {
      Vector sum{};
      for (int j = 0; j < width; ++j, ++v) {
        R::load(xj, xc + j * W);
        sum += *v * xj;
      }
      R::subtract(x + static_cast<size_t>(L.row[e]) * W, sum);
    }
  }
}

// D L^T x = y over `nodes` (descending): per supernode x_j = y_j / D_j - sum_{i > j} L_ij x_i,
// first over the rows below (solved already, four at a time), then back through the diagonal
// block.
template <int W>
[[gnu::always_inline]] inline void backward(const Factor& L, const std::vector<int>& nodes,
                                            double* x) {
  using R = Row<W>;
  using Vector = typename R::Vector;
  for (auto it = nodes.rbegin(); it != nodes.rend(); ++it) {
    const Supernode& node = L.nodes[*it];
    const int width = node.width;
    double* xc = x + static_cast<size_t>(node.first) * W;
    Vector xi[4];
    for (int j = 0; j < width; ++j) {
      R::load(xi[0], xc + j * W);
      R::store(xc + j * W, L.inv_diagonal[node.first + j] * xi[0]);
    }
    const double* diagonal_block = L.value + node.values;
    const double* v = diagonal_block + triangle(width);
    int e = node.rows;
    for (; e + 4 <= node.rows_end; e += 4, v += 4 * width) {
      for (int r = 0; r < 4; ++r) R::load(xi[r], x + static_cast<size_t>(L.row[e + r]) * W);
      for (int j = 0; j < width; ++j) {
        R::subtract(xc + j * W, v[j] * xi[0] + v[width + j] * xi[1] + v[2 * width + j] * xi[2] +
                                    v[3 * width + j] * xi[3]);
      }
    }
    for (; e < node.rows_end; ++e) {
      R::load(xi[0], x + static_cast<size_t>(L.row[e]) * W);
      for (int j = 0; j < width; ++j, ++v) R::subtract(xc + j * W, *v * xi[0]);
    }
    for (int i = width - 1; i > 0; --i) {
      const double* l = diagonal_block + triangle(i);
      R::load(xi[0], xc + i * W);
      for (int j = 0; j < i; ++j) R::subtract(xc + j * W, l[j] * xi[0]);
    }
  }
}

// The kernel for the width, known at run time (1 to kMaxWidth).
template <bool Forward, int... W>
[[gnu::always_inline]] inline void dispatch(std::integer_sequence<int, W...>, const Factor& L,
                                            const std::vector<int>& nodes, double* x, int width) {
  ((width == W + 1 ? (Forward ? forward<W + 1>(L, nodes, x) : backward<W + 1>(L, nodes, x))
                   : void()),
   ...);
}

// Compiled for AVX-512 and AVX2 as well, chosen at run time: no -march flag is needed.
__attribute__((target_clones("avx512f", "avx2", "default"))) void forward_nodes(
    const Factor& L, const std::vector<int>& nodes, double* x, int width) {
  dispatch<true>(std::make_integer_sequence<int, kMaxWidth>(), L, nodes, x, width);
}

__attribute__((target_clones("avx512f", "avx2", "default"))) void backward_nodes(
    const Factor& L, const std::vector<int>& nodes, double* x, int width) {
  dispatch<false>(std::make_integer_sequence<int, kMaxWidth>(), L, nodes, x, width);
}

double checked_pivot(double d) {
  if (!(d != 0.0 && std::isfinite(d))) throw SolverError("triangular solve: singular factor");
  return d;
}

}  // namespace

TriangularSolver::TriangularSolver(const cholmod_factor* factor) {
  assign(factor);
}

void TriangularSolver::assign(const cholmod_factor* factor) {
  if (factor->xtype != CHOLMOD_REAL || factor->itype != CHOLMOD_INT || factor->minor < factor->n ||
      (factor->is_super && !factor->is_ll)) {
    throw SolverError("triangular solve: not a complete real factorisation");
  }
  n_ = static_cast<int>(factor->n);
  const int* perm = static_cast<const int*>(factor->Perm);
  order_.assign(perm, perm + n_);
  inv_diagonal_.resize(n_);
  // The buffers keep their memory from one factor to the next (no page faults on reuse).
  nodes_.clear();
  split(factor->is_super ? read_supernodal(factor) : read_simplicial(factor), true);
}

// CHOLMOD's supernodes: a column-major block per supernode, its rows listed (the diagonal
// block's first), L L^T scaled to L D L^T.
std::vector<int> TriangularSolver::read_supernodal(const cholmod_factor* factor) {
  const int* super = static_cast<const int*>(factor->super);
  const int* pi = static_cast<const int*>(factor->pi);
  const int* px = static_cast<const int*>(factor->px);
  const int* Ls = static_cast<const int*>(factor->s);
  const double* Lx = static_cast<const double*>(factor->x);
  const int count = static_cast<int>(factor->nsuper);
  std::vector<int> node_of(n_);
  for (int s = 0; s < count; ++s)
    std::fill(node_of.begin() + super[s], node_of.begin() + super[s + 1], s);
  row_.resize(factor->ssize);
  value_.resize(factor->xsize);
  int rows = 0;
  long values = 0;
  std::vector<double> scale;
  std::vector<int> tree;
  std::vector<long> at;  // where block row r's values go (-1: a row of zeros, dropped)
  for (int s = 0; s < count; ++s) {
    const int first = super[s], width = super[s + 1] - first, block_rows = pi[s + 1] - pi[s];
    const double* block = Lx + px[s];
    const auto entry = [&](int r, int j) { return block[static_cast<long>(j) * block_rows + r]; };
    Supernode node{first, width, rows, rows, values};
    scale.resize(width);
    for (int j = 0; j < width; ++j) {
      if (Ls[pi[s] + j] != first + j) throw SolverError("triangular solve: malformed supernode");
      const double d = checked_pivot(entry(j, j));
      inv_diagonal_[first + j] = 1.0 / (d * d);
      scale[j] = 1.0 / d;
    }
    at.assign(block_rows, -1);
    for (int j = 0; j < width; ++j)  // marks the rows below with a nonzero, column by column
      for (int r = width; r < block_rows; ++r)
        if (entry(r, j) != 0.0) at[r] = 0;
    for (int r = 0; r < width; ++r) at[r] = values + triangle(r);
    values += triangle(width);
    int parent = n_;
    for (int r = width; r < block_rows; ++r) {
      parent = std::min(parent, Ls[pi[s] + r]);
      if (at[r] < 0) continue;
      row_[rows++] = Ls[pi[s] + r];
      at[r] = values;
      values += width;
    }
    // Transposed in tiles of 8 rows: each column's 8 values share a cache line.
    for (int r0 = 0; r0 < block_rows; r0 += 8) {
      const int r1 = std::min(r0 + 8, block_rows);
      for (int j = 0; j < width; ++j)
        for (int r = std::max(r0, j + 1); r < r1; ++r)
          if (at[r] >= 0) value_[at[r] + j] = entry(r, j) * scale[j];
    }
    node.rows_end = rows;
    nodes_.push_back(node);
    tree.push_back(parent < n_ ? node_of[parent] : -1);
  }
  row_.resize(rows);
  value_.resize(values);
  return tree;
}

// A simplicial factor's fundamental supernodes: column c + 1 joins column c's supernode when
// it is c's parent in the elimination tree and c's other rows are exactly its rows.
std::vector<int> TriangularSolver::read_simplicial(const cholmod_factor* factor) {
  const int* Lp = static_cast<const int*>(factor->p);
  const int* Li = static_cast<const int*>(factor->i);
  const int* Lnz = static_cast<const int*>(factor->nz);
  const double* Lx = static_cast<const double*>(factor->x);
  // Column c's entries below the diagonal (stored first): Lp[c] + 1 ... Lp[c] + Lnz[c] - 1.
  std::vector<int> parent(n_, -1), mark(n_, -1), position(n_, -1);
  for (int c = 0; c < n_; ++c) {
    for (int e = Lp[c] + 1; e < Lp[c] + Lnz[c]; ++e)
      if (parent[c] < 0 || Li[e] < parent[c]) parent[c] = Li[e];
  }
  const auto continues = [&](int c) {  // whether column c + 1 joins column c's supernode
    if (parent[c] != c + 1 || Lnz[c] != Lnz[c + 1] + 1) return false;
    for (int e = Lp[c + 1] + 1; e < Lp[c + 1] + Lnz[c + 1]; ++e) mark[Li[e]] = c;
    for (int e = Lp[c] + 1; e < Lp[c] + Lnz[c]; ++e)
      if (Li[e] != c + 1 && mark[Li[e]] != c) return false;
    return true;
  };
  std::vector<int> node_of(n_), tree;
  row_.resize(factor->nzmax);
  value_.resize(factor->nzmax);
  int rows = 0;
  long values = 0;
  for (int first = 0; first < n_;) {
    int width = 1;
    while (first + width < n_ && continues(first + width - 1)) ++width;
    const int last = first + width - 1;
    std::fill(node_of.begin() + first, node_of.begin() + first + width,
              static_cast<int>(nodes_.size()));
    // The supernode's rows below: the last column's; rows of values that are all zero dropped.
    const long size = triangle(width) + static_cast<long>(Lnz[last] - 1) * width;
    if (static_cast<long>(value_.size()) < values + size) value_.resize(values + size);
    std::fill(value_.begin() + values, value_.begin() + values + size, 0.0);
    for (int e = Lp[last] + 1; e < Lp[last] + Lnz[last]; ++e) position[Li[e]] = e - Lp[last] - 1;
    for (int j = 0; j < width; ++j) {
      const int c = first + j;
      const double diagonal = checked_pivot(Lx[Lp[c]]);
      inv_diagonal_[c] = factor->is_ll ? 1.0 / (diagonal * diagonal) : 1.0 / diagonal;
      const double scale = factor->is_ll ? 1.0 / diagonal : 1.0;
      for (int e = Lp[c] + 1; e < Lp[c] + Lnz[c]; ++e) {
        const int i = Li[e];
        const long at = i <= last ? triangle(i - first) + j
                                  : triangle(width) + static_cast<long>(position[i]) * width + j;
        value_[values + at] = Lx[e] * scale;
      }
    }
    Supernode node{first, width, rows, rows, values};
    values += triangle(width);
    for (int r = 0; r < Lnz[last] - 1; ++r) {
      const double* row_values =
          value_.data() + node.values + triangle(width) + static_cast<long>(r) * width;
      if (std::all_of(row_values, row_values + width, [](double v) { return v == 0.0; })) continue;
      row_[rows++] = Li[Lp[last] + 1 + r];
      std::copy(row_values, row_values + width, value_.begin() + values);  // never ahead of r
      values += width;
    }
    node.rows_end = rows;
    nodes_.push_back(node);
    tree.push_back(parent[last]);  // a column for now, its supernode below
    first += width;
  }
  for (int& p : tree) p = p >= 0 ? node_of[p] : -1;
  row_.resize(rows);
  value_.resize(values);
  return tree;
}

// Splits the largest subtree (moving its root into the separator) until no subtree holds much
// of the work, then deals the subtrees to two threads, largest first, each to the lighter one.
void TriangularSolver::split(const std::vector<int>& parent, bool parallel) {
  const int count = static_cast<int>(nodes_.size());
  for (auto& list : forest_) list.clear();
  separator_.clear();
  slot_column_.clear();
  separator_share_ = 0.0;
  const auto own = [&](int s) {
    const Supernode& node = nodes_[s];
    return node.width + triangle(node.width) +
           static_cast<long>(node.rows_end - node.rows) * node.width;
  };
  std::vector<long> subtree(count, 0);
  for (int s = 0; s < count; ++s) {
    subtree[s] += own(s);
    if (parent[s] >= 0) subtree[parent[s]] += subtree[s];
  }
  long total = 0;
  for (int s = 0; s < count; ++s) total += own(s);
  if (!parallel || total < kParallelEntries) {
    forest_[0].resize(count);
    for (int s = 0; s < count; ++s) forest_[0][s] = s;
    return;
  }
  std::vector<int> first_child(count + 1, 0), children(count);  // children of s: CSR
  for (int s = 0; s < count; ++s)
    if (parent[s] >= 0) ++first_child[parent[s] + 1];
  for (int s = 0; s < count; ++s) first_child[s + 1] += first_child[s];
  {
    std::vector<int> next(first_child.begin(), first_child.end() - 1);
    for (int s = 0; s < count; ++s)
      if (parent[s] >= 0) children[next[parent[s]]++] = s;
  }
  using Candidate = std::pair<long, int>;  // (subtree work, root)
  std::priority_queue<Candidate> candidates;
  for (int s = 0; s < count; ++s)
    if (parent[s] < 0) candidates.emplace(subtree[s], s);
  std::vector<int> owner(count, -1);  // thread, or 2: separator
  long separator_work = 0;
  while (!candidates.empty()) {
    const auto [work, root] = candidates.top();
    if (work <= kLargestShare * total || separator_work + own(root) > kSeparatorCap * total) break;
    candidates.pop();
    owner[root] = 2;
    separator_work += own(root);
    for (int c = first_child[root]; c < first_child[root + 1]; ++c)
      candidates.emplace(subtree[children[c]], children[c]);
  }
  long load[2] = {0, 0};
  while (!candidates.empty()) {  // popped largest first
    const auto [work, root] = candidates.top();
    candidates.pop();
    const int t = load[0] <= load[1] ? 0 : 1;
    owner[root] = t;
    load[t] += work;
  }
  for (int s = count - 1; s >= 0; --s) {  // a parent comes after its children
    if (owner[s] < 0) owner[s] = owner[parent[s]];
  }
  // Every entry of L lies on the path from its column to the root, so a forest's supernode
  // reaches only its own forest and the separator (checked all the same): its separator rows
  // are remapped to the thread's own copies of them.
  std::vector<int> column_owner(n_), slot(n_, -1);
  for (int s = 0; s < count; ++s) {
    const Supernode& node = nodes_[s];
    std::fill_n(column_owner.begin() + node.first, node.width, owner[s]);
  }
  for (int s = 0; s < count; ++s) {
    for (int e = nodes_[s].rows; e < nodes_[s].rows_end; ++e) {
      const int o = column_owner[row_[e]];
      if (o != owner[s] && o != 2) {  // not an elimination tree: one thread solves it all
        split(parent, false);
        return;
      }
    }
  }
  for (int s = 0; s < count; ++s) {
    (owner[s] == 2 ? separator_ : forest_[owner[s]]).push_back(s);
    if (owner[s] != 2) continue;
    for (int j = 0; j < nodes_[s].width; ++j) {
      slot[nodes_[s].first + j] = static_cast<int>(slot_column_.size());
      slot_column_.push_back(nodes_[s].first + j);
    }
  }
  const int slots = static_cast<int>(slot_column_.size());
  for (int s = 0; s < count; ++s) {
    if (owner[s] == 2) continue;
    for (int e = nodes_[s].rows; e < nodes_[s].rows_end; ++e)
      if (column_owner[row_[e]] == 2) row_[e] = n_ + owner[s] * slots + slot[row_[e]];
  }
  separator_share_ = static_cast<double>(separator_work) / total;
}

void TriangularSolver::solve_in_place(double* x, int width) const {
  if (width < 1 || width > kMaxWidth)
    throw InputError("triangular solve: 1 to 8 columns at a time");
  const Factor L{nodes_.data(), row_.data(), value_.data(), inv_diagonal_.data()};
  const int slots = static_cast<int>(slot_column_.size());
  std::fill_n(x + static_cast<size_t>(n_) * width, static_cast<size_t>(2 * slots) * width, 0.0);
  if (forest_[1].empty() && separator_.empty()) {
    forward_nodes(L, forest_[0], x, width);
    backward_nodes(L, forest_[0], x, width);
    return;
  }
  const auto row = [&](int i) { return x + static_cast<size_t>(i) * width; };
  std::barrier sync(2);
  const auto work = [&](int t) {
    forward_nodes(L, forest_[t], x, width);
    sync.arrive_and_wait();
    if (t == 0) {
      for (int s = 0; s < slots; ++s) {
        double* xs = row(slot_column_[s]);
        const double* a = row(n_ + s);
        const double* b = row(n_ + slots + s);
        for (int k = 0; k < width; ++k) xs[k] += a[k] + b[k];
      }
      forward_nodes(L, separator_, x, width);
      backward_nodes(L, separator_, x, width);
      for (int s = 0; s < slots; ++s) {
        const double* xs = row(slot_column_[s]);
        std::copy(xs, xs + width, row(n_ + s));
        std::copy(xs, xs + width, row(n_ + slots + s));
      }
    }
    sync.arrive_and_wait();
    backward_nodes(L, forest_[t], x, width);
  };
  run_pair([&] { work(0); }, [&] { work(1); });
}

Eigen::MatrixXd TriangularSolver::solve(const Eigen::Ref<const Eigen::MatrixXd>& B) const {
  Eigen::MatrixXd X;
  std::vector<double> workspace;
  solve(B, X, workspace);
  return X;
}

}  // namespace specdeform::detail
