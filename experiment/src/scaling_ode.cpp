// SPDX-License-Identifier: MIT
// The scaling sweep's ODE scenes: ode::run_scene's `repeat` timed passes, each beside a pass
// of ODE self-threaded on a fresh copy of the scene, reduced to the sweep's records.
#include "scaling_ode.hpp"

#include <algorithm>
#include <stdexcept>

#include "tgraph/graph/error.hpp"
#ifdef TGRAPH_HAVE_ODE
#include "tgraph/ode/run.hpp"
#include "tgraph/ode/scenes.hpp"
#endif

namespace tgraph::experiment::detail {

const std::vector<std::string>& default_ode_methods() {
  static const std::vector<std::string> methods = {"sequential",     "ode", "worksteal", "islands",
                                                   "islands-serial", "list"};
  return methods;
}

#ifdef TGRAPH_HAVE_ODE

namespace {

ode::RunResult ode_run(const ScalingScene& s, const std::string& method, std::uint32_t k,
                       const ScalingPlan& p, bool check) {
  ode::RunOptions o = ode::run_options(s.scene, s.steps, ode::choose_method(method), k, p.repeat);
  o.check = check;
  return ode::run_scene(o);
}

}  // namespace

std::optional<ScalingScene> ode_scene(const std::string& name, bool quick) {
  if (!ode::is_scene(name)) return std::nullopt;
  return ScalingScene{name, std::nullopt, quick ? 40u : ode::default_steps(name), true};
}

std::vector<std::string> ode_scene_names() { return ode::scene_names(); }

std::vector<std::string> checked_ode_methods(const std::vector<std::string>& methods) {
  for (const std::string& m : methods) {
    try {
      (void)ode::choose_method(m);
    } catch (const OptionError&) {
      throw OptionError("methods", "unknown method '" + m +
                                       "' for the ODE scenes (expected "
                                       "sequential, ode, worksteal or a partition strategy)");
    }
  }
  return methods;
}

std::pair<std::string, std::string> ode_policy_and_method(const std::string& method) {
  const ode::Method m = ode::choose_method(method);
  return {std::string(ode::to_string(m.policy)), ode::method_name(m)};
}

ScalingReference ode_reference(const ScalingScene& s, const ScalingPlan& p) {
  const ode::RunResult r = ode_run(s, "sequential", 1, p, false);
  return {s.label(), r.steps, 1, r.sequential_wall_ns};
}

ScalingRecord ode_record(const ScalingScene& s, const std::string& method, std::uint32_t k,
                         const ScalingPlan& p, ScalingRecord rec) {
  const ode::RunResult r = ode_run(s, method, k, p, true);
  rec.ode = true;
  rec.wall_ns = r.wall_ns;
  rec.sequential_wall_ns = r.sequential_wall_ns;  // the same run's ODE self-threaded
  rec.speedup = r.speedup;
  rec.world_speedup = r.world_speedup;
  if (r.sequential_wall_ns > 0)
    rec.serial_share = static_cast<double>(r.collide_ns + r.partition_ns) /
                       static_cast<double>(r.sequential_wall_ns);
  rec.parks_per_step = static_cast<double>(r.stats.parks) / std::max<double>(r.steps, 1);
  rec.partitioned_steps = static_cast<std::uint32_t>(r.stats.partitions);
  rec.check = r.check;
  rec.max_abs_diff = r.max_abs_diff;
  return rec;
}

#else  // no tgraph::ode in this build: no scene is an ODE scene

namespace {
[[noreturn]] void no_ode() {
  throw std::logic_error("an ODE scene's run asked of a build without tgraph::ode");
}
}  // namespace

std::optional<ScalingScene> ode_scene(const std::string& name, bool) {
  if (name.rfind("ode-", 0) == 0)
    throw OptionError("scenes", "'" + name +
                                    "': the ODE scenes are not in this build "
                                    "(libode-dev was not found)");
  return std::nullopt;
}

std::vector<std::string> ode_scene_names() { return {}; }

std::vector<std::string> checked_ode_methods(const std::vector<std::string>& methods) {
  return methods;
}

std::pair<std::string, std::string> ode_policy_and_method(const std::string&) { no_ode(); }

ScalingReference ode_reference(const ScalingScene&, const ScalingPlan&) { no_ode(); }

ScalingRecord ode_record(const ScalingScene&, const std::string&, std::uint32_t, const ScalingPlan&,
                         ScalingRecord) {
  no_ode();
}

#endif

}  // namespace tgraph::experiment::detail
