// SPDX-License-Identifier: MIT
// Running an experiment: per scene variant a capture (for the predictions and the
// replays), the simulator at every thread count, live runs and replays at the measured ones,
// and for the heterogeneous scene one live run per method that repartitions every step.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <map>
#include <memory>

#include "common.hpp"
#include "output.hpp"
#include "tgraph/experiment/experiment.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/fixed.hpp"
#include "tgraph/graph/metrics.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/measure/capture.hpp"
#include "tgraph/measure/live.hpp"
#include "tgraph/measure/method.hpp"
#include "tgraph/measure/replay_trace.hpp"
#include "tgraph/model/cost_model.hpp"
#include "tgraph/partition/evaluate.hpp"
#include "tgraph/partition/strategy.hpp"
#include "tgraph/samples/scene.hpp"

namespace tgraph::experiment {
namespace {

namespace tp = tgraph::partition;
namespace tr = tgraph::replay;
namespace meas = tgraph::measure;

double ms(double ns) { return ns / 1e6; }

samples::SceneOptions scene_options(const SceneVariant& v) {
  samples::SceneOptions so;
  so.subobjects = v.subobjects;
  return so;
}

Trace capture_variant(const SceneVariant& v, std::uint32_t steps) {
  Trace trace = meas::capture_trace(v.scene, steps, scene_options(v));
  if (v.subobjects) trace.header.scene += " (" + std::to_string(*v.subobjects) + " sub-objects)";
  return trace;
}

// A strategy as a step partitioner that keeps each call's statistics (migrations). Live,
// sticky rebalances at the live trigger's tolerance, as `tgraph run` does.
struct LiveRun {
  meas::LiveResult result;
  std::vector<tp::Stats> calls;  // the partitioner's calls, in order (first pass first)
};

LiveRun run_live(const SceneVariant& v, const std::string& method, std::uint32_t k,
                 const ExperimentPlan& p, bool every_step) {
  meas::LiveOptions o = detail::live_options(k, p.steps, p.repeat, false);
  o.repartition_every_step = every_step;
  auto calls = std::make_shared<std::vector<tp::Stats>>();  // in order, first pass first
  const std::optional<tp::StepPartitioner> part = meas::live_partitioner(
      meas::choose_method(method), meas::live_strategy_options(o), o, calls);
  const std::string scene = v.scene;
  const samples::SceneOptions so = scene_options(v);
  LiveRun run;
  run.result = meas::run_live([scene, so] { return meas::make_live_engine(scene, so); },
                            part ? &*part : nullptr, o);
  run.calls = *calls;
  return run;
}

// `work_ns`: the captured trace's task work over the same steps (the sequential cost of
// the time integration alone).
Measured measured_of(const meas::LiveResult& r, std::uint32_t steps, double work_ns) {
  Measured m;
  const double n = std::max<double>(steps, 1);
  m.live_ms_per_step = ms(static_cast<double>(r.wall_ns)) / n;
  m.engine_ms_per_step = ms(static_cast<double>(r.baseline_wall_ns)) / n;
  m.live_speedup = r.speedup;
  m.step_speedup = r.speedup;
  double execute_ns = 0;
  for (const meas::LiveStepMeasure& s : r.steps) execute_ns += static_cast<double>(s.execute_ns);
  m.integration_speedup = execute_ns > 0 ? work_ns / execute_ns : 0;
  m.core_bound = r.core_bound;
  std::uint64_t recorded = 0;
  for (const meas::LiveStepMeasure& s : r.steps) {
    m.record_ms_per_step += ms(static_cast<double>(s.record_ns)) / n;
    m.graph_update_ms_per_step += ms(static_cast<double>(s.graph_update_ns)) / n;
    m.partition_ms_per_step += ms(static_cast<double>(s.partition_ns)) / n;
    m.build_ms_per_step += ms(static_cast<double>(s.build_ns)) / n;
    recorded += s.recorded ? 1 : 0;
  }
  m.plans_built = r.plans_built;
  m.structure_changes = recorded > 0 ? recorded - 1 : 0;
  m.signals = r.signals;
  return m;
}

std::string run_label(const SceneVariant& v, const std::string& method, std::uint32_t k) {
  return v.label() + " " + method + " K=" + std::to_string(k);
}

// Predictions of every partition strategy at every thread count, plus the assignments of
// the measured counts (what the replays run).
struct Predictions {
  std::map<std::pair<std::string, std::uint32_t>, Predicted> by_method_k;
  std::map<std::pair<std::string, std::uint32_t>, TraceAssignment> assignments;
};

Predictions predict(const Trace& trace, const ExperimentPlan& p, const model::CostModel& model) {
  Predictions out;
  const double n = static_cast<double>(std::max<std::size_t>(trace.steps.size(), 1));
  for (const std::string& method : p.methods) {
    if (meas::choose_method(method).policy != tr::Policy::kPartition) continue;
    for (std::uint32_t k : p.threads.all()) {
      tp::TracePartition part = tp::partition_trace(trace, method, k);
      const tp::Report ev = tp::evaluate(trace, part.assignment, model, method);
      Predicted pr;
      pr.speedup = ev.total.speedup;
      pr.step_speedup = ev.total.speedup;
      const double graph_ns = static_cast<double>(ev.total.makespan_ns) - static_cast<double>(ev.total.host_ns);
      pr.integration_speedup = graph_ns > 0 ? static_cast<double>(ev.total.work_ns) / graph_ns : 0;
      pr.ms_per_step = ms(static_cast<double>(ev.total.makespan_ns)) / n;
      pr.work_ms_per_step = ms(static_cast<double>(ev.total.work_ns)) / n;
      pr.imbalance = ev.total.imbalance;
      pr.migrated_tasks = ev.total.migrated_tasks;
      for (double t : part.assignment.partition_ms) pr.partition_ms_per_step += t / n;
      out.by_method_k[{method, k}] = pr;
      if (k <= p.cores) out.assignments[{method, k}] = std::move(part.assignment);
    }
  }
  return out;
}

void summarise_series(ExperimentResult& res) {
  std::map<std::string, std::vector<const StepRow*>> by_method;
  for (const StepRow& s : res.steps) by_method[s.method].push_back(&s);
  for (const std::string& method : res.plan.series_methods) {
    const auto it = by_method.find(method);
    if (it == by_method.end() || it->second.empty()) continue;
    SeriesSummary sum;
    sum.method = method;
    sum.threads = it->second.front()->threads;
    sum.steps = static_cast<std::uint32_t>(it->second.size());
    std::uint32_t changed = 0;
    for (const StepRow* s : it->second) {
      sum.step_ms += s->step_ms / sum.steps;
      sum.engine_ms += s->engine_ms / sum.steps;
      sum.partition_ms += s->partition_ms / sum.steps;
      sum.build_ms += s->build_ms / sum.steps;
      sum.migrated_tasks += s->migrated_tasks;
      if (s->structure_changed && s->step > 0) {
        ++changed;
        sum.update_ms_changed += s->graph_update_ms + s->build_ms;
        sum.new_graph_ms_changed += s->record_ms + s->partition_ms + s->build_ms;
      }
    }
    sum.structure_changes = changed;
    if (changed) {
      sum.update_ms_changed /= changed;
      sum.new_graph_ms_changed /= changed;
    }
    res.series.push_back(sum);
  }
}

}  // namespace

std::size_t ExperimentResult::failures() const {
  std::size_t n = 0;
  for (const ResultRow& r : rows) n += r.failure.empty() ? 0 : 1;
  return n;
}

ExperimentResult run_experiment(const ExperimentOptions& options, Progress& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  ExperimentResult res = detail::start_experiment<ExperimentResult>(options, plan_experiment, progress);
  const ExperimentPlan& p = res.plan;
  const std::string name(to_string(p.name));
  progress.note("experiment " + name + " on " + res.machine.summary() + ": measured at " +
                std::to_string(p.threads.measured.size()) +
                " thread counts (<= " + std::to_string(p.cores) + " cores), predicted at " +
                std::to_string(p.threads.predicted.size()) + " more; " + std::to_string(p.runs()) +
                " runs");
  for (const std::string& n : p.notes) progress.note(n);
  // --calibration, else the default calibration file when `tgraph calibrate` wrote one,
  // else the defaults.
  const model::CostModel model = model::select_cost_model("calibrated", p.calibration);
  res.cost_model = model.source == model::CostModel::defaults().source ? "defaults" : model.source;

  for (const SceneVariant& v : p.scenes) {
    progress.note("capturing " + v.label() + " (" + std::to_string(p.steps) +
                  " steps) and predicting " + std::to_string(p.threads.all().size()) +
                  " thread counts...");
    const Trace trace = capture_variant(v, p.steps);
    const std::string trace_file = v.label() + ".tgt";
    write_trace(p.out_dir + "/" + trace_file, trace);
    res.files.push_back(trace_file);
    const Predictions pred = predict(trace, p, model);
    double trace_work_ns = 0;  // the time integration's sequential cost over the captured steps
    for (const StepGraph& g : trace.steps) trace_work_ns += static_cast<double>(compute_metrics(g).work_ns);

    for (const std::string& method : p.methods) {
      const meas::MethodChoice choice = meas::choose_method(method);
      const std::string policy(tr::to_string(choice.policy));
      for (std::uint32_t k : p.threads.all()) {
        ResultRow row;
        row.experiment = name;
        row.scene = v.scene;
        row.subobjects = v.subobjects;
        row.method = method;
        row.policy = policy;
        row.threads = k;
        if (const auto it = pred.by_method_k.find({method, k}); it != pred.by_method_k.end())
          row.predicted = it->second;
        if (k > p.cores && !row.predicted) continue;  // a baseline: nothing to predict
        if (k <= p.cores) {
          const std::string label = run_label(v, method, k);
          progress.begin(label + " live");
          try {
            const LiveRun live = run_live(v, method, k, p, false);
            row.measured = measured_of(live.result, p.steps, trace_work_ns);
            progress.end(label + ": live " + fixed(row.measured->live_ms_per_step, 2) +
                         " ms/step, engine " + fixed(row.measured->engine_ms_per_step, 2) +
                         " ms/step, speed-up " + fixed(row.measured->live_speedup, 2));
          } catch (const std::exception& e) {
            row.failure = std::string("live run: ") + e.what();
            progress.end(label + ": live run failed: " + e.what());
          }
          if (p.replays(method, k)) {
            progress.begin(label + " replay");
            try {
              meas::ReplayOptions ro;
              ro.policy = choice.policy;
              ro.exec.threads = k;
              ro.repeat = p.repeat;
              ro.observe = false;
              const auto a = pred.assignments.find({method, k});
              const meas::ReplayResult rr =
                  meas::replay_trace(trace, a == pred.assignments.end() ? nullptr : &a->second, ro);
              if (row.measured) {
                const double n = static_cast<double>(trace.steps.size());
                row.measured->replay_ms_per_step = ms(static_cast<double>(rr.wall_ns)) / n;
                row.measured->replay_sequential_ms_per_step =
                    ms(static_cast<double>(rr.sequential_wall_ns)) / n;
                row.measured->replay_speedup = rr.speedup;
              }
              progress.end(label + ": replay " + fixed(ms(static_cast<double>(rr.wall_ns)), 1) +
                           " ms, sequential " +
                           fixed(ms(static_cast<double>(rr.sequential_wall_ns)), 1) +
                           " ms, speed-up " + fixed(rr.speedup, 2));
            } catch (const std::exception& e) {
              row.failure += std::string(row.failure.empty() ? "" : "; ") + "replay: " + e.what();
              progress.end(label + ": replay failed: " + e.what());
            }
          }
        }
        res.rows.push_back(std::move(row));
      }
    }

    for (const std::string& method : p.series_methods) {
      const std::uint32_t k = p.series_threads;
      const std::string label = run_label(v, method, k) + " repartitioned every step";
      progress.begin(label);
      try {
        const LiveRun live = run_live(v, method, k, p, true);
        std::uint64_t moved = 0;
        for (std::uint32_t s = 0; s < live.result.steps.size(); ++s) {
          const meas::LiveStepMeasure& m = live.result.steps[s];
          StepRow r;
          r.method = method;
          r.threads = k;
          r.step = s;
          r.structure_changed = m.recorded;
          r.step_ms = ms(static_cast<double>(m.wall_ns));
          r.engine_ms = ms(static_cast<double>(m.baseline_ns));
          r.record_ms = ms(static_cast<double>(m.record_ns));
          r.graph_update_ms = ms(static_cast<double>(m.graph_update_ns));
          r.partition_ms = ms(static_cast<double>(m.partition_ns));
          r.build_ms = ms(static_cast<double>(m.build_ns));
          r.execute_ms = ms(static_cast<double>(m.execute_ns));
          // Every step calls the partitioner; the first pass's calls come first.
          if (s < live.calls.size()) r.migrated_tasks = live.calls[s].moved_tasks;
          moved += r.migrated_tasks;
          res.steps.push_back(r);
        }
        progress.end(label + ": speed-up " + fixed(live.result.speedup, 2) + ", " +
                     std::to_string(moved) + " migrated tasks");
      } catch (const std::exception& e) {
        ResultRow row;
        row.experiment = name;
        row.scene = v.scene;
        row.method = method + " (every step)";
        row.policy = "partition";
        row.threads = k;
        row.failure = std::string("per-step run: ") + e.what();
        res.rows.push_back(std::move(row));
        progress.end(label + ": failed: " + e.what());
      }
    }
  }
  summarise_series(res);
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  write_outputs(res);
  progress.finish();
  return res;
}

}  // namespace tgraph::experiment
