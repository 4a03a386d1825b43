// SPDX-License-Identifier: MIT
// The demo pipeline: capture, partition with every strategy, evaluate, replay, report.
#include "tgraph/experiment/demo.hpp"

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "common.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/graph/metrics.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/measure/capture.hpp"
#include "tgraph/measure/replay_trace.hpp"
#include "tgraph/model/cost_model.hpp"
#include "tgraph/partition/evaluate.hpp"
#include "tgraph/partition/strategy.hpp"
#include "tgraph/replay/observer.hpp"

namespace tgraph::experiment {
namespace {

namespace tp = tgraph::partition;
namespace tr = tgraph::replay;
namespace meas = tgraph::measure;

meas::ReplayResult replay(const Trace& trace, const TraceAssignment* a, tr::Policy policy,
                        const DemoOptions& o) {
  meas::ReplayOptions ro;
  ro.policy = policy;
  ro.exec.threads = policy == tr::Policy::kSequential ? 1 : o.threads;
  ro.repeat = o.repeat;
  return meas::replay_trace(trace, a, ro);
}

void fill_measured(viz::MethodRow& row, const meas::ReplayResult& r) {
  row.measured_ms = static_cast<double>(r.wall_ns) / 1e6;
  row.sequential_ms = static_cast<double>(r.sequential_wall_ns) / 1e6;
  row.speedup = r.speedup;
  row.efficiency = r.efficiency;
  row.signals = r.signals();
}

// Replays the chosen method once more on its first steps, observed, for the report's timeline.
Timeline observed_timeline(const Trace& trace, const TraceAssignment& a, const DemoOptions& o) {
  meas::ReplayOptions ro;
  ro.exec.threads = o.threads;
  ro.repeat = 1;
  ro.steps = std::min<std::uint32_t>(2, static_cast<std::uint32_t>(trace.steps.size()));
  ro.sequential_baseline = false;
  tr::TimelineObserver t;
  meas::replay_trace(trace, &a, ro, nullptr, &t);
  return t.timeline();
}

std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char* fmt, ...) {
  va_list args;
  va_start(args, fmt);
  va_list copy;
  va_copy(copy, args);
  const int n = std::vsnprintf(nullptr, 0, fmt, copy);
  va_end(copy);
  std::string s(static_cast<std::size_t>(std::max(n, 0)) + 1, '\0');
  std::vsnprintf(s.data(), s.size(), fmt, args);
  va_end(args);
  s.pop_back();
  return s;
}

// The cost model in words: the defaults' constants and where a calibration comes from.
std::string cost_model_words(const std::string& name, const model::CostModel& m) {
  if (name == "defaults")
    return format("its defaults (%.0f ns a signal, %.2f ns a byte; no calibration file: "
                  "`tgraph calibrate` writes one)",
                  m.sync_latency_ns, m.per_byte_ns);
  return format("the calibration file %s (%.0f ns a signal, %.2f ns a byte)", name.c_str(),
                m.sync_latency_ns, m.per_byte_ns);
}

}  // namespace

