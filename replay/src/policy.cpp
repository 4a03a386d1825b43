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
  }
  return "?";
}

std::optional<Policy> parse_policy(std::string_view name) {
  for (Policy p : {Policy::kSequential, Policy::kPartition, Policy::kWorksteal, Policy::kBarrier,
                   Policy::kStarpu})
    if (to_string(p) == name) return p;
  return std::nullopt;
}

std::string_view to_string(CwMode mode) {
  switch (mode) {
    case CwMode::kReduce:
      return "reduce";
    case CwMode::kSerialize:
      return "serialize";
  }
  return "?";
}

}  // namespace tgraph::replay
