// SPDX-License-Identifier: MIT
// Under ThreadSanitizer: oneTBB, libgomp and StarPU are not instrumented, so the hand-offs they
// perform are invisible to TSan. The executors annotate the hand-off of their own data
// (replay/src/tsan.hpp; an OpenMP region's shared variables: omp_region.hpp), and the
// suppressions below name only those runtime libraries and their inlined header code, never
// tgraph's own functions: a race in an executor's own state is still reported
// (tsan_report_test.cpp plants one). The partitioned executor (std::thread + atomics) needs
// none.
#if defined(__SANITIZE_THREAD__)
extern "C" const char* __tsan_default_suppressions() {
  return
      // oneTBB's own task object (its header task_group.h, inlined): created by the spawner,
      // destroyed by the thread that ran it after a hand-off through TBB's queues.
      "race_top:task_group.h\n"
      // oneTBB frees its internal blocks (a task group's storage after a rethrown task
      // exception) in a worker, after a hand-off through its uninstrumented atomics (seen
      // once, under load, in Executor.RethrowsATaskExceptionAfterJoiningAndStaysUsable).
      "called_from_lib:libtbb.so.12\n"
      // oneTBB's wait_context (inlined from its headers) on the stack of the thread that made
      // the task group, released by a worker that cancels a spawned task after a task
      // exception; the worker got the task through TBB's uninstrumented queues.
      "race:tbb::detail::d1::wait_context::add_reference\n"
      // libgomp allocates, copies (a task's firstprivate block) and frees its task objects
      // in different threads, inside the library.
      "called_from_lib:libgomp.so.1\n"
      // libstarpu allocates its job structures in one thread and frees them in another
      // after a hand-off through its own locks.
      "called_from_lib:libstarpu-1.3.so\n";
}
#endif
