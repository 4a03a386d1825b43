// SPDX-License-Identifier: MIT
// Internal, for tests only: the partition executor with fault injection. Not part of
// ExecOptions: tests that need it add replay/src to their include path.
#pragma once

#include <memory>
#include <optional>

#include "tgraph/replay/executor.hpp"

namespace tgraph::replay::detail {

/// Faults the partition executor injects into its plans.
struct PartitionTestHooks {
  /// The completion of this task (original id) is never published, as if a wake-up were
  /// lost; its readers on other processors wait until the watchdog fires.
  std::optional<TaskId> lose_signal;
};

/// make_executor(Policy::kPartition, options) with `hooks` applied to every plan it builds.
std::unique_ptr<Executor> make_partition_executor_for_tests(const ExecOptions& options,
                                                            const PartitionTestHooks& hooks);

}  // namespace tgraph::replay::detail
