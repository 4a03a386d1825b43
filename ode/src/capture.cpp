// SPDX-License-Identifier: MIT
#include <chrono>
#include <nlohmann/json.hpp>
#include <sstream>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/median.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/ode/run.hpp"
#include "tgraph/ode/scenes.hpp"

namespace tgraph::ode {

CaptureReport capture_scene(const CaptureOptions& options) {
  if (!is_scene(options.scene))
    throw InputError(options.scene, std::nullopt,
                     "unknown ODE scene (ode-piles, ode-heap, ode-chains)");
  if (options.threads == 0) throw OptionError("threads", "must be at least 1");
  if (options.output.empty()) throw OptionError("output", "a .tgt file to write is required");
  if (options.steps && *options.steps == 0) throw OptionError("steps", "must be at least 1");
  dInitODE2(0);
  struct Close {
    ~Close() { dCloseODE(); }
  } close;
  CaptureReport report;
  report.options = options;
  AttachOptions a;
  a.threads = options.threads;
  a.method = options.method;
  // The same steps recorded and not, in one run, five times each alternating (medians): the
  // recording's cost. The last recorded pass is the one written.
  std::vector<StepGraph> steps;
  std::vector<std::int64_t> off, on;
  report.steps = options.steps.value_or(default_steps(options.scene));
  // The recorded passes' logs are made and written when attaching, before the timed steps.
  a.reserve_steps = report.steps;
  a.reserve_room =
      recording_room(options.scene, options.stepper, a.threads, report.steps, a.method);
  constexpr int kRounds = 5;  // a 50-step pass of ode-piles is some 50 ms: five for a median
  for (int round = 0; round < kRounds; ++round) {
    for (const bool record : {false, true}) {
      auto scene = Scene::make(options.scene, options.stepper, 0);
      a.record = record;
      Attachment attach(scene->world(), a);
      const auto t0 = std::chrono::steady_clock::now();
      for (std::uint32_t i = 0; i < report.steps; ++i) scene->step(&attach);
      const std::int64_t ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                  std::chrono::steady_clock::now() - t0)
                                  .count();
      (record ? on : off).push_back(ns);
      if (record && round == kRounds - 1)
        steps = attach.take_steps();  // built after the timed steps
    }
  }
  report.unrecorded_ns = median(off);
  report.recorded_ns = median(on);
  report.overhead = report.unrecorded_ns > 0 ? static_cast<double>(report.recorded_ns) /
                                                       static_cast<double>(report.unrecorded_ns) -
                                                   1.0
                                             : 0.0;
  TraceHeader header;
  header.scene = options.scene;
  header.engine = "ODE " + std::string(to_string(options.stepper)) + " through tgraph::ode (" +
                  std::to_string(options.threads) + " threads, " + method_name(options.method) +
                  ")";
  header.machine = machine_description();
  header.tgraph_version = TGRAPH_VERSION;
  TraceWriter writer(options.output, header);
  for (const StepGraph& g : steps) {
    writer.append(g);
    report.tasks += g.tasks.size();
    report.edges += g.edges.size();
  }
  writer.close();
  report.bytes = writer.bytes_written();
  return report;
}

RecordingRoom recording_room(const std::string& scene_name, Stepper stepper, std::uint32_t threads,
                             std::uint32_t steps, const Method& method) {
  auto scene = Scene::make(scene_name, stepper, 0);
  AttachOptions a;
  a.threads = threads;
  a.method = method;
  a.record = true;
  Attachment attach(scene->world(), a);
  for (std::uint32_t i = 0; i < steps; ++i) {
    scene->step(&attach);
    attach.drop_steps();  // only the maxima are wanted: one step's log held at a time
  }
  return attach.recording_room();
}

std::string to_json(const CaptureReport& r) {
  const nlohmann::ordered_json j = {{"scene", r.options.scene},
                                    {"steps", r.steps},
                                    {"tasks", r.tasks},
                                    {"edges", r.edges},
                                    {"bytes", r.bytes},
                                    {"recorded_ns", r.recorded_ns},
                                    {"unrecorded_ns", r.unrecorded_ns},
                                    {"capture_overhead", r.overhead},
                                    {"output", r.options.output}};
  return j.dump() + "\n";
}

std::string to_text(const CaptureReport& r) {
  std::ostringstream out;
  out << "captured " << r.options.scene << ": " << r.steps << " steps, " << r.tasks << " tasks, "
      << r.edges << " edges -> " << r.options.output << " (" << r.bytes
      << " bytes); recording cost " << r.overhead * 100.0 << " % ("
      << static_cast<double>(r.recorded_ns) / 1e6 << " ms against "
      << static_cast<double>(r.unrecorded_ns) / 1e6 << " ms unrecorded, same run)\n";
  return out.str();
}

}  // namespace tgraph::ode
