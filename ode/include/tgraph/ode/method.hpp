// SPDX-License-Identifier: MIT
// How ODE's calls run: ODE self-threaded (the reference), ODE's own pool (the peer), or
// tgraph's runtime under work stealing, island-level stealing or a partition strategy's
// placement.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace tgraph::ode {

/// Who runs the calls ODE posts during a world step.
enum class Policy : std::uint8_t {
  kSequential = 0,  ///< ODE self-threaded (no implementation set): the reference
  kOde = 1,         ///< ODE's own multithreaded implementation and thread pool (the peer)
  kWorksteal = 2,   ///< tgraph's threads: per-thread deques, idle threads steal
  kPartition = 3,   ///< tgraph's threads: calls placed by stable key, idle threads steal
  /// tgraph's threads: idle threads steal only what the stepping thread's own code posts
  /// (ODE's island jobs); a call posted by a running call runs on its poster's thread, so an
  /// island's stages run on the thread that took the island, one instance after another.
  kIslands = 4,
  /// tgraph's threads, work stealing, ODE made to step each island with its single-threaded
  /// stepper (ODE self-threaded's algorithm) and K island jobs: K threads step whole islands
  /// side by side (docs/ode.md: what later ODE calls island_stepping_max_threads = 1).
  kIslandsSerial = 5,
};
/// "sequential", "ode", "worksteal", "partition", "islands" or "islands-serial".
std::string_view to_string(Policy policy);

/// A run's policy and, under the partition policy, the strategy placing the calls.
struct Method {
  Policy policy = Policy::kWorksteal;
  std::string strategy;  ///< kPartition: a partition strategy (list, metis, ...)
};
/// `sequential`, `ode`, `worksteal`, `islands` or `islands-serial`, else a partition strategy's
/// name (`list`, `metis`...) under the partition policy; OptionError of the field "method" for any
/// other name.
Method choose_method(std::string_view name);
/// How reports name the method: the strategy under the partition policy, else the policy.
std::string method_name(const Method& method);

/// The world step ODE is entered with.
enum class Stepper : std::uint8_t {
  kQuickStep = 0,  ///< dWorldQuickStep: iterative LCP (Gazebo's default)
  kStep = 1,       ///< dWorldStep: the "big matrix" LDLT method
};
/// "dWorldQuickStep" or "dWorldStep".
std::string_view to_string(Stepper stepper);
/// "quickstep" / "dWorldQuickStep" or "step" / "dWorldStep"; OptionError of the field
/// "stepper" otherwise.
Stepper parse_stepper(std::string_view name);

}  // namespace tgraph::ode
