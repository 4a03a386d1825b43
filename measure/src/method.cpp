// SPDX-License-Identifier: MIT
#include "tgraph/measure/method.hpp"

namespace tgraph::measure {

MethodChoice choose_method(std::string_view name) {
  if (const auto p = replay::parse_policy(name); p && *p != replay::Policy::kPartition)
    return {*p, std::string(name)};
  return {replay::Policy::kPartition, std::string(name)};
}

std::string method_name(const MethodChoice& choice) {
  return choice.policy == replay::Policy::kPartition ? choice.method
                                                     : std::string(to_string(choice.policy));
}

}  // namespace tgraph::measure
