// SPDX-License-Identifier: MIT
// `tgraph capture`: the instrumented engine on a scene, every step streamed to a .tgt trace
// (samples::capture_scene), or run uninstrumented with --no-capture.
#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <iostream>
#include <stdexcept>

#include "commands.hpp"
#include "ode_verbs.hpp"
#include "option_words.hpp"
#include "tgraph/samples/capture_run.hpp"

namespace tgraph::app {

void add_capture(CLI::App& app) {
  using enum samples::Coupling;
  auto o = std::make_shared<samples::CaptureOptions>();
  auto a = std::make_shared<Args>();
  auto* cmd = app.add_subcommand(
      "capture", "Run the instrumented engine on a scene and record each step's task graph");
  cmd->add_option("--scene", o->scene,
                  "Built-in scene (" + CLI::detail::join(samples::builtin_scene_names(), ", ") +
                      ") or scene file")
      ->required();
  cmd->add_option("--steps", o->steps, "Steps to run (default: the scene's)");
  cmd->add_option("-o,--output", o->output, "Trace file to write (.tgt)");
  cmd->add_option("--dt", o->scene_options.dt, "Time step override (s)");
  cmd->add_option("--seed", o->scene_options.seed, "Seed of the scene's random placement");
  cmd->add_option("--subobjects", o->scene_options.subobjects,
                  "Cloth scenes: number of sub-objects (a perfect square)");
  cmd->add_option("--split", o->scene_options.split,
                  "Deformable objects: split each internal force field into N tasks (overrides split=)")
      ->check(CLI::Range(1, 1024));
  add_enum(cmd, "--coupling", o->scene_options.coupling, {kGroups, kShared},
           "Solver sharing: groups (one CG per collision group) or shared");
  cmd->add_option("--cost-passes", o->cost_passes,
                  "Time every task body N times from the same state (its written data restored "
                  "between passes) and keep the median (default 1)")
      ->check(CLI::Range(1u, 1000u));
  cmd->add_flag("--no-capture", o->no_capture,
                "Run the same steps uninstrumented (Mode::kOff), write nothing");
  cmd->add_flag("--allow-misuse", o->allow_misuse,
                "Write steps in which the recorder saw API misuses (an unbalanced loop, a "
                "changed loop body...) instead of stopping before the first, with a warning");
  cmd->add_flag("--verify-accesses", o->verify_accesses,
                "Run every task between checksums of the state and again with its undeclared "
                "data perturbed; list each write or read it does not declare (exit 1 when any; "
                "docs/instrumenting.md, \"Finding a wrong declaration\")");
  cmd->add_flag("--json", a->json, "Print a JSON summary");
  auto ode = std::make_shared<OdeFlags>();
  add_ode_capture_flags(cmd, *ode);
  cmd->callback([o, a, ode] {
    if (is_ode_scene(o->scene) && o->verify_accesses)  // ODE declares dependencies, no data
      throw UsageError("--verify-accesses: ODE's calls declare no data accesses (" + o->scene +
                       " is captured through ODE's threading interface)");
    if (is_ode_scene(o->scene))  // ODE's scenes: tgraph::ode (apps/cmd_ode.cpp)
      return capture_ode(o->scene, o->steps, o->output, a->json, *ode);
    o->progress = isatty(STDERR_FILENO) != 0;
    o->warn = [](const std::string& w) { warn(name_fields(w, flag_of)); };
    // A file size limit (RLIMIT_FSIZE) then fails the write with EFBIG instead of killing us.
    ::signal(SIGXFSZ, SIG_IGN);
    const samples::CaptureRun r = samples::capture_scene(*o);
    std::cout << (a->json ? samples::capture_json(r, *o) + "\n" : samples::capture_text(r, *o))
              << std::flush;
    if (!r.access_findings.empty())
      throw std::runtime_error("capture: " + std::to_string(r.access_findings.size()) +
                               " wrong access declaration(s) found (listed in the report)");
  });
}

}  // namespace tgraph::app
