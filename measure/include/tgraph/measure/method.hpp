// SPDX-License-Identifier: MIT
// What a run measures: a partitioning strategy under the partition policy, or a baseline
// policy (the methods of `tgraph run`, `tgraph validate` and the experiments).
#pragma once

#include <string>
#include <string_view>

#include "tgraph/replay/policy.hpp"

namespace tgraph::measure {

/// A run's policy and, for the partition policy, its strategy.
struct MethodChoice {
  replay::Policy policy = replay::Policy::kPartition;
  std::string method = "owner";  ///< the strategy (partition policy)
};

/// `name`: a baseline policy's name (worksteal, barrier, omp-tasks, starpu, sequential: the
/// replay registry's) gives that policy; a strategy's name (partition's registry) that
/// strategy under the partition policy. UsageError naming both lists for any other name.
MethodChoice choose_method(std::string_view name);

/// How reports name the method: the strategy under the partition policy, else the policy.
std::string method_name(const MethodChoice& choice);

}  // namespace tgraph::measure
