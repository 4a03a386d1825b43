// SPDX-License-Identifier: MIT
// Under ThreadSanitizer: oneTBB, libgomp and libstarpu are not instrumented, so the
// hand-offs they perform are invisible to TSan. What the libraries do inside themselves
// (their own allocations, queues and frees, and oneTBB's header code inlined into tgraph's)
// is left out here, by library; the executors annotate the hand-off of their own data
// (replay/src/tsan.hpp), and the code that only passes the runtime its arguments is
// uninstrumented like the runtime (the OpenMP regions' outlined functions,
// replay/src/omp_region.hpp; the oneTBB functor's call, replay/src/worksteal_task.cpp). No
// entry names a function of tgraph: a race on an executor's own state is reported
// (tests/replay/tsan/race_test.cpp).
#if defined(__SANITIZE_THREAD__)
extern "C" const char* __tsan_default_suppressions() {
  return
      // TBB frees its own internal blocks (a task group's storage after a rethrown task
      // exception) in a worker, after a hand-off through its uninstrumented atomics.
      "called_from_lib:libtbb.so.12\n"
      // oneTBB's task object (its header's code, inlined into tgraph's): made by the spawner
      // inside task_group::run, destroyed by the thread that ran it, handed over by libtbb.
      "race_top:oneapi/tbb/task_group.h\n"
      // oneTBB's wait_context, on the stack of the thread that made the task group (its
      // constructor writes the count), released by a worker that cancels a spawned task
      // after a task exception (fetch_add inlined from oneTBB's headers), the task handed
      // over by libtbb (seen once in 10 runs of replay_test, in
      // Executor.RethrowsATaskExceptionAfterJoiningAndStaysUsable).
      "race:tbb::detail::d1::wait_context::add_reference\n"
      // libgomp allocates, queues, copies and frees its task objects and barriers itself.
      "called_from_lib:libgomp.so.1\n"
      // libstarpu allocates its job structures in one thread and frees them in another after
      // a hand-off through its own (uninstrumented) locks; tgraph's side is annotated.
      "called_from_lib:libstarpu-1.3.so\n";
}
#endif
