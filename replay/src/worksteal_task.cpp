// SPDX-License-Identifier: MIT
#include "worksteal_task.hpp"

namespace tgraph::replay::detail {

// Not instrumented for ThreadSanitizer: its only accesses are the reads of the functor's
// fields, which oneTBB copied into its task object on the spawning thread and handed over
// through its own (uninstrumented) queues; the task's data hand-off is annotated by the
// executor (worksteal_executor.cpp).
#if defined(__SANITIZE_THREAD__)
__attribute__((no_sanitize_thread))
#endif
void SpawnedInstance::operator()() const {
  fn(context, task, iteration);
}

}  // namespace tgraph::replay::detail
