// SPDX-License-Identifier: MIT
// Internal: the partition executor's stall report (what its watchdog prints), apart from the
// runtime that samples it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "partition_plan.hpp"

namespace tgraph::replay::detail {

/// Where one thread stands, as the watchdog samples it. `kind`: 0 nothing, 1 the completion
/// of task `id`, 2 the decision of loop `id`, 3 the first-touch barrier, 4 combine `id`,
/// 5 the other threads' programs (stealing: the end of its own), 6 the completion of its
/// own task `id` that another thread took; `task`: the task it runs, last ran or waits to run;
/// `inside`: the task it runs inside that wait (taken from thread `inside_of`'s program), or
/// kNoTask.
struct ThreadStand {
  std::uint32_t kind = 0;
  std::uint32_t id = 0;
  TaskId task = kNoTask;
  TaskId inside = kNoTask;
  std::uint32_t inside_of = 0;
};

/// "thread 0 waits for task 13 (addForce) on thread 1 (datum 'f@1') before running task 73
/// (reduce); thread 1 ...": one clause per thread, in thread order. A thread that runs a task
/// inside a wait says so first: "thread 0 runs task 12 (integrate), taken from thread 1's
/// program, inside its wait: it waits for ...".
std::string stall_report(const ExecGraph& x, const PartitionPlan& plan,
                         const std::vector<ThreadStand>& threads);

}  // namespace tgraph::replay::detail
