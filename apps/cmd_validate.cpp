// SPDX-License-Identifier: MIT
// `tgraph validate`: live run, replay of a capture and simulator side by side (measure::validate).
#include <iostream>

#include "commands.hpp"
#include "flags.hpp"
#include "ode_verbs.hpp"
#include "tgraph/measure/report.hpp"
#include "tgraph/measure/validate.hpp"

namespace tgraph::app {

void add_validate(CLI::App& app) {
  auto o = std::make_shared<measure::ValidateOptions>();
  auto a = std::make_shared<Args>();
  o->threads = default_threads();
  a->method = "owner";
  auto* cmd = app.add_subcommand(
      "validate", "Live run, replay of a capture and simulator side by side, with their ratios");
  cmd->add_option("--scene", o->scene, "Built-in scene or scene file")->required();
  cmd->add_option("--threads,-k", o->threads, "Threads");
  cmd->add_option("--method", a->method,
                  "Partitioning strategy, or a baseline policy (worksteal, barrier, sequential)");
  cmd->add_option("--steps", o->steps, "Steps (default 20; ODE scenes: the scene's, as run)");
  cmd->add_option("--split", o->scene_options.split, "Force-field tasks per deformable object")
      ->check(CLI::Range(1, 1024));
  cmd->add_option("--repeat", o->repeat,
                  "Rounds of live pass, capture, replay pass and simulation (medians; default 3)");
  cmd->add_option("--calibration", o->calibration, "Calibration file (default: the default one)");
  cmd->add_flag("!--no-live-serial", o->live_serial,
                "Charge the capture's host time in the prediction instead of the live run's "
                "serial work per step (record, partition wait, prepare)");
  cmd->add_flag("--json", a->json, "Print one JSON object");
  auto ode = std::make_shared<OdeFlags>();
  add_ode_flags(cmd, *ode);
  cmd->callback([cmd, o, a, ode] {
    if (is_ode_scene(o->scene))  // ODE's scenes: tgraph::ode (apps/cmd_ode.cpp)
      return validate_ode(
          o->scene, cmd->count("--steps") ? std::optional<std::uint32_t>(o->steps) : std::nullopt,
          a->method, o->threads, o->repeat, o->calibration, a->json, *ode);
    o->method = method_flags(a->method);
    const measure::Validation v = measure::validate(*o);
    std::cout << (a->json ? measure::to_json(v, *o) : measure::to_text(v, *o));
  });
}

}  // namespace tgraph::app
