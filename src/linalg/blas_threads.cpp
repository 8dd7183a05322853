#include "linalg/blas_threads.h"

#include <dlfcn.h>

namespace specdeform::detail {

namespace {

using SetThreads = void (*)(int);
using GetThreads = int (*)();

template <typename Function>
Function lookup(const char* name) {
  return reinterpret_cast<Function>(dlsym(RTLD_DEFAULT, name));
}

}  // namespace

SingleThreadedBlas::SingleThreadedBlas() {
  const auto get = lookup<GetThreads>("openblas_get_num_threads");
  set_ = lookup<SetThreads>("openblas_set_num_threads");
  if (get == nullptr || set_ == nullptr) return;
  previous_ = get();
  if (previous_ > 1) set_(1);
}

SingleThreadedBlas::~SingleThreadedBlas() {
  if (previous_ > 1) set_(previous_);
}

}  // namespace specdeform::detail
