// SPDX-License-Identifier: MIT
// `tgraph demo` (and `tgraph` alone): capture a built-in scene, partition it with every
// strategy, evaluate each offline, replay each on all cores against the work-stealing and
// barrier baselines, print the comparison and write the HTML report (viz/report.hpp).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

#include "commands.hpp"
#include "tgraph/capture/recorder.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/graph/metrics.hpp"
#include "tgraph/partition/cost_model.hpp"
#include "tgraph/partition/evaluate.hpp"
#include "tgraph/partition/strategy.hpp"
#include "tgraph/replay/measure.hpp"
#include "tgraph/replay/observer.hpp"
#include "tgraph/samples/scene.hpp"
#include "tgraph/viz/report.hpp"

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

void fill_measured(viz::MethodRow& row, const tr::ReplayResult& r) {
  row.measured_ms = static_cast<double>(r.wall_ns) / 1e6;
  row.sequential_ms = static_cast<double>(r.sequential_wall_ns) / 1e6;
  row.speedup = r.speedup;
  row.efficiency = r.efficiency;
  row.signals = r.signals();
}

// Replays the chosen method once more on its first steps, observed, for the report's timeline.
viz::Timeline observed_timeline(const Trace& trace, const TraceAssignment& a, const DemoOptions& o) {
  tr::ReplayOptions ro;
  ro.exec.threads = o.threads;
  ro.repeat = 1;
  ro.steps = std::min<std::uint32_t>(2, static_cast<std::uint32_t>(trace.steps.size()));
  ro.sequential_baseline = false;
  tr::TimelineObserver t;
  tr::replay_trace(trace, &a, ro, nullptr, &t);
  return viz::parse_timeline(t.to_json(), "demo timeline");
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

  std::vector<viz::MethodRow> rows, predictions;  // predictions: K < threads, not replayed
  std::vector<viz::StepSeries> series;
  std::vector<TraceAssignment> assignments;
  std::vector<std::uint32_t> ks;  // predicted at powers of two below --threads, measured at it
  for (std::uint32_t k = 2; k < o.threads; k *= 2) ks.push_back(k);
  ks.push_back(o.threads);
  for (const std::string& method : tp::strategy_names()) {
    if (method == "single") continue;  // the null strategy: everything on processor 0
    say("partitioning with " + method + " and replaying on " + std::to_string(o.threads) + " threads...");
    for (std::uint32_t k : ks) {
      const tp::TracePartition part = tp::partition_trace(trace, method, k);
      const tp::Report ev = tp::evaluate(trace, part.assignment, model, method);
      viz::MethodRow row;
      row.method = method;
      row.k = k;
      row.partitioned = true;
      for (double ms : part.assignment.partition_ms) row.partition_ms += ms;
      row.imbalance = ev.total.imbalance;
      row.cut_bytes = ev.total.cut_bytes;
      row.migrated_tasks = ev.total.migrated_tasks;
      row.predicted_speedup = ev.total.speedup;
      if (k != o.threads) {
        predictions.push_back(row);
        continue;
      }
      viz::StepSeries s{method, k, part.assignment.partition_ms, {}};
      for (const tp::StepReport& st : ev.steps) s.migrated_tasks.push_back(st.migrated_tasks);
      series.push_back(std::move(s));
      try {
        fill_measured(row, replay(trace, &part.assignment, tr::Policy::kPartition, o));
      } catch (const Error& e) {
        row.failure = e.what();  // reported in the table, the other methods still run
        say("  replay failed: " + row.failure);
      }
      rows.push_back(row);
      assignments.push_back(part.assignment);
    }
  }
  std::vector<tr::Policy> baselines = {tr::Policy::kWorksteal, tr::Policy::kBarrier};
#ifdef TGRAPH_HAVE_STARPU
  baselines.push_back(tr::Policy::kStarpu);
#else
  say("starpu: not in this build (libstarpu-dev was not found), no starpu row");
#endif
  for (tr::Policy p : baselines) {
    say("replaying with " + std::string(tr::to_string(p)) + "...");
    viz::MethodRow row;
    row.method = std::string(tr::to_string(p));
    row.k = o.threads;
    try {
      fill_measured(row, replay(trace, nullptr, p, o));
    } catch (const Error& e) {
      row.failure = e.what();
      say("  replay failed: " + row.failure);
    }
    rows.push_back(row);
  }

  // The report shows the partition with the best measured speed-up (its graph and timeline).
  std::size_t best = 0;
  for (std::size_t i = 0; i < assignments.size(); ++i)
    if (rows[i].speedup.value_or(0) > rows[best].speedup.value_or(0)) best = i;
  const std::size_t graph_step = trace.steps.size() > 1 ? 1 : 0;
  viz::ReportContent c = viz::report_content(trace, trace_path, &assignments[best].steps[graph_step], graph_step,
                                             rows[best].method);
  c.title = "tgraph demo: " + o.scene + ", " + std::to_string(o.steps) + " steps, " + std::to_string(o.threads) +
            " threads";
  c.notes = {"Wall times are medians of " + std::to_string(o.repeat) +
             " passes; speed-up is against sequential replay timed in the same run. Predicted speed-ups "
             "come from the calibrated cost model (tgraph evaluate)."};
  c.rows = rows;
  c.rows.insert(c.rows.end(), predictions.begin(), predictions.end());
  c.series = series;
  say("observing " + rows[best].method + " for the timeline...");
  c.timeline = observed_timeline(trace, assignments[best], o);
  c.timeline_caption = rows[best].method + " on " + std::to_string(o.threads) + " threads, observed pass.";
  const std::string report_path = o.out_dir + "/report.html";
  write_file_atomic(report_path, viz::report_html(c));

  if (o.json) {
    nlohmann::json j = {{"scene", o.scene}, {"steps", o.steps}, {"threads", o.threads},
                        {"trace", trace_path}, {"report", report_path}, {"rows", nlohmann::json::array()}};
    for (const viz::MethodRow& r : rows)
      j["rows"].push_back({{"method", r.method}, {"partitioned", r.partitioned}, {"partition_ms", r.partition_ms},
                           {"imbalance", r.imbalance}, {"cut_bytes", r.cut_bytes},
                           {"migrated_tasks", r.migrated_tasks}, {"predicted_speedup", r.predicted_speedup.value_or(0)},
                           {"wall_ns", r.measured_ms.value_or(0) * 1e6},
                           {"sequential_wall_ns", r.sequential_ms.value_or(0) * 1e6},
                           {"speedup", r.speedup.value_or(0)}, {"efficiency", r.efficiency.value_or(0)},
                           {"signals", r.signals.value_or(0)},
                           {"replay_failure", r.failure.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.failure)}});
    print_json(j);
    return;
  }
  std::printf("\n%s: %d steps, %llu tasks/step, parallelism %.1f, %u threads (replay: medians of %u passes)\n\n",
              o.scene.c_str(), o.steps, static_cast<unsigned long long>(m0.tasks), m0.parallelism, o.threads,
              o.repeat);
  std::printf("%-13s %10s %9s %12s %9s %10s %11s %11s %8s %6s\n", "method", "part. ms", "imbalance",
              "cut bytes", "migrated", "predicted", "replay ms", "seq. ms", "speedup", "eff.");
  for (const viz::MethodRow& r : rows) {
    if (r.partitioned)
      std::printf("%-13s %10.2f %9.3f %12llu %9llu %9.2fx", r.method.c_str(), r.partition_ms, r.imbalance,
                  static_cast<unsigned long long>(r.cut_bytes), static_cast<unsigned long long>(r.migrated_tasks),
                  r.predicted_speedup.value_or(0));
    else
      std::printf("%-13s %10s %9s %12s %9s %10s", r.method.c_str(), "-", "-", "-", "-", "-");
    if (!r.failure.empty())
      std::printf("  replay failed: %s\n", r.failure.c_str());
    else
      std::printf(" %11.2f %11.2f %7.2fx %6.2f\n", r.measured_ms.value_or(0), r.sequential_ms.value_or(0),
                  r.speedup.value_or(0), r.efficiency.value_or(0));
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
