// SPDX-License-Identifier: MIT
// Internal: how the OpenMP executors open their `omp parallel` regions, so that
// ThreadSanitizer sees every access of theirs and none of the runtime's hand-off.
#pragma once

#include "tsan.hpp"

namespace tgraph::replay::detail {

/// TSan: the address standing for the start of an OpenMP region. The OpenMP runtime (not
/// instrumented) starts the region's threads, or wakes its kept ones, with no order TSan can
/// see: omp_parallel() releases this token, each region body acquires it first.
inline char region_token = 0;

/// Runs `region()` on each thread of an `omp parallel num_threads(threads)` region.
///
/// GCC passes the region's shared variables (here only `&region`) in a block it writes on
/// the caller's stack and the runtime hands to its threads; the outlined function
/// (`*._omp_fn.N`) reads that block anywhere, even above its first statement, so no
/// annotation inside it can order the read. This function and its outlined region hold
/// nothing but that hand-off, and are left uninstrumented, like the runtime library itself
/// (GCC gives the outlined function its parent's attributes); everything the region does is
/// in `region`, a lambda of its own (TGRAPH_OMP_REGION), instrumented: a race on an
/// executor's state there is reported (tests/replay/tsan/race_test.cpp).
template <class Region>
#if defined(__SANITIZE_THREAD__)
__attribute__((no_sanitize_thread))
#endif
__attribute__((noinline)) void omp_parallel(int threads, const Region& region) {
  TGRAPH_TSAN_RELEASE(&region_token);
#pragma omp parallel num_threads(threads)
  region();
}

}  // namespace tgraph::replay::detail

/// Opens an executor's OpenMP region body, not inlined into the uninstrumented outlined
/// function: `const auto region = TGRAPH_OMP_REGION { ... }; detail::omp_parallel(k, region);`
#define TGRAPH_OMP_REGION [&]() __attribute__((noinline))
