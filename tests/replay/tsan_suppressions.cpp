// SPDX-License-Identifier: MIT
// Under ThreadSanitizer: oneTBB and libgomp are not instrumented, so the hand-offs they
// perform are invisible to TSan. The executors annotate the hand-off of their own data
// (replay/src/tsan.hpp); what the libraries themselves pass between threads (their task
// objects, the functor's fields, the omp shared-variable block) is only reachable here.
// The partitioned executor (std::thread + atomics) needs no suppression. StarPU (the starpu
// policy) is not instrumented either: the executor annotates its hand-offs the same way.
#if defined(__SANITIZE_THREAD__)
extern "C" const char* __tsan_default_suppressions() {
  return
      // TBB's own task object, created by the spawner, destroyed by the runner.
      "race_top:task_group.h\n"
      // Reading the spawned functor's fields (replay/src/worksteal_task.cpp).
      "race_top:worksteal_task.cpp\n"
      // libgomp hands the shared-variable block of `omp parallel` to its threads; the
      // region's own data is annotated (replay/src/tsan.hpp).
      "race_top:BarrierExecutor::execute\n"
      // libstarpu allocates its job structures in one thread and frees them in another after
      // a hand-off through its own (uninstrumented) locks; tgraph's side is annotated.
      "called_from_lib:libstarpu-1.3.so\n";
}
#endif
