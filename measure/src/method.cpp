// SPDX-License-Identifier: MIT
#include "tgraph/measure/method.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include "tgraph/graph/error.hpp"
#include "tgraph/partition/strategy.hpp"

namespace tgraph::measure {

namespace {

std::string join(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

}  // namespace

MethodChoice choose_method(std::string_view name) {
  if (const auto p = replay::parse_policy(name); p && *p != replay::Policy::kPartition)
    return {*p, std::string(name)};
  const std::vector<std::string> strategies = partition::strategy_names();
  if (std::find(strategies.begin(), strategies.end(), name) == strategies.end())
    throw UsageError("unknown method '" + std::string(name) + "' (strategies: " +
                     join(strategies) + "; baseline policies: " +
                     replay::policy_list("", true) + ", sequential)");
  return {replay::Policy::kPartition, std::string(name)};
}

std::string method_name(const MethodChoice& choice) {
  return choice.policy == replay::Policy::kPartition ? choice.method
                                                     : std::string(to_string(choice.policy));
}

}  // namespace tgraph::measure
