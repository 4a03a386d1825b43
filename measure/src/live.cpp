// SPDX-License-Identifier: MIT
// Live runs: timed passes interleaved with the uninstrumented engine, the observed passes
// and the check of the final state.
#include "tgraph/measure/live.hpp"

#include <algorithm>
#include <memory>
#include <optional>
#include <string>

#include "live_observers.hpp"
#include "live_pass.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/measure/passes.hpp"
#include "tgraph/replay/thread_binding.hpp"

namespace tgraph::measure {

namespace tr = tgraph::replay;

std::string_view to_string(Check check) {
  switch (check) {
    case Check::kIdentical:
      return "identical";
    case Check::kDiffers:
      return "differs";
    case Check::kWithinRounding:
      return "within-rounding";
  }
  return "?";
}

std::string_view to_string(CheckReference reference) {
  switch (reference) {
    case CheckReference::kTwin:
      return "twin";
    case CheckReference::kPlain:
      return "plain";
  }
  return "?";
}

namespace {

/// The uninstrumented engine's passes, on each of the first cores the run uses (cores of a
/// VM can differ in speed; a sequential run could land on either), the fastest kept.
struct Baseline {
  std::vector<PassTimes> by_core;  ///< every pass on each core
  PassTimes fastest;               ///< each pass's fastest core, by step
};

void time_baseline_pass(const EngineFactory& make_engine, const LiveOptions& o, Baseline& b) {
  std::int64_t best = -1;
  std::vector<std::int64_t> best_steps;
  tr::BindingScope binding;
  for (std::uint32_t c = 0; c < b.by_core.size(); ++c) {
    if (o.exec.pin) binding.pin(c);
    std::unique_ptr<LiveEngine> engine = make_engine();
    std::int64_t total = 0;
    std::vector<std::int64_t> steps(o.steps);
    for (std::uint32_t s = 0; s < o.steps; ++s) {
      const std::int64_t t0 = tr::now_ns();
      engine->plain_step();
      steps[s] = tr::now_ns() - t0;
      total += steps[s];
      b.by_core[c].add(s, steps[s]);
    }
    b.by_core[c].end_pass();
    if (best < 0 || total < best) {
      best = total;
      best_steps = std::move(steps);
    }
  }
  for (std::uint32_t s = 0; s < o.steps; ++s) b.fastest.add(s, best_steps[s]);
  b.fastest.end_pass();
}

/// The engine's plain run: `steps` plain steps of a fresh engine, its final state.
StateSnapshot plain_state(const EngineFactory& make_engine, std::uint32_t steps) {
  std::unique_ptr<LiveEngine> engine = make_engine();
  for (std::uint32_t s = 0; s < steps; ++s) engine->plain_step();
  return snapshot(engine->state());
}

/// The check of the first timed pass's final state against o.check_reference.
void check_final_state(const EngineFactory& make_engine,
                       const partition::StepPartitioner* partitioner, const LiveOptions& o,
                       const detail::PassResult& first, LiveResult& res) {
  res.check_reference = o.check_reference;
  StateSnapshot reference;
  try {
    if (o.check_reference == CheckReference::kPlain) {
      reference = plain_state(make_engine, o.steps);
      res.reference = "the plain run (the engine's own sequential steps, uninstrumented)";
    } else {
      // A sequential run with the same reduction order (see the header).
      tr::ExecOptions ro = o.exec;
      std::unique_ptr<tr::Executor> ref;
      detail::PassOptions po;
      po.keep_state = true;
      if (res.cw == CwMode::kSerialize || o.policy == tr::Policy::kSequential) {
        ro.threads = 1;
        ro.reduce_scope = ReduceScope::kNone;
        ref = tr::make_executor(tr::Policy::kSequential, ro);
        res.reference = "the twin (sequential executor, program order)";
      } else if (o.policy == tr::Policy::kPartition) {
        ro.partition.serial = true;
        ref = tr::make_executor(tr::Policy::kPartition, ro);
        po.fixed = &first.assignments;
        res.reference =
            "the twin (serial partition executor, same assignments and per-processor reducers)";
      } else {
        ro.threads = 1;
        ro.reduce_scope = res.scope;
        ref = tr::make_executor(tr::Policy::kSequential, ro);
        res.reference = "the twin (sequential executor, same per-writer reducers)";
      }
      reference = detail::run_pass(make_engine, partitioner, *ref, o, po).state;
    }
  } catch (const UsageError& e) {
    // The reference could not follow the same steps (its graphs differ): a difference.
    res.difference = StateDifference{std::string("structure: ") + e.what(), 0, 0};
    res.check = Check::kDiffers;
    return;
  }
  res.data_compared = reference.names.size();
  res.difference = compare(reference, first.state);
  res.longest_reduction = first.longest_reduction;
  res.reduction_rounds = 0;
  for (const LiveStepMeasure& m : first.steps) {
    res.reduction_rounds += 1;
    for (const std::uint32_t it : m.loop_iterations) res.reduction_rounds += it;
  }
  if (o.check_reference == CheckReference::kPlain)
    res.rounding_bound = reduction_order_bound(res.longest_reduction, res.reduction_rounds);
  if (!res.difference) {
    res.check = Check::kIdentical;
    return;
  }
  std::optional<Magnitudes> involved;
  if (o.check_reference == CheckReference::kPlain) {
    // The magnitudes each datum held in program order: a sequential pass with CW writes in
    // place, watched after every task.
    LiveEngine* watched = nullptr;
    const EngineFactory watch = [&make_engine, &watched] {
      std::unique_ptr<LiveEngine> e = make_engine();
      watched = e.get();
      return e;
    };
    MagnitudeObserver observer([&watched] { return watched->state(); });
    tr::ExecOptions so = o.exec;
    so.threads = 1;
    so.reduce_scope = ReduceScope::kNone;
    std::unique_ptr<tr::Executor> seq = tr::make_executor(tr::Policy::kSequential, so);
    seq->add_observer(observer);
    const detail::PassResult in_order = detail::run_pass(watch, nullptr, *seq, o, {});
    seq->clear_observers();
    involved = observer.magnitudes();
    for (std::uint32_t s = 0; s < o.steps && s < in_order.steps.size() && !res.iterations; ++s) {
      const std::vector<std::uint32_t>& a = in_order.steps[s].loop_iterations;
      const std::vector<std::uint32_t>& b = first.steps[s].loop_iterations;
      for (std::uint32_t l = 0; l < a.size() || l < b.size(); ++l) {
        const std::uint32_t x = l < a.size() ? a[l] : 0, y = l < b.size() ? b[l] : 0;
        if (x != y) {
          res.iterations = IterationDifference{s, l, x, y};
          break;
        }
      }
    }
  }
  res.values = compare_values(reference, first.state, involved ? &*involved : nullptr);
  const bool within = o.check_reference == CheckReference::kPlain &&
                      res.values->incomparable.empty() && !res.iterations &&
                      res.values->max_rel_diff <= res.rounding_bound;
  res.check = within ? Check::kWithinRounding : Check::kDiffers;
}

}  // namespace

LiveResult run_live(const EngineFactory& make_engine, const partition::StepPartitioner* partitioner,
                    const LiveOptions& o) {
  if (o.steps == 0) throw OptionError("steps", "must be at least 1");
  if (o.repeat == 0) throw OptionError("repeat", "must be at least 1");
  if (o.policy == tr::Policy::kPartition && (partitioner == nullptr || !*partitioner))
    throw UsageError("the partition policy needs a partitioning method");
  LiveResult res;
  res.policy = o.policy;
  // A fresh executor per pass: its threads and pinning end with the pass, so the
  // uninstrumented engine that follows runs where the OS puts it, as users run it (the
  // partition executor pins the calling thread to the first core while it lives).
  auto make = [&o] {
    auto e = tr::make_executor(o.policy, o.exec);
    e->set_observe_stride(o.cost_stride);
    return e;
  };
  std::unique_ptr<tr::Executor> ex = make();
  res.threads = ex->threads();
  res.cw = ex->cw();
  res.scope = ex->scope();
  ex.reset();
  if (o.check && o.check_reference == CheckReference::kTwin &&
      res.scope == ReduceScope::kPerThread && res.cw == CwMode::kReduce &&
      res.threads > 1)
    throw OptionError("reduce_scope",
                      "per-thread temporaries sum in an order of the run's timing, which no "
                      "reference run reproduces, and {check} compares bit for bit: use per-writer "
                      "(the same work, a fixed order)");
  const bool partition = o.policy == tr::Policy::kPartition;

  std::vector<detail::PassResult> passes;
  const std::uint32_t baseline_cores =
      o.exec.pin ? std::min<std::uint32_t>({res.threads, tr::hardware_pus(), 4}) : 1;
  Baseline baseline{std::vector<PassTimes>(baseline_cores, PassTimes(o.steps)), PassTimes(o.steps)};
  // The step times every pass records; their medians are the result's (wall first).
  StepFieldTimes<LiveStepMeasure, 6> times(
      {&LiveStepMeasure::wall_ns, &LiveStepMeasure::record_ns, &LiveStepMeasure::partition_ns,
       &LiveStepMeasure::background_partition_ns, &LiveStepMeasure::prepare_ns,
       &LiveStepMeasure::execute_ns},
      o.steps);
  for (std::uint32_t pass = 0; pass < o.repeat; ++pass) {
    if (o.baseline) time_baseline_pass(make_engine, o, baseline);
    if (!ex) ex = make();
    detail::PassOptions po;
    po.feed_costs = partition;
    po.keep_state = pass == 0 && o.check;
    po.keep_assignments = pass == 0 && (o.check || o.keep_assignments);
    passes.push_back(detail::run_pass(make_engine, partitioner, *ex, o, po));
    res.plans_built += ex->plans_built();
    res.order_fallbacks += ex->order_fallbacks();
    ex.reset();
    times.add_pass(passes.back().steps);
  }
  const detail::PassResult& first = passes[0];
  res.signals = first.signals;
  res.waits = first.waits;
  res.blocked_waits = first.blocked_waits;
  res.parks = first.parks;
  res.pass_wall_ns = times.times(0).pass_totals();
  res.steps = first.steps;  // the first pass's plan and structure figures
  times.write_medians(res.steps);
  if (o.keep_assignments) res.assignments = first.assignments;
  for (std::uint32_t s = 0; s < o.steps; ++s)
    res.steps[s].baseline_ns = baseline.fastest.step_median(s);
  res.wall_ns = times.times(0).median_total();
  for (const PassTimes& core : baseline.by_core) {
    res.baseline_core_pass_wall_ns.push_back(core.pass_totals());
    const std::int64_t m = core.median_total();
    if (m > 0 && (res.baseline_wall_ns == 0 || m < res.baseline_wall_ns)) res.baseline_wall_ns = m;
  }
  if (res.baseline_wall_ns > 0 && baseline_cores == res.threads)
    for (const PassTimes& core : baseline.by_core)
      res.core_bound +=
          static_cast<double>(res.baseline_wall_ns) / static_cast<double>(core.median_total());
  if (res.wall_ns > 0 && res.baseline_wall_ns > 0)
    res.speedup = static_cast<double>(res.baseline_wall_ns) / static_cast<double>(res.wall_ns);

  if (o.observe) {
    // The policy with per-thread and per-kind observers (every instance), then sequential.
    replay::StatsObserver stats;
    detail::KindObserver kinds;
    replay::TimelineObserver timeline;  // the attribution's (docs/explain.md)
    timeline.set_cpu_time(o.keep_timeline);  // asked for: interruptions told apart
    ex = make();
    ex->set_observe_stride(1);
    ex->add_observer(stats);
    ex->add_observer(kinds);
    ex->add_observer(timeline);
    detail::PassResult observed;
    detail::PassOptions po;
    po.feed_costs = partition;
    po.stats = &stats;
    try {
      observed = detail::run_pass(make_engine, partitioner, *ex, o, po);
    } catch (...) {
      ex->clear_observers();
      throw;
    }
    ex->clear_observers();
    for (std::uint32_t s = 0; s < o.steps; ++s) res.steps[s].threads = observed.steps[s].threads;
    detail::KindObserver seq_kinds;
    if (o.policy != tr::Policy::kSequential) {
      tr::ExecOptions so = o.exec;
      so.threads = 1;
      auto seq = tr::make_executor(tr::Policy::kSequential, so);
      seq->add_observer(seq_kinds);
      detail::run_pass(make_engine, nullptr, *seq, o, {});
    }
    for (const auto& [kind, t] : kinds.total()) {
      KindTime k;
      k.kind = kind;
      k.instances = t.second;
      k.mean_ns = t.second ? static_cast<double>(t.first) / static_cast<double>(t.second) : 0;
      const auto it = seq_kinds.total().find(kind);
      if (it != seq_kinds.total().end() && it->second.second > 0)
        k.sequential_mean_ns =
            static_cast<double>(it->second.first) / static_cast<double>(it->second.second);
      res.kinds.push_back(std::move(k));
    }
    // Where the observed pass's time went: its serial phases per step, its bodies against
    // the kinds' sequential means.
    Timeline t = timeline.timeline();
    if (t.step_info.size() == o.steps) {
      std::vector<std::pair<std::string, double>> means;
      for (const KindTime& k : res.kinds)
        if (k.sequential_mean_ns > 0) means.emplace_back(k.kind, k.sequential_mean_ns);
      explain::set_kind_costs(t, means);
      for (std::uint32_t s = 0; s < o.steps; ++s) {
        TimelineStep& info = t.step_info[s];
        info.record_ns = observed.steps[s].record_ns;
        info.partition_ns = observed.steps[s].partition_ns;
        info.prepare_ns = observed.steps[s].prepare_ns;
      }
      explain::ExplainOptions eo;
      eo.what_ifs = false;
      const explain::Explanation e = explain::explain_timeline(t, "observed pass", eo);
      for (std::uint32_t s = 0; s < o.steps; ++s) res.steps[s].attribution = e.steps[s].attribution;
      res.attribution = e.attribution;
      if (o.keep_timeline) res.timeline = std::move(t);
    }
  }

  if (o.check) check_final_state(make_engine, partitioner, o, first, res);
  return res;
}

}  // namespace tgraph::measure
