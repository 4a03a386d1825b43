// SPDX-License-Identifier: MIT
// Internal: how the OpenMP executors write their `omp parallel` regions for ThreadSanitizer.
#pragma once

namespace tgraph::replay::detail {

/// TSan: the address standing for the start of an OpenMP region. libgomp (not instrumented)
/// hands the region's block of shared variables to its threads, and GCC may read that block
/// anywhere in the outlined region, even before a first statement. So each executor's
/// region is a lambda of its own, not inlined (TGRAPH_OMP_REGION), that the region only
/// calls: the caller releases this token after building the lambda, the lambda acquires it
/// first (the address of a global needs no read), and GCC's outlined function (`*._omp_fn.N`)
/// holds nothing but libgomp's hand-off (see docs/replay.md, "Tests and ThreadSanitizer").
inline char region_token = 0;

}  // namespace tgraph::replay::detail

/// Opens an executor's OpenMP region body: `const auto region = TGRAPH_OMP_REGION { ... };`
#define TGRAPH_OMP_REGION [&]() __attribute__((noinline))
