// SPDX-License-Identifier: MIT
#include "tgraph/replay/policy.hpp"

namespace tgraph::replay {

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
