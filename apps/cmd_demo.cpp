// SPDX-License-Identifier: MIT
// `tgraph demo` (and `tgraph` alone): capture a built-in scene, partition it with every
// strategy, evaluate each offline, replay each on all cores against the work-stealing and
// barrier baselines, print the comparison and write a self-contained HTML report.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <thread>

#include "commands.hpp"
#include "tgraph/capture/recorder.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/graph/metrics.hpp"
#include "tgraph/partition/cost_model.hpp"
#include "tgraph/partition/evaluate.hpp"
#include "tgraph/partition/strategy.hpp"
#include "tgraph/replay/measure.hpp"
#include "tgraph/samples/scene.hpp"

namespace tgraph::app {
namespace {

namespace tp = tgraph::partition;
namespace tr = tgraph::replay;

struct DemoOptions {
  std::string scene = "bars64";
  int steps = 10;
  std::uint32_t threads = default_threads();
  std::uint32_t repeat = 3;
  std::string out_dir = "tgraph-demo";
  bool json = false;
};

// One row of the comparison.
struct Row {
  std::string name;              // strategy or baseline policy
  bool partitioned = false;      // a graph partition (else a dynamic baseline)
  double partition_ms = 0;
  double imbalance = 0;
  std::uint64_t cut_bytes = 0;
  std::uint64_t migrated_tasks = 0;
  double predicted_speedup = 0;
  double measured_ms = 0;
  double sequential_ms = 0;
  double speedup = 0;
  double efficiency = 0;
  std::uint64_t signals = 0;
  std::string failure;           // why the replay could not run (empty: it ran)
};

Trace capture_scene(const DemoOptions& o) {
  auto scene = samples::make_scene(o.scene, {});
  capture::Recorder rec(capture::Mode::kCapture);
  Trace trace;
  trace.header = scene_header(*scene, 1);
  for (int s = 0; s < o.steps; ++s) {
    scene->step(rec);
    trace.steps.push_back(rec.end_step());
  }
  if (rec.errors() != 0) throw Failure("demo: the capture API reported " + std::to_string(rec.errors()) + " misuses");
  return trace;
}

tr::ReplayResult replay(const Trace& trace, const TraceAssignment* a, tr::Policy policy,
                        const DemoOptions& o) {
  tr::ReplayOptions ro;
  ro.policy = policy;
  ro.exec.threads = policy == tr::Policy::kSequential ? 1 : o.threads;
  ro.repeat = o.repeat;
  return tr::replay_trace(trace, a, ro);
}

void fill_measured(Row& row, const tr::ReplayResult& r) {
  row.measured_ms = static_cast<double>(r.wall_ns) / 1e6;
  row.sequential_ms = static_cast<double>(r.sequential_wall_ns) / 1e6;
  row.speedup = r.speedup;
  row.efficiency = r.efficiency;
  row.signals = r.signals();
}

std::string html_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '&': out += "&amp;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

// Self-contained page: the table plus an inline SVG bar chart of measured and predicted
// speed-ups (no script, no external resource).
std::string html_report(const DemoOptions& o, const Metrics& m, const Trace& trace,
                        const std::vector<Row>& rows) {
  std::ostringstream h;
  h << "<!doctype html><html><head><meta charset=\"utf-8\"><title>tgraph demo: "
    << html_escape(o.scene) << "</title><style>body{font-family:sans-serif;margin:2em}"
    << "table{border-collapse:collapse}td,th{border:1px solid #999;padding:4px 8px;text-align:right}"
    << "th{background:#eee}td:first-child{text-align:left}</style></head><body>";
  h << "<h1>tgraph demo: " << html_escape(o.scene) << ", " << o.steps << " steps, " << o.threads
    << " threads</h1>";
  h << "<p>" << trace.steps.size() << " steps, " << m.tasks << " tasks in step 0, work "
    << static_cast<double>(m.work_ns) / 1e6 << " ms, span " << static_cast<double>(m.span_ns) / 1e6
    << " ms, parallelism " << m.parallelism << " (step 0). Machine: " << html_escape(trace.header.machine)
    << ". Wall times are medians of " << o.repeat
    << " passes; speed-up is against sequential replay timed in the same run.</p>";
  h << "<table><tr><th>method</th><th>partition ms</th><th>imbalance</th><th>cut bytes</th>"
    << "<th>migrated tasks</th><th>predicted speed-up</th><th>measured ms</th><th>sequential ms</th>"
    << "<th>speed-up</th><th>efficiency</th><th>signals</th></tr>";
  for (const Row& r : rows) {
    h << "<tr><td>" << html_escape(r.name) << "</td>";
    if (r.partitioned)
      h << "<td>" << r.partition_ms << "</td><td>" << r.imbalance << "</td><td>" << r.cut_bytes << "</td><td>"
        << r.migrated_tasks << "</td><td>" << r.predicted_speedup << "</td>";
    else
      h << "<td>-</td><td>-</td><td>-</td><td>-</td><td>-</td>";
    if (!r.failure.empty()) {
      h << "<td colspan=\"5\">replay failed: " << html_escape(r.failure) << "</td></tr>";
      continue;
    }
    h << "<td>" << r.measured_ms << "</td><td>" << r.sequential_ms << "</td><td>" << r.speedup << "</td><td>"
      << r.efficiency << "</td><td>" << r.signals << "</td></tr>";
  }
  h << "</table>";
  // Bar chart.
  double top = static_cast<double>(o.threads);
  for (const Row& r : rows) top = std::max({top, r.speedup, r.predicted_speedup});
  const int bar_h = 18, gap = 10, left = 110, width = 500;
  const int height = static_cast<int>(rows.size()) * (2 * bar_h + gap) + 40;
  h << "<h2>Speed-up over sequential</h2><svg xmlns=\"http://www.w3.org/2000/svg\" width=\""
    << left + width + 80 << "\" height=\"" << height << "\">";
  int y = 10;
  for (const Row& r : rows) {
    const double wm = r.speedup / top * width, wp = r.predicted_speedup / top * width;
    h << "<text x=\"0\" y=\"" << y + bar_h << "\" font-size=\"12\">" << html_escape(r.name) << "</text>";
    h << "<rect x=\"" << left << "\" y=\"" << y << "\" width=\"" << wm << "\" height=\"" << bar_h
      << "\" fill=\"#3a7\"><title>measured " << r.speedup << "</title></rect>";
    h << "<text x=\"" << left + wm + 4 << "\" y=\"" << y + 13 << "\" font-size=\"11\">" << r.speedup
      << " measured</text>";
    if (r.partitioned) {
      h << "<rect x=\"" << left << "\" y=\"" << y + bar_h << "\" width=\"" << wp << "\" height=\"" << bar_h
        << "\" fill=\"#9bd\"><title>predicted " << r.predicted_speedup << "</title></rect>";
      h << "<text x=\"" << left + wp + 4 << "\" y=\"" << y + bar_h + 13 << "\" font-size=\"11\">"
        << r.predicted_speedup << " predicted</text>";
    }
    y += 2 * bar_h + gap;
  }
  const double xk = left + static_cast<double>(o.threads) / top * width;
  h << "<line x1=\"" << xk << "\" y1=\"0\" x2=\"" << xk << "\" y2=\"" << y
    << "\" stroke=\"#c33\" stroke-dasharray=\"4\"/><text x=\"" << xk + 2 << "\" y=\"" << y + 14
    << "\" font-size=\"11\" fill=\"#c33\">" << o.threads << " threads</text></svg></body></html>\n";
  return h.str();
}

void run_demo(const DemoOptions& o) {
  if (o.steps < 1) throw UsageError("demo: --steps must be >= 1");
  if (o.threads < 1) throw UsageError("demo: --threads must be >= 1");
  std::filesystem::create_directories(o.out_dir);
  const auto say = [&](const std::string& s) {
    if (!o.json) std::fprintf(stderr, "%s\n", s.c_str());
  };
  say("capturing " + o.scene + " (" + std::to_string(o.steps) + " steps)...");
  const Trace trace = capture_scene(o);
  const std::string trace_path = o.out_dir + "/" + o.scene + ".tgt";
  write_trace(trace_path, trace);
  const Metrics m0 = compute_metrics(trace.steps.front());

  const tp::CostModel model = tp::select_cost_model("calibrated", "");

  std::vector<Row> rows;
  for (const std::string& method : tp::strategy_names()) {
    if (method == "single") continue;  // the null strategy: everything on processor 0
    say("partitioning with " + method + " and replaying on " + std::to_string(o.threads) + " threads...");
    const tp::TracePartition part = tp::partition_trace(trace, method, o.threads);
    const tp::Report ev = tp::evaluate(trace, part.assignment, model, method);
    Row row;
    row.name = method;
    row.partitioned = true;
    for (double ms : part.assignment.partition_ms) row.partition_ms += ms;
    row.imbalance = ev.total.imbalance;
    row.cut_bytes = ev.total.cut_bytes;
    row.migrated_tasks = ev.total.migrated_tasks;
    row.predicted_speedup = ev.total.speedup;
    try {
      fill_measured(row, replay(trace, &part.assignment, tr::Policy::kPartition, o));
    } catch (const Error& e) {
      row.failure = e.what();  // reported in the table, the other methods still run
      say("  replay failed: " + row.failure);
    }
    rows.push_back(row);
  }
  std::vector<tr::Policy> baselines = {tr::Policy::kWorksteal, tr::Policy::kBarrier};
#ifdef TGRAPH_HAVE_STARPU
  baselines.push_back(tr::Policy::kStarpu);
#else
  say("starpu: not in this build (libstarpu-dev was not found), no starpu row");
#endif
  for (tr::Policy p : baselines) {
    say("replaying with " + std::string(tr::to_string(p)) + "...");
    Row row;
    row.name = std::string(tr::to_string(p));
    try {
      fill_measured(row, replay(trace, nullptr, p, o));
    } catch (const Error& e) {
      row.failure = e.what();
      say("  replay failed: " + row.failure);
    }
    rows.push_back(row);
  }
  const std::string report_path = o.out_dir + "/report.html";
  write_file_atomic(report_path, html_report(o, m0, trace, rows));

  if (o.json) {
    nlohmann::json j = {{"scene", o.scene}, {"steps", o.steps}, {"threads", o.threads},
                        {"trace", trace_path}, {"report", report_path}, {"rows", nlohmann::json::array()}};
    for (const Row& r : rows)
      j["rows"].push_back({{"method", r.name}, {"partitioned", r.partitioned}, {"partition_ms", r.partition_ms},
                           {"imbalance", r.imbalance}, {"cut_bytes", r.cut_bytes},
                           {"migrated_tasks", r.migrated_tasks}, {"predicted_speedup", r.predicted_speedup},
                           {"wall_ns", r.measured_ms * 1e6}, {"sequential_wall_ns", r.sequential_ms * 1e6},
                           {"speedup", r.speedup}, {"efficiency", r.efficiency}, {"signals", r.signals},
                           {"replay_failure", r.failure.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.failure)}});
    print_json(j);
    return;
  }
  std::printf("\n%s: %d steps, %llu tasks/step, parallelism %.1f, %u threads (replay: medians of %u passes)\n\n",
              o.scene.c_str(), o.steps, static_cast<unsigned long long>(m0.tasks), m0.parallelism, o.threads,
              o.repeat);
  std::printf("%-13s %10s %9s %12s %9s %10s %11s %11s %8s %6s\n", "method", "part. ms", "imbalance",
              "cut bytes", "migrated", "predicted", "replay ms", "seq. ms", "speedup", "eff.");
  for (const Row& r : rows) {
    if (r.partitioned)
      std::printf("%-13s %10.2f %9.3f %12llu %9llu %9.2fx", r.name.c_str(), r.partition_ms, r.imbalance,
                  static_cast<unsigned long long>(r.cut_bytes), static_cast<unsigned long long>(r.migrated_tasks),
                  r.predicted_speedup);
    else
      std::printf("%-13s %10s %9s %12s %9s %10s", r.name.c_str(), "-", "-", "-", "-", "-");
    if (!r.failure.empty())
      std::printf("  replay failed: %s\n", r.failure.c_str());
    else
      std::printf(" %11.2f %11.2f %7.2fx %6.2f\n", r.measured_ms, r.sequential_ms, r.speedup, r.efficiency);
  }
  std::printf("\ntrace: %s\nreport: %s\n", trace_path.c_str(), report_path.c_str());
}

}  // namespace

void add_demo(CLI::App& app) {
  auto o = std::make_shared<DemoOptions>();
  auto* cmd = app.add_subcommand("demo", "Default job: capture, partition with every strategy, replay, compare");
  cmd->add_option("--scene", o->scene, "Built-in scene or scene file");
  cmd->add_option("--steps", o->steps, "Steps to capture");
  cmd->add_option("--threads", o->threads, "Replay threads (default: all hardware threads)");
  cmd->add_option("--repeat", o->repeat, "Timed passes per replay (medians)");
  cmd->add_option("--out", o->out_dir, "Folder for the trace and report.html");
  cmd->add_flag("--json", o->json, "Print one JSON object");
  cmd->callback([o] { run_demo(*o); });
}

}  // namespace tgraph::app
