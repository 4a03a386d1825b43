// SPDX-License-Identifier: MIT
// The policies: name -> factory, help and availability, filled in this one function (no
// static self-registration, which silently drops entries in static libraries). Adding a
// policy: its executor in a file of its own with its factory, a value of `enum class
// Policy`, and one line below; its name, help and the "unknown policy" error follow.
#include <string>
#include <vector>

#include "tgraph/graph/error.hpp"
#include "tgraph/replay/executor.hpp"

namespace tgraph::replay {

// Each policy's factory, defined in its own file.
std::unique_ptr<Executor> make_sequential_executor(const ExecOptions& o);  // executor.cpp
std::unique_ptr<Executor> make_partition_executor(const ExecOptions& o);
std::unique_ptr<Executor> make_worksteal_executor(const ExecOptions& o);
std::unique_ptr<Executor> make_barrier_executor(const ExecOptions& o);
std::unique_ptr<Executor> make_starpu_executor(const ExecOptions& o);
std::unique_ptr<Executor> make_omp_tasks_executor(const ExecOptions& o);

namespace {

#ifdef TGRAPH_HAVE_STARPU
constexpr bool kStarpuBuilt = true;
#else
constexpr bool kStarpuBuilt = false;
#endif

/// One registered policy: what policies() shows, and how its executor is made.
struct Registered {
  PolicyInfo info;
  std::unique_ptr<Executor> (*make)(const ExecOptions&);
};

const std::vector<Registered>& registry() {
  // In the order the command line lists them.
  static const std::vector<Registered> r = {
      // policy, name, help, built, baseline, what a build without it lacks; factory
      {{Policy::kPartition, "partition",
        "one pinned thread per processor of an assignment, signal/wait", true, false, ""},
       make_partition_executor},
      {{Policy::kWorksteal, "worksteal", "oneTBB work stealing over the dataflow graph", true,
        true, ""},
       make_worksteal_executor},
      {{Policy::kBarrier, "barrier", "OpenMP loops, a barrier after each phase (--barrier-rule)",
        true, true, ""},
       make_barrier_executor},
      {{Policy::kStarpu, "starpu", "StarPU tasks, one data handle per datum", kStarpuBuilt, true,
        kStarpuBuilt ? "" : "libstarpu-dev was not found"},
       make_starpu_executor},
      {{Policy::kOmpTasks, "omp-tasks", "OpenMP tasks, one depend object per datum", true, true,
        ""},
       make_omp_tasks_executor},
      {{Policy::kSequential, "sequential", "one thread in program order: every run's reference",
        true, false, ""},
       make_sequential_executor},
  };
  return r;
}

const Registered& registered(Policy policy) {
  for (const Registered& e : registry())
    if (e.info.policy == policy) return e;
  throw UsageError("unknown policy");  // a value of Policy that was not registered
}

}  // namespace

std::vector<PolicyInfo> policies() {
  std::vector<PolicyInfo> out;
  for (const Registered& e : registry()) out.push_back(e.info);
  return out;
}

std::string_view to_string(Policy policy) { return registered(policy).info.name; }

std::optional<Policy> parse_policy(std::string_view name) {
  for (const Registered& e : registry())
    if (e.info.name == name) return e.info.policy;
  return std::nullopt;
}

std::string policy_list(std::string_view last, bool baselines_only) {
  std::vector<std::string_view> names;
  for (const Registered& e : registry())
    if (!baselines_only || e.info.baseline) names.push_back(e.info.name);
  std::string s;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) s += i + 1 == names.size() && !last.empty() ? " " + std::string(last) + " " : ", ";
    s += names[i];
  }
  return s;
}

std::unique_ptr<Executor> make_registered_executor(Policy policy, const ExecOptions& options) {
  return registered(policy).make(options);
}

}  // namespace tgraph::replay
