// SPDX-License-Identifier: MIT
#include "tgraph/ode/method.hpp"

#include <algorithm>

#include "tgraph/graph/error.hpp"
#include "tgraph/partition/strategy.hpp"

namespace tgraph::ode {

std::string_view to_string(Policy policy) {
  switch (policy) {
    case Policy::kSequential:
      return "sequential";
    case Policy::kOde:
      return "ode";
    case Policy::kWorksteal:
      return "worksteal";
    case Policy::kPartition:
      return "partition";
    case Policy::kIslands:
      return "islands";
    case Policy::kIslandsSerial:
      return "islands-serial";
  }
  return "?";
}

Method choose_method(std::string_view name) {
  for (Policy p : {Policy::kSequential, Policy::kOde, Policy::kWorksteal, Policy::kIslands,
                   Policy::kIslandsSerial})
    if (name == to_string(p)) return {p, ""};
  const std::vector<std::string> strategies = partition::strategy_names();
  if (std::find(strategies.begin(), strategies.end(), name) != strategies.end())
    return {Policy::kPartition, std::string(name)};
  std::string known = "sequential, ode, worksteal, islands, islands-serial";
  for (const std::string& s : strategies) known += ", " + s;
  throw OptionError("method",
                    "unknown method '" + std::string(name) + "' for an ODE scene (" + known + ")");
}

std::string method_name(const Method& method) {
  return method.policy == Policy::kPartition ? method.strategy
                                             : std::string(to_string(method.policy));
}

std::string_view to_string(Stepper stepper) {
  switch (stepper) {
    case Stepper::kQuickStep:
      return "dWorldQuickStep";
    case Stepper::kStep:
      return "dWorldStep";
  }
  return "?";
}

Stepper parse_stepper(std::string_view name) {
  if (name == "quickstep" || name == "dWorldQuickStep") return Stepper::kQuickStep;
  if (name == "step" || name == "dWorldStep") return Stepper::kStep;
  throw OptionError("stepper", "unknown stepper '" + std::string(name) +
                                   "' (quickstep = dWorldQuickStep, step = dWorldStep)");
}

}  // namespace tgraph::ode