DemoResult run_demo(const DemoOptions& o, const std::function<void(const std::string&)>& say_fn) {
  if (o.steps < 1) throw OptionError("steps", "must be at least 1");
  if (o.threads < 1) throw OptionError("threads", "must be at least 1");
  detail::make_results_folder(o.out);
  const auto say = [&](const std::string& s) {
    if (say_fn) say_fn(s);
  };
  say("capturing " + o.scene + " (" + std::to_string(o.steps) + " steps)...");
  const Trace trace = meas::capture_trace(o.scene, static_cast<std::uint32_t>(o.steps));
  DemoResult res;
  res.scene = o.scene;
  res.steps = o.steps;
  res.threads = o.threads;
  res.repeat = o.repeat;
  res.trace_path = o.out + "/" + o.scene + ".tgt";
  write_trace(res.trace_path, trace);
  const Metrics m0 = compute_metrics(trace.steps.front());
  res.tasks = m0.tasks;
  res.parallelism = m0.parallelism;
  // The default calibration file when `tgraph calibrate` wrote one, else the defaults.
  const model::CostModel model = model::select_cost_model("calibrated", "");
  res.cost_model = model.source == model::CostModel::defaults().source ? "defaults" : model.source;

  std::vector<viz::MethodRow> rows, predictions;  // predictions: K < threads, not replayed
  std::vector<viz::StepSeries> series;
  std::vector<TraceAssignment> assignments;
  std::vector<std::uint32_t> ks;  // predicted at powers of two below `threads`, measured at it
  for (std::uint32_t k = 2; k < o.threads; k *= 2) ks.push_back(k);
  ks.push_back(o.threads);
  for (const std::string& method : tp::strategy_names()) {
    if (method == "single") continue;  // the null strategy: everything on processor 0
    say("partitioning with " + method + " and replaying on " + std::to_string(o.threads) +
        " threads...");
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
  std::vector<tr::Policy> baselines = {tr::Policy::kWorksteal, tr::Policy::kBarrier,
                                       tr::Policy::kOmpTasks};
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
  viz::ReportContent c = viz::report_content(
      trace, res.trace_path, &assignments[best].steps[graph_step], graph_step, rows[best].method);
  viz::set_quotient(c,
                    tp::step_quotient(trace.steps[graph_step], assignments[best].steps[graph_step]),
                    rows[best].method);
  c.title = "tgraph demo: " + o.scene + ", " + std::to_string(o.steps) + " steps, " +
            std::to_string(o.threads) + " threads";
  c.notes = {
      "Wall times are medians of " + std::to_string(o.repeat) +
      " passes; speed-up is against sequential replay timed in the same run. Predicted speed-ups "
      "come from the cost model (tgraph evaluate) with " +
      cost_model_words(res.cost_model, model) + "."};
  c.rows = rows;
  c.rows.insert(c.rows.end(), predictions.begin(), predictions.end());
  c.series = series;
  say("observing " + rows[best].method + " for the timeline...");
  c.timeline = observed_timeline(trace, assignments[best], o);
  c.timeline_caption =
      rows[best].method + " on " + std::to_string(o.threads) + " threads, observed pass.";
  viz::draw_executed_path(c, trace, res.trace_path, &assignments[best].steps[graph_step],
                          rows[best].method);
  res.report_path = o.out + "/report.html";
  write_file_atomic(res.report_path, viz::report_html(c));
  res.rows = std::move(rows);
  return res;
}

std::string demo_json(const DemoResult& r) {
  nlohmann::json j = {{"scene", r.scene},        {"steps", r.steps},
                      {"threads", r.threads},    {"trace", r.trace_path},
                      {"report", r.report_path}, {"cost_model", r.cost_model},
                      {"rows", nlohmann::json::array()}};
  for (const viz::MethodRow& row : r.rows)
    j["rows"].push_back({{"method", row.method},
                         {"partitioned", row.partitioned},
                         {"partition_ms", row.partition_ms},
                         {"imbalance", row.imbalance},
                         {"cut_bytes", row.cut_bytes},
                         {"migrated_tasks", row.migrated_tasks},
                         {"predicted_speedup", row.predicted_speedup.value_or(0)},
                         {"wall_ns", row.measured_ms.value_or(0) * 1e6},
                         {"sequential_wall_ns", row.sequential_ms.value_or(0) * 1e6},
                         {"speedup", row.speedup.value_or(0)},
                         {"efficiency", row.efficiency.value_or(0)},
                         {"signals", row.signals.value_or(0)},
                         {"replay_failure", row.failure.empty() ? nlohmann::json(nullptr)
                                                                : nlohmann::json(row.failure)}});
  return j.dump();
}

std::string demo_text(const DemoResult& r) {
  std::string s = format(
      "\n%s: %d steps, %llu tasks/step, parallelism %.1f, %u threads (replay: medians of %u "
      "passes)\n\n",
      r.scene.c_str(), r.steps, static_cast<unsigned long long>(r.tasks), r.parallelism, r.threads,
      r.repeat);
  s += format("%-13s %10s %9s %12s %9s %10s %11s %11s %8s %6s\n", "method", "part. ms", "imbalance",
              "cut bytes", "migrated", "predicted", "replay ms", "seq. ms", "speedup", "eff.");
  for (const viz::MethodRow& row : r.rows) {
    if (row.partitioned)
      s += format("%-13s %10.2f %9.3f %12llu %9llu %9.2fx", row.method.c_str(), row.partition_ms,
                  row.imbalance, static_cast<unsigned long long>(row.cut_bytes),
                  static_cast<unsigned long long>(row.migrated_tasks),
                  row.predicted_speedup.value_or(0));
    else
      s += format("%-13s %10s %9s %12s %9s %10s", row.method.c_str(), "-", "-", "-", "-", "-");
    if (!row.failure.empty())
      s += format("  replay failed: %s\n", row.failure.c_str());
    else
      s += format(" %11.2f %11.2f %7.2fx %6.2f\n", row.measured_ms.value_or(0),
                  row.sequential_ms.value_or(0), row.speedup.value_or(0),
                  row.efficiency.value_or(0));
  }
  const std::string model =
      r.cost_model == "defaults" ? "defaults (no calibration file)" : "from " + r.cost_model;
  s += format("\npredicted: cost model %s\n", model.c_str());
  const auto absolute = [](const std::string& p) {
    return std::filesystem::absolute(p).lexically_normal().string();
  };
  s += format("trace: %s\nreport: %s\n", absolute(r.trace_path).c_str(),
              absolute(r.report_path).c_str());
  return s;
}

}  // namespace tgraph::experiment
