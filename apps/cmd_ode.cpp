// SPDX-License-Identifier: MIT
// The ODE scenes of `run`, `capture` and `validate` (ode_verbs.hpp).
#include <iostream>

#include "commands.hpp"
#include "ode_verbs.hpp"
#if TGRAPH_HAVE_ODE
#include "tgraph/ode/run.hpp"
#include "tgraph/ode/scenes.hpp"
#endif

namespace tgraph::app {
namespace {

// `owner`, the verbs' default strategy, follows objects; ODE's calls have none (its own
// fallback would be list): an ODE scene's default is tgraph's best policy there,
// islands-serial (docs/ode.md).
[[maybe_unused]] std::string ode_method(const std::string& method) {
  return method == "owner" ? "islands-serial" : method;
}

[[maybe_unused]] void no_ode(const std::string& scene) {
  throw InputError(scene, std::nullopt,
                   "ODE scene, but this tgraph was built without tgraph::ode (pkg-config ode, "
                   "Debian libode-dev)");
}

}  // namespace

bool is_ode_scene(const std::string& scene) { return scene.rfind("ode-", 0) == 0; }

void add_ode_flags(CLI::App* cmd, OdeFlags& flags) {
  cmd->add_option("--stepper", flags.stepper,
                  "ODE scenes: quickstep (dWorldQuickStep) or step (dWorldStep)")
      ->check(CLI::IsMember({"quickstep", "step"}));
  cmd->add_option(
         "--repartition-interval", flags.repartition_interval,
         "ODE scenes, a partition strategy: steps between partitionings of a recorded step")
      ->check(CLI::Range(1u, 1000000u));
}

void add_ode_capture_flags(CLI::App* cmd, OdeFlags& flags) {
  cmd->add_option("--stepper", flags.stepper,
                  "ODE scenes: quickstep (dWorldQuickStep) or step (dWorldStep)")
      ->check(CLI::IsMember({"quickstep", "step"}));
  cmd->add_option("--threads,-k", flags.threads,
                  "ODE scenes: threads ODE posts its calls for (default 2)")
      ->check(CLI::Range(1u, 1024u));
  cmd->add_option("--method,-m", flags.method,
                  "ODE scenes: the policy whose steps are recorded: islands-serial (default: "
                  "whole islands side by side, each stepped single-threaded), worksteal or "
                  "islands (ODE's K-thread stages), or a partition strategy");
}

#if TGRAPH_HAVE_ODE

void run_ode(const std::string& scene, std::optional<std::uint32_t> steps,
             const std::string& method, std::uint32_t threads, std::uint32_t repeat, bool check,
             bool json, double timeout_s, const OdeFlags& flags) {
  ode::RunOptions o = ode::run_options(scene, steps, ode::choose_method(ode_method(method)),
                                       threads, repeat, ode::parse_stepper(flags.stepper));
  o.check = check;
  o.watchdog_s = timeout_s;
  o.repartition_interval = flags.repartition_interval;
  o.json = json;
  const ode::RunResult r = ode::run_scene(o);
  std::cout << (json ? ode::to_json(r) : ode::to_text(r)) << std::flush;
  if (r.check == "differs") throw Failure(ode::differs_line(r));
}

void capture_ode(const std::string& scene, std::optional<int> steps, const std::string& output,
                 bool json, const OdeFlags& flags) {
  ode::CaptureOptions o;
  o.scene = scene;
  if (steps) {
    if (*steps <= 0) throw OptionError("steps", "must be at least 1");
    o.steps = static_cast<std::uint32_t>(*steps);
  }
  o.output = output;
  o.threads = flags.threads;
  o.stepper = ode::parse_stepper(flags.stepper);
  o.method = ode::choose_method(flags.method);
  const ode::CaptureReport r = ode::capture_scene(o);
  std::cout << (json ? ode::to_json(r) : ode::to_text(r)) << std::flush;
}

void validate_ode(const std::string& scene, std::optional<std::uint32_t> steps,
                  const std::string& method, std::uint32_t threads, std::uint32_t repeat,
                  const std::string& calibration, bool json, const OdeFlags& flags) {
  const ode::ValidateReport r = ode::validate_scene(
      ode::validate_options(ode::run_options(scene, steps, ode::choose_method(ode_method(method)),
                                             threads, repeat, ode::parse_stepper(flags.stepper)),
                            calibration));
  std::cout << (json ? ode::to_json(r) : ode::to_text(r)) << std::flush;
}

#else

void run_ode(const std::string& scene, std::optional<std::uint32_t>, const std::string&,
             std::uint32_t, std::uint32_t, bool, bool, double, const OdeFlags&) {
  no_ode(scene);
}
void capture_ode(const std::string& scene, std::optional<int>, const std::string&, bool,
                 const OdeFlags&) {
  no_ode(scene);
}
void validate_ode(const std::string& scene, std::optional<std::uint32_t>, const std::string&,
                  std::uint32_t, std::uint32_t, const std::string&, bool, const OdeFlags&) {
  no_ode(scene);
}

#endif

}  // namespace tgraph::app
