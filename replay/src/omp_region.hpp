// SPDX-License-Identifier: MIT
// Internal: what every `omp parallel` region of the OpenMP executors does first.
#pragma once

#include <omp.h>

#include "tsan.hpp"

namespace tgraph::replay::detail {

/// Call first in an `omp parallel` region, before it reads any shared variable. Under
/// ThreadSanitizer: the runtime (not instrumented) fills the region's block of shared
/// variables after anything the caller could annotate before the region, so the primary
/// thread releases from inside the region and, after a barrier, every thread acquires: the
/// block's writes then happen before its reads. Nothing in other builds.
inline void tsan_region_entry() {
#if defined(__SANITIZE_THREAD__)
  static char token = 0;
  if (omp_get_thread_num() == 0) TGRAPH_TSAN_RELEASE(&token);
#pragma omp barrier
  TGRAPH_TSAN_ACQUIRE(&token);
#endif
}

}  // namespace tgraph::replay::detail
