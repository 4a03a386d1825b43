// SPDX-License-Identifier: MIT
// `tgraph capture`'s pipeline: scene -> Recorder -> TraceWriter, step after step.
#include "tgraph/samples/capture_run.hpp"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "tgraph/capture/recorder.hpp"
#include "tgraph/capture/write_step.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/samples/divergence.hpp"

namespace tgraph::samples {
namespace {

// "%g" of a double (std::to_string prints 1e308 with 309 digits).
std::string shortest(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

TraceHeader scene_header(const Scene& scene, std::uint64_t seed) {
  TraceHeader header;
  header.scene = scene.name();
  header.engine = std::string("tgraph-samples ") + TGRAPH_VERSION + " (" +
                  std::string(to_string(scene.solver().integrator)) + " Euler, dt " +
                  shortest(scene.solver().dt) + ", seed " + std::to_string(seed) + ")";
  header.machine = machine_description();
  header.tgraph_version = TGRAPH_VERSION;
  return header;
}

CaptureRun capture_scene(const CaptureOptions& o) {
  if (!o.no_capture && o.output.empty())
    throw OptionError("output", "is required (or {no_capture})");
  if (o.steps && *o.steps < 1) throw OptionError("steps", "must be at least 1");
  std::unique_ptr<Scene> scene = make_scene(o.scene, o.scene_options);
  CaptureRun run;
  run.scene = scene->name();
  if (o.warn)
    for (const std::string& w : scene->warnings()) o.warn(w);
  run.steps = o.steps.value_or(scene->default_steps());
  run.dt = scene->solver().dt;
  run.bodies = scene->bodies().size();

  capture::Recorder rec(o.no_capture ? capture::Mode::kOff : capture::Mode::kCapture);
  run.mode = std::string(capture::to_string(rec.mode()));
  rec.set_derive_edges(false);  // the trace stores no edges; readers derive them
  if (o.cost_passes == 0) throw OptionError("cost_passes", "must be at least 1");
  rec.set_cost_passes(o.cost_passes);
  if (o.verify_accesses && o.no_capture)
    throw OptionError("verify_accesses", "needs the capture (not {no_capture})");
  rec.set_verify_accesses(o.verify_accesses);
  run.cost_passes = o.cost_passes;
  std::unique_ptr<TraceWriter> writer;
  if (!o.no_capture)
    writer = std::make_unique<TraceWriter>(o.output, scene_header(*scene, o.scene_options.seed));

  // A diverging simulation or a failed write stops the capture; the steps written before
  // stay in the partial file (TraceWriter: <output>.partial).
  const auto stop = [&](const std::string& why) {
    if (!writer) throw CaptureFailure("capture: " + why);
    throw CaptureFailure("capture: " + why + "; the " + std::to_string(writer->steps_written()) +
                             " complete steps before it are in " + writer->partial_path() + " (",
                         "read with {recover})", kNamesFields);
  };
  auto last_report = std::chrono::steady_clock::now();
  for (int s = 0; s < run.steps; ++s) {
    const auto t0 = std::chrono::steady_clock::now();
    try {
      scene->step(rec);
    } catch (const DivergenceError& e) {
      stop(e.what());
    }
    StepGraph g = rec.end_step();
    if (rec.step_errors() != 0 && !o.allow_misuse) {
      // The graph is not what the engine ran: refuse the step, name the first misuse.
      const std::string refused = "step " + std::to_string(s) +
                                  " is not written: write it anyway with {allow_misuse}";
      const std::string what = "capture: " + capture::step_misuse_line(rec) + "; ";
      if (!writer) throw CaptureFailure(what, refused, kNamesFields);
      throw CaptureFailure(what + "the " + std::to_string(writer->steps_written()) +
                               " complete steps before it are in " + writer->partial_path() + " (",
                           "read with {recover}); " + refused, kNamesFields);
    }
    const auto t1 = std::chrono::steady_clock::now();
    const double ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
    run.seconds += ms / 1000.0;
    run.step_ms.push_back(ms);
    const StepStats st = scene->last_stats();
    run.cg_iterations.push_back(st.cg_iterations);
    run.groups.push_back(st.groups);
    run.tasks += g.tasks.size();
    if (writer) {
      try {
        writer->append(g);
      } catch (const Error& e) {
        stop("step " + std::to_string(s) + ": " + e.what());
      }
    }
    if (o.progress && (t1 - last_report > std::chrono::milliseconds(200) || s + 1 == run.steps)) {
      std::fprintf(stderr, "\rcapture %s: step %d/%d (%.1f ms/step)   ", run.scene.c_str(), s + 1,
                   run.steps, 1000.0 * run.seconds / (s + 1));
      last_report = t1;
    }
  }
  if (o.progress) std::fprintf(stderr, "\n");
  if (writer) {
    try {
      writer->close();
    } catch (const Error& e) {
      stop(e.what());
    }
    run.file_bytes = writer->bytes_written();
  }
  run.single_pass_runs = rec.single_pass_runs();
  run.misuses = rec.errors();
  run.access_findings = rec.access_findings();
  if (const AccessChecker::Counts* c = rec.access_counts()) run.access_counts = *c;
  if (run.misuses != 0 && o.warn)
    o.warn("the recorder counted " + std::to_string(run.misuses) +
           " API misuse(s), written anyway; the first: " + capture::to_string(rec.misuses()[0]));
  return run;
}

std::string capture_json(const CaptureRun& r, const CaptureOptions& o) {
  nlohmann::json j;
  j["scene"] = r.scene;
  j["mode"] = r.mode;
  j["steps"] = r.steps;
  j["seconds"] = r.seconds;
  j["tasks"] = r.tasks;
  j["tasks_per_step"] = static_cast<double>(r.tasks) / r.steps;
  j["file_bytes"] = r.file_bytes;
  if (!o.output.empty() && !o.no_capture) j["output"] = o.output;
  j["dt"] = r.dt;
  j["seed"] = o.scene_options.seed;
  j["bodies"] = r.bodies;
  j["step_ms"] = r.step_ms;
  j["cg_iterations"] = r.cg_iterations;
  j["groups"] = r.groups;
  j["cost_passes"] = r.cost_passes;
  j["single_pass_runs"] = r.single_pass_runs;
  j["misuses"] = r.misuses;
  if (o.verify_accesses) {
    nlohmann::json f = nlohmann::json::array();
    for (const AccessFinding& a : r.access_findings)
      f.push_back({{"task", a.task},
                   {"datum", a.datum},
                   {"found", std::string(to_string(a.found))},
                   {"declared", a.declared}});
    j["access_findings"] = f;
    j["access_check"] = {{"runs", r.access_counts.runs},
                         {"reruns", r.access_counts.reruns},
                         {"reads_unchecked", r.access_counts.reads_unchecked}};
  }
  return j.dump();
}

std::string capture_text(const CaptureRun& r, const CaptureOptions& o) {
  char line[1024];
  std::snprintf(line, sizeof line, "scene %s: %d steps in %.3f s (%.2f ms/step), %s",
                r.scene.c_str(), r.steps, r.seconds, 1000.0 * r.seconds / r.steps,
                o.no_capture ? "not captured\n" : "");
  std::string out = line;
  if (!o.no_capture) {
    std::snprintf(line, sizeof line, "%llu tasks, %llu bytes -> ",
                  static_cast<unsigned long long>(r.tasks),
                  static_cast<unsigned long long>(r.file_bytes));
    out += line + o.output + "\n";
  }
  if (o.verify_accesses) {
    std::snprintf(line, sizeof line,
                  "verify-accesses: %llu task runs checked, %llu reruns, %llu not checked for "
                  "reads (they write data without storage): %zu finding(s)\n",
                  static_cast<unsigned long long>(r.access_counts.runs),
                  static_cast<unsigned long long>(r.access_counts.reruns),
                  static_cast<unsigned long long>(r.access_counts.reads_unchecked),
                  r.access_findings.size());
    out += line;
    for (const AccessFinding& a : r.access_findings) out += "  " + to_string(a) + "\n";
  }
  return out;
}

}  // namespace tgraph::samples
