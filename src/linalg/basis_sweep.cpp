#include "basis_sweep.h"

#include "parallel.h"
#include "specdeform/exceptions.h"

namespace specdeform::detail {

namespace {

constexpr int kLanes = 8;  // X is processed 8 columns (one AVX-512 register) at a time

struct Rows {
  const double* V;
  Eigen::Index ldv;
  int k;
  double* X;
  int w;
  const double* D;        // k x w, or nullptr
  const double* weights;  // n, or nullptr
  const double* Y;        // n x w, or nullptr
  double* P;              // k x w accumulator, or nullptr
  double* G;              // w x w accumulator, or nullptr
};

// 8 doubles, loaded and stored unaligned: one AVX-512 register, two AVX2 ones.
using Lanes = double __attribute__((vector_size(64), aligned(8), may_alias));
// (Passed by reference: a 64-byte vector by value would have a different ABI in each clone.)
[[gnu::always_inline]] inline void load(Lanes& x, const double* p) {
  x = *reinterpret_cast<const Lanes*>(p);
}
[[gnu::always_inline]] inline void store(double* p, const Lanes& x) {
  *reinterpret_cast<Lanes*>(p) = x;
}

// Y's lanes q..q+7 for R rows from i (X's already updated).
template <int R>
[[gnu::always_inline]] inline void weighted_lanes(const Rows& a, Eigen::Index i, int q,
                                                  Lanes (&y)[R]) {
  for (int r = 0; r < R; ++r) {
    const Eigen::Index at = (i + r) * a.w + q;
    if (a.Y != nullptr) {
      load(y[r], a.Y + at);
    } else {
      load(y[r], a.X + at);
      y[r] *= a.weights != nullptr ? a.weights[i + r] : 1.0;
    }
  }
}

// out[c][q..q+7] += sum_r s[r][c] Y_{i+r}[q..q+7] for c < count (out: count x w, row-major).
template <int R>
[[gnu::always_inline]] inline void add_products(const Rows& a, Eigen::Index i, int q,
                                                const double* const (&s)[R], int count,
                                                double* out) {
  Lanes y[R];
  weighted_lanes<R>(a, i, q, y);
  for (int c = 0; c < count; ++c) {
    double* o = out + c * a.w + q;
    Lanes sum;
    load(sum, o);
    for (int r = 0; r < R; ++r) sum += s[r][c] * y[r];
    store(o, sum);
  }
}

// R consecutive rows from i: V's rows are read once from memory, then reused from L1.
template <int R>
[[gnu::always_inline]] inline void sweep_rows(const Rows& a, Eigen::Index i) {
  const double* v[R];
  double* x[R];
  const double* x_read[R];
  for (int r = 0; r < R; ++r) {
    v[r] = a.V + (i + r) * a.ldv;
    x[r] = a.X + (i + r) * a.w;
    x_read[r] = x[r];
  }
  for (int q = 0; q < a.w; q += kLanes) {
    if (a.D != nullptr) {
      Lanes xs[R];
      for (int r = 0; r < R; ++r) load(xs[r], x[r] + q);
      for (int c = 0; c < a.k; ++c) {
        Lanes d;
        load(d, a.D + c * a.w + q);
        for (int r = 0; r < R; ++r) xs[r] -= v[r][c] * d;
      }
      for (int r = 0; r < R; ++r) store(x[r] + q, xs[r]);
    }
    if (a.P != nullptr) add_products<R>(a, i, q, v, a.k, a.P);
  }
  if (a.G != nullptr) {
    for (int q = 0; q < a.w; q += kLanes) add_products<R>(a, i, q, x_read, a.w, a.G);
  }
}

// Compiled for AVX-512 and AVX2 as well, chosen at run time: no -march flag is needed.
__attribute__((target_clones("avx512f", "avx2", "default"))) void sweep_range(const Rows& a,
                                                                              Eigen::Index begin,
                                                                              Eigen::Index end) {
  Eigen::Index i = begin;
  for (; i + 8 <= end; i += 8) sweep_rows<8>(a, i);
  for (; i < end; ++i) sweep_rows<1>(a, i);
}

}  // namespace

void sweep_basis(const RowMatrix& V, Eigen::Index k, RowMatrix& X, const SweepProducts& p) {
  const Eigen::Index n = X.rows(), w = X.cols();
  const bool sizes_ok =
      V.rows() == n && k >= 0 && k <= V.cols() && w % kLanes == 0 &&
      (p.subtract == nullptr || (p.subtract->rows() == k && p.subtract->cols() == w)) &&
      (p.weights == nullptr || p.weights->size() == n) &&
      (p.weighted == nullptr || (p.weighted->rows() == n && p.weighted->cols() == w));
  if (!sizes_ok) throw InputError("basis sweep: the sizes do not match");
  RowMatrix partial_projection, partial_gram;  // the second thread's sums
  if (p.projection != nullptr) {
    p.projection->setZero(k, w);
    partial_projection.setZero(k, w);
  }
  if (p.gram != nullptr) {
    p.gram->setZero(w, w);
    partial_gram.setZero(w, w);
  }
  const auto rows = [&](RowMatrix* projection, RowMatrix* gram) {
    return Rows{V.data(),
                V.cols(),
                static_cast<int>(k),
                X.data(),
                static_cast<int>(w),
                p.subtract != nullptr ? p.subtract->data() : nullptr,
                p.weights != nullptr ? p.weights->data() : nullptr,
                p.weighted != nullptr ? p.weighted->data() : nullptr,
                projection != nullptr ? projection->data() : nullptr,
                gram != nullptr ? gram->data() : nullptr};
  };
  const Rows first = rows(p.projection, p.gram);
  const Rows second = rows(p.projection != nullptr ? &partial_projection : nullptr,
                           p.gram != nullptr ? &partial_gram : nullptr);
  const Eigen::Index half = n / 2;
  run_pair([&] { sweep_range(first, 0, half); }, [&] { sweep_range(second, half, n); });
  if (p.projection != nullptr) *p.projection += partial_projection;
  if (p.gram != nullptr) *p.gram += partial_gram;
}

}  // namespace specdeform::detail
