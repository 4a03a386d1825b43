// SPDX-License-Identifier: MIT
// The heavy side of the asymmetric fence of Parking (sync.hpp): membarrier(2).
#include "sync.hpp"

#if defined(__linux__)
#include <linux/membarrier.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

namespace tgraph::replay::detail {

bool asymmetric_fence_available() {
#if defined(__linux__) && defined(__NR_membarrier)
  // Registered once per process (the kernel keeps it for the whole address space).
  static const bool available = [] {
    const long cmds = ::syscall(__NR_membarrier, MEMBARRIER_CMD_QUERY, 0, 0);
    return cmds > 0 && (cmds & MEMBARRIER_CMD_PRIVATE_EXPEDITED) != 0 &&
           ::syscall(__NR_membarrier, MEMBARRIER_CMD_REGISTER_PRIVATE_EXPEDITED, 0, 0) == 0;
  }();
  return available;
#else
  return false;
#endif
}

void asymmetric_heavy_fence() {
#if defined(__linux__) && defined(__NR_membarrier)
  // Every running thread of the process passes a full barrier before this returns (an
  // interrupt on each CPU running one); a thread not running passes one when it is scheduled.
  ::syscall(__NR_membarrier, MEMBARRIER_CMD_PRIVATE_EXPEDITED, 0, 0);
#endif
}

}  // namespace tgraph::replay::detail
