// SPDX-License-Identifier: MIT
// Under ThreadSanitizer: oneTBB's task objects are created by one thread and run by another
// through libtbb's (uninstrumented) deques; the executors annotate the hand-off of their own
// data (replay/src/tsan.hpp), but TBB's task object itself is only reachable here.
#if defined(__SANITIZE_THREAD__)
extern "C" const char* __tsan_default_suppressions() {
  return "race_top:tbb::detail::d1::function_task\n"
         "race_top:tbb::detail::d1::task_ptr_or_nullptr\n";
}
#endif
