// SPDX-License-Identifier: MIT
#include "tgraph/replay/policy.hpp"

#include <string>

#include "tgraph/graph/error.hpp"

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

Policy policy_flag(std::string_view name, std::string_view flag) {
  if (const auto p = parse_policy(name)) return *p;
  throw UsageError(std::string(flag) + " " + std::string(name) +
                   ": expected partition, worksteal, barrier, starpu or sequential");
}

MethodChoice choose_method(std::string_view method, std::string_view policy) {
  MethodChoice c{Policy::kPartition, std::string(method)};
  if (const auto p = parse_policy(method); p && *p != Policy::kPartition)
    c.policy = *p;
  else if (method == "partition")
    c.method = "owner";
  if (!policy.empty()) c.policy = policy_flag(policy, "--policy");
  return c;
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

std::string_view to_string(ReduceScope scope) {
  switch (scope) {
    case ReduceScope::kNone:
      return "none";
    case ReduceScope::kPerProcessor:
      return "per-processor";
    case ReduceScope::kPerWriter:
      return "per-writer";
  }
  return "?";
}

std::string_view to_string(BarrierRule rule) {
  switch (rule) {
    case BarrierRule::kLevel:
      return "level";
    case BarrierRule::kOperation:
      return "operation";
  }
  return "?";
}

BarrierRule barrier_rule_flag(std::string_view name, std::string_view flag) {
  if (name == "level") return BarrierRule::kLevel;
  if (name == "operation") return BarrierRule::kOperation;
  throw UsageError(std::string(flag) + ": expected level or operation, got '" +
                   std::string(name) + "'");
}

}  // namespace tgraph::replay
