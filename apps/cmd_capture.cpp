// SPDX-License-Identifier: MIT
// `tgraph capture`: runs the instrumented engine on a scene and streams every step's task
// graph to a .tgt trace (or runs it uninstrumented with --no-capture).
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "commands.hpp"
#include "tgraph/capture/recorder.hpp"
#include "tgraph/samples/divergence.hpp"
#include "tgraph/samples/scene.hpp"

namespace tgraph::app {
namespace {

struct CaptureOptions {
  std::string scene;
  std::optional<int> steps;
  std::string output;
  std::optional<double> dt;
  std::uint64_t seed = 1;
  std::optional<int> subobjects;
  std::string coupling;
  bool no_capture = false;
  bool json = false;
};


void run_capture(const CaptureOptions& o) {
  if (!o.no_capture && o.output.empty()) throw UsageError("capture: -o/--output is required (or --no-capture)");
  if (o.steps && *o.steps < 1) throw UsageError("capture: --steps must be >= 1");
  samples::SceneOptions so;
  so.dt = o.dt;
  so.seed = o.seed;
  so.subobjects = o.subobjects;
  if (o.coupling == "groups") so.coupling = samples::Coupling::kGroups;
  if (o.coupling == "shared") so.coupling = samples::Coupling::kShared;
  std::unique_ptr<samples::Scene> scene = samples::make_scene(o.scene, so);
  for (const std::string& w : scene->warnings()) std::fprintf(stderr, "tgraph: warning: %s\n", w.c_str());
  const int steps = o.steps.value_or(scene->default_steps());
  // A file size limit (RLIMIT_FSIZE) then fails the write with EFBIG instead of killing us.
  ::signal(SIGXFSZ, SIG_IGN);

  capture::Recorder rec(o.no_capture ? capture::Mode::kOff : capture::Mode::kCapture);
  rec.set_derive_edges(false);  // the trace stores no edges; readers derive them
  std::unique_ptr<TraceWriter> writer;
  if (!o.no_capture) {
    writer = std::make_unique<TraceWriter>(o.output, scene_header(*scene, o.seed));
  }

  const bool progress = isatty(STDERR_FILENO) != 0;
  std::vector<double> step_ms;
  std::vector<std::uint32_t> cg_iterations;
  std::vector<std::uint32_t> groups;
  std::uint64_t tasks = 0;
  double seconds = 0.0;
  auto last_report = std::chrono::steady_clock::now();
  // A diverging simulation or a failed write stops the capture (exit 1); the steps written
  // before stay in the partial file (TraceWriter: <output>.partial).
  const auto stop = [&](const std::string& why) {
    std::string kept;
    if (writer)
      kept = "; the " + std::to_string(writer->steps_written()) + " complete steps before it are in " +
             writer->partial_path() + " (read with --recover)";
    throw Failure("capture: " + why + kept);
  };
  for (int s = 0; s < steps; ++s) {
    const auto t0 = std::chrono::steady_clock::now();
    try {
      scene->step(rec);
    } catch (const samples::DivergenceError& e) {
      stop(e.what());
    }
    StepGraph g = rec.end_step();
    const auto t1 = std::chrono::steady_clock::now();
    const double ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
    seconds += ms / 1000.0;
    step_ms.push_back(ms);
    const samples::StepStats st = scene->last_stats();
    cg_iterations.push_back(st.cg_iterations);
    groups.push_back(st.groups);
    tasks += g.tasks.size();
    if (writer) {
      try {
        writer->append(g);
      } catch (const Error& e) {
        stop("step " + std::to_string(s) + ": " + e.what());
      }
    }
    if (progress && (t1 - last_report > std::chrono::milliseconds(200) || s + 1 == steps)) {
      std::fprintf(stderr, "\rcapture %s: step %d/%d (%.1f ms/step)   ", scene->name().c_str(), s + 1, steps,
                   1000.0 * seconds / (s + 1));
      last_report = t1;
    }
  }
  if (progress) std::fprintf(stderr, "\n");
  std::uint64_t bytes = 0;
  if (writer) {
    try {
      writer->close();
    } catch (const Error& e) {
      stop(e.what());
    }
    bytes = writer->bytes_written();
  }
  if (rec.errors() != 0)
    throw Failure("capture: the recorder reported " + std::to_string(rec.errors()) + " API misuse(s)");

  if (o.json) {
    nlohmann::json j;
    j["scene"] = scene->name();
    j["mode"] = std::string(capture::to_string(rec.mode()));
    j["steps"] = steps;
    j["seconds"] = seconds;
    j["tasks"] = tasks;
    j["tasks_per_step"] = static_cast<double>(tasks) / steps;
    j["file_bytes"] = bytes;
    if (!o.output.empty() && !o.no_capture) j["output"] = o.output;
    j["dt"] = scene->solver().dt;
    j["seed"] = o.seed;
    j["bodies"] = scene->bodies().size();
    j["step_ms"] = step_ms;
    j["cg_iterations"] = cg_iterations;
    j["groups"] = groups;
    print_json(j);
  } else {
    std::printf("scene %s: %d steps in %.3f s (%.2f ms/step), %s", scene->name().c_str(), steps, seconds,
                1000.0 * seconds / steps, o.no_capture ? "not captured\n" : "");
    if (!o.no_capture)
      std::printf("%llu tasks, %llu bytes -> %s\n", static_cast<unsigned long long>(tasks),
                  static_cast<unsigned long long>(bytes), o.output.c_str());
  }
}

// "%g" of a double (std::to_string prints 1e308 with 309 digits).
std::string shortest(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

TraceHeader scene_header(const samples::Scene& scene, std::uint64_t seed) {
  TraceHeader header;
  header.scene = scene.name();
  header.engine = std::string("tgraph-samples ") + TGRAPH_VERSION + " (" +
                  std::string(samples::to_string(scene.solver().integrator)) + " Euler, dt " +
                  shortest(scene.solver().dt) + ", seed " + std::to_string(seed) + ")";
  header.machine = machine_description();
  header.tgraph_version = TGRAPH_VERSION;
  return header;
}

void add_capture(CLI::App& app) {
  auto o = std::make_shared<CaptureOptions>();
  CLI::App* cmd = app.add_subcommand("capture", "Run the instrumented engine on a scene and record each step's task graph");
  cmd->add_option("--scene", o->scene, "Built-in scene (fig2, bars64, falling, cloth128, cloth256, cloth512, torso) or scene file")
      ->required();
  cmd->add_option("--steps", o->steps, "Steps to run (default: the scene's)");
  cmd->add_option("-o,--output", o->output, "Trace file to write (.tgt)");
  cmd->add_option("--dt", o->dt, "Time step override (s)");
  cmd->add_option("--seed", o->seed, "Seed of the scene's random placement");
  cmd->add_option("--subobjects", o->subobjects, "Cloth scenes: number of sub-objects (a perfect square)");
  cmd->add_option("--coupling", o->coupling, "Solver sharing: groups (one CG per collision group) or shared")
      ->check(CLI::IsMember({"groups", "shared"}));
  cmd->add_flag("--no-capture", o->no_capture, "Run the same steps uninstrumented (Mode::kOff), write nothing");
  cmd->add_flag("--json", o->json, "Print a JSON summary");
  cmd->callback([o] { run_capture(*o); });
}

}  // namespace tgraph::app
