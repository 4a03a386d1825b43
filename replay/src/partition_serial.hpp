// SPDX-License-Identifier: MIT
// Internal: the partition executor's serial twin. The per-processor programs of a plan run
// interleaved on the calling thread (round robin, each processor advancing while its waits
// hold, under the threaded runtime's readiness rule), which makes runs deterministic and
// checks that an explicit task order cannot deadlock.
#pragma once

#include <vector>

#include "partition_plan.hpp"
#include "tgraph/replay/executor.hpp"

namespace tgraph::replay::detail {

/// Runs `plan` interleaved on one thread. With a workload: the serial executor
/// (PartitionOptions::serial; `observers` and `stats` optional); without: a dry run in which
/// every loop runs two iterations. Throws UsageError naming each blocked processor when no
/// processor can advance (the plan's order deadlocks).
void run_interleaved(const PartitionPlan& plan, const ExecGraph& x, Workload* w,
                     const std::vector<Observer*>* observers, ExecStepStats* stats);

/// Throws UsageError when the plan's explicit task order can deadlock: the processors'
/// orders wait in a cycle through a loop, or a dry run of two iterations per loop stalls.
/// (Program order never deadlocks: every wait names an earlier task in program order.)
void check_deadlock_free(const PartitionPlan& plan, const ExecGraph& x);

}  // namespace tgraph::replay::detail
