// SPDX-License-Identifier: MIT
// The command line's words for the modules' enums: flag values to policies, barrier rules and
// methods, with errors that name the flag (the modules take enums and numbers).
#pragma once

#include <string>
#include <string_view>

#include "tgraph/graph/error.hpp"
#include "tgraph/measure/method.hpp"
#include "tgraph/replay/policy.hpp"

namespace tgraph::app {

/// The policy named by flag `flag`; UsageError naming the flag and the names otherwise.
inline replay::Policy policy_flag(std::string_view name, std::string_view flag) {
  if (const auto p = replay::parse_policy(name)) return *p;
  throw UsageError(std::string(flag) + " " + std::string(name) + ": expected " +
                   replay::policy_list("or"));
}

/// `--barrier-rule omp-for|level|operation`; UsageError naming the flag otherwise.
inline replay::BarrierRule barrier_rule_flag(std::string_view name, std::string_view flag) {
  if (const auto r = replay::parse_barrier_rule(name)) return *r;
  throw UsageError(std::string(flag) + ": expected omp-for, level or operation, got '" +
                   std::string(name) + "'");
}

/// `--method` (a strategy, or a baseline policy such as worksteal; "partition" stands for
/// the partition policy's default strategy, owner) and an optional `--policy` override
/// (empty: none), as `tgraph run` and `tgraph validate` take them.
inline measure::MethodChoice method_flags(std::string_view method, std::string_view policy = {}) {
  measure::MethodChoice c = measure::choose_method(method == "partition" ? "owner" : method);
  if (!policy.empty()) c.policy = policy_flag(policy, "--policy");
  return c;
}

}  // namespace tgraph::app
