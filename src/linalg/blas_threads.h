// Internal: OpenBLAS's own threads held to one for a scope. The eigensolver runs its bandwidth-
// bound loops on two threads of its own (linalg/parallel.h); OpenBLAS's idle workers meanwhile
// spin in sched_yield (measured: about 28% of the samples of `specdeform basis` on 2 cores),
// taking a core from them. Where the BLAS is not OpenBLAS (no openblas_set_num_threads in the
// process), this does nothing. Process-wide: a BLAS call on another thread in the meantime runs
// on one thread too.
#pragma once

namespace specdeform::detail {

class SingleThreadedBlas {
 public:
  SingleThreadedBlas();
  ~SingleThreadedBlas();
  SingleThreadedBlas(const SingleThreadedBlas&) = delete;
  SingleThreadedBlas& operator=(const SingleThreadedBlas&) = delete;

 private:
  void (*set_)(int) = nullptr;  // openblas_set_num_threads, where there is one
  int previous_ = 0;
};

}  // namespace specdeform::detail
