// SPDX-License-Identifier: MIT
#include "tgraph/replay/policy.hpp"

namespace tgraph::replay {

std::string_view to_string(Policy policy) {
  switch (policy) {
    case Policy::kSequential:
      return "sequential";
    case Policy::kPartition:
      return "partition";
    case Policy::kWorksteal:
      return "worksteal";
    case Policy::kBarrier:
      return "barrier";
    case Policy::kStarpu:
      return "starpu";
    case Policy::kOmpTasks:
      return "omp-tasks";
  }
  return "?";
}

std::optional<Policy> parse_policy(std::string_view name) {
  for (Policy p : {Policy::kSequential, Policy::kPartition, Policy::kWorksteal, Policy::kBarrier,
                   Policy::kStarpu, Policy::kOmpTasks})
    if (to_string(p) == name) return p;
  return std::nullopt;
}

std::string_view to_string(BarrierRule rule) {
  switch (rule) {
    case BarrierRule::kLevel:
      return "level";
    case BarrierRule::kOperation:
      return "operation";
    case BarrierRule::kOmpFor:
      return "omp-for";
  }
  return "?";
}

std::optional<BarrierRule> parse_barrier_rule(std::string_view name) {
  for (BarrierRule r : {BarrierRule::kOmpFor, BarrierRule::kLevel, BarrierRule::kOperation})
    if (to_string(r) == name) return r;
  return std::nullopt;
}

}  // namespace tgraph::replay
