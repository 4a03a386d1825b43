// SPDX-License-Identifier: MIT
// Under ThreadSanitizer: oneTBB and libgomp are not instrumented, so the hand-offs they
// perform are invisible to TSan. The executors annotate the hand-off of their own data
// (replay/src/tsan.hpp); what the libraries themselves pass between threads (their task
// objects, the functor's fields, the omp shared-variable block) is only reachable here.
// The partitioned executor (std::thread + atomics) needs no suppression. StarPU (the starpu
// policy) and libgomp's task queues (the omp-tasks policy) are not instrumented either: the
// executors annotate their hand-offs the same way.
#if defined(__SANITIZE_THREAD__)
extern "C" const char* __tsan_default_suppressions() {
  return
      // TBB's own task object, created by the spawner, destroyed by the runner.
      "race_top:task_group.h\n"
      // Reading the spawned functor's fields (replay/src/worksteal_task.cpp).
      "race_top:worksteal_task.cpp\n"
      // TBB frees its own internal blocks (a task group's storage after a rethrown task
      // exception) in a worker, after a hand-off through its uninstrumented atomics: the
      // free called from libtbb is not a race of ours (seen once, under load, in
      // Executor.RethrowsATaskExceptionAfterJoiningAndStaysUsable).
      "called_from_lib:libtbb.so.12\n"
      // TBB's wait_context, on the stack of the thread that made the task group (its
      // constructor writes the count), released by a worker that cancels a spawned task
      // after a task exception (fetch_add inlined from TBB's headers): the worker got the
      // task through TBB's uninstrumented queues (seen once in 10 runs of replay_test, in
      // Executor.RethrowsATaskExceptionAfterJoiningAndStaysUsable).
      "race:tbb::detail::d1::wait_context::add_reference\n"
      // libgomp hands the shared-variable block of `omp parallel` to its threads; the
      // region's own data is annotated (replay/src/tsan.hpp).
      "race_top:BarrierExecutor::run\n"
      // omp-tasks: libgomp copies each task's firstprivate block into a task it allocates,
      // queues it and frees it after another thread ran it, all inside libgomp (not
      // instrumented): the outlined task body's read of its own arguments, the region's
      // shared block, and libgomp's malloc/free of those task objects. The task bodies'
      // data hand-off is annotated per dependence object (replay/src/omp_tasks_executor.cpp).
      "race_top:OmpTasksExecutor::submit\n"
      "race_top:OmpTasksExecutor::run\n"
      "called_from_lib:libgomp.so.1\n"
      // libstarpu allocates its job structures in one thread and frees them in another after
      // a hand-off through its own (uninstrumented) locks; tgraph's side is annotated.
      "called_from_lib:libstarpu-1.3.so\n";
}
#endif
