// SPDX-License-Identifier: MIT
// Replays: timed passes of a trace under a policy, interleaved with sequential ones.
#include "tgraph/measure/replay_trace.hpp"

#include <algorithm>
#include <memory>
#include <string>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/metrics.hpp"
#include "tgraph/measure/cache_misses.hpp"
#include "tgraph/measure/passes.hpp"

namespace tgraph::measure {

using namespace tgraph::replay;

std::uint64_t ReplayResult::signals() const {
  std::uint64_t s = 0;
  for (const auto& m : steps) s += m.signals;
  return s;
}
std::uint64_t ReplayResult::waits() const {
  std::uint64_t s = 0;
  for (const auto& m : steps) s += m.waits;
  return s;
}
std::int64_t ReplayResult::wait_ns() const {
  std::int64_t s = 0;
  for (const auto& m : steps) s += m.wait_ns;
  return s;
}
std::int64_t ReplayResult::build_ns() const {
  std::int64_t s = 0;
  for (const auto& m : steps) s += m.build_ns;
  return s;
}

std::int64_t ReplayResult::rebuild_ns() const {
  std::int64_t s = 0;
  for (const auto& m : steps) s += m.rebuild_ns;
  return s;
}
std::uint64_t ReplayResult::remote_bytes() const {
  std::uint64_t s = 0;
  for (const auto& m : steps) s += m.remote_bytes;
  return s;
}
std::uint64_t ReplayResult::migrated_bytes() const {
  std::uint64_t s = 0;
  for (const auto& m : steps) s += m.migrated_bytes;
  return s;
}
std::optional<std::uint64_t> ReplayResult::predicted_makespan_ns() const {
  std::uint64_t s = 0;
  for (const auto& m : steps) {
    if (!m.predicted_makespan_ns) return std::nullopt;
    s += *m.predicted_makespan_ns;
  }
  return s;
}

namespace {

// The synthetic bodies of options `so` (with touch rate `rate` when > 0) timed where the
// sequential program runs them: up to three steps from `first` on a sequential executor, in
// a workload of their own, first with the spins off (allocating and warming the buffers),
// then timed, spinning if `spin`.
SyntheticWorkload::BodyTimes bodies_in_place(const Trace& trace, std::uint32_t first,
                                             std::uint32_t n, const ExecOptions& exec,
                                             SyntheticOptions so, bool spin, double rate) {
  auto probe = make_executor(Policy::kSequential, exec);
  const std::uint32_t probed = std::min<std::uint32_t>(n, 3);
  auto run = [&](SyntheticWorkload& w) {
    for (std::uint32_t i = 0; i < probed; ++i) {
      const StepGraph& g = trace.steps[first + i];
      w.set_step(g);
      probe->run_step(g, nullptr, w);
    }
  };
  so.spin = false;
  SyntheticWorkload w(so);
  if (rate > 0) w.set_touch_ns_per_byte(rate);
  run(w);
  w.set_spin(spin);
  w.time_bodies(true);
  run(w);
  return w.timed();
}

}  // namespace

ReplayResult replay_trace(const Trace& trace, const TraceAssignment* assignments,
                          const ReplayOptions& o, const std::vector<std::uint64_t>* predicted,
                          TimelineObserver* timeline) {
  if (trace.steps.empty()) throw UsageError("the trace has no steps");
  if (o.first_step >= trace.steps.size())
    throw OptionError("first_step", std::to_string(o.first_step) + " is past the trace's " +
                                        std::to_string(trace.steps.size()) + " steps");
  const std::uint32_t last =
      o.steps == 0 ? static_cast<std::uint32_t>(trace.steps.size())
                   : std::min<std::uint32_t>(static_cast<std::uint32_t>(trace.steps.size()),
                                             o.first_step + o.steps);
  const bool partition = o.policy == Policy::kPartition;
  if (partition) {
    if (!assignments) throw UsageError("the partition policy needs an assignment");
    if (assignments->steps.size() < last)
      throw UsageError("the assignment covers " + std::to_string(assignments->steps.size()) +
                       " steps, " + std::to_string(last) + " are replayed");
  }
  if (o.repeat == 0) throw OptionError("repeat", "must be at least 1");

  ReplayResult r;
  r.policy = o.policy;
  r.calibration = SyntheticWorkload::calibration();
  CacheMissCounter misses;
  const std::uint64_t misses0 = misses.read();

  auto ex = make_executor(o.policy, o.exec);
  r.threads = ex->threads();  // 1 for the sequential policy, which is its own baseline
  std::unique_ptr<Executor> seq;
  if (o.sequential_baseline && o.policy != Policy::kSequential)
    seq = make_executor(Policy::kSequential, o.exec);
  const std::uint32_t n = last - o.first_step;
  // A body run where the sequential program ran it must cost its recorded time. The rate of
  // the bodies' own data passes there sizes both how much of its data a short task touches
  // (SyntheticOptions::fraction_ns_per_byte, unless the caller fixed it) and its spin after
  // the pass; measured twice, the second time with the fraction the first gave (the words
  // touched change the rate). The process's in-cache rate let the passes of most tasks
  // outlast their recorded costs (cloth256-s64: 24,258 of 28,266 bodies of three steps; its
  // sequential replay ran 8-17 % over its costs), and a stream over one buffer of the
  // working set's size, the passes' best case, did not size the spins better.
  SyntheticOptions so = o.synthetic;
  double in_place = 0, offset = 0;
  if (so.touch) {
    for (int round = 0; round < 2; ++round) {
      const auto t = bodies_in_place(trace, o.first_step, n, o.exec, so, false, 0);
      in_place = t.bytes > 0 ? t.body_ns / t.bytes : 0.0;
      if (in_place > 0 && !o.synthetic.fraction_ns_per_byte) so.fraction_ns_per_byte = in_place;
    }
  }
  // A body that spins runs over its pass and its spin by a little (the calls, the loop's
  // start, a pass slower between spins than back to back: 36-61 ns a task on bars64,
  // 580-780 on cloth256-s64's larger passes): measured on the same steps, taken off each
  // spin.
  if (so.spin) {
    const auto t = bodies_in_place(trace, o.first_step, n, o.exec, so, true, in_place);
    if (t.tasks > 0) offset = (t.body_ns - t.cost_ns) / static_cast<double>(t.tasks);
  }
  SyntheticWorkload w(so), ws(so);
  w.set_spin_offset_ns(offset);
  ws.set_spin_offset_ns(offset);
  r.spin_offset_ns = offset;
  std::uint64_t working_set = 0;
  for (const Datum& d : trace.steps[o.first_step].data) working_set += d.bytes;
  if (so.touch && in_place > 0) {
    ws.set_touch_ns_per_byte(in_place);
    w.set_touch_ns_per_byte(in_place);
    r.touch_ns_per_byte = in_place;
  } else if (so.touch) {
    r.touch_ns_per_byte = ws.calibrate_touch(working_set);
    w.calibrate_touch(working_set);
  }
  r.working_set_bytes = working_set;

  r.steps.resize(n);
  PassTimes walls(n), seq_walls(n), runs(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    const StepGraph& g = trace.steps[o.first_step + i];
    StepMeasure& m = r.steps[i];
    m.step = o.first_step + i;
    const Metrics met = compute_metrics(g);
    m.work_ns = met.work_ns;
    m.span_ns = met.span_ns;
    m.host_ns = g.host_ns;
    r.host_ns += g.host_ns;
    if (predicted && m.step < predicted->size()) m.predicted_makespan_ns = (*predicted)[m.step];
    r.work_ns += m.work_ns;
    r.span_ns += m.span_ns;
  }
  auto assignment_of = [&](std::uint32_t s) -> const Assignment* {
    return partition ? &assignments->steps[s] : nullptr;
  };
  for (std::uint32_t pass = 0; pass < o.repeat; ++pass) {
    if (seq) {
      for (std::uint32_t i = 0; i < n; ++i) {
        const StepGraph& g = trace.steps[o.first_step + i];
        ws.set_step(g);
        const std::int64_t host = ws.run_host(g);
        const ExecStepStats s = seq->run_step(g, nullptr, ws);
        seq_walls.add(i, host + s.wall_ns);
      }
      seq_walls.end_pass();
    }
    for (std::uint32_t i = 0; i < n; ++i) {
      const StepGraph& g = trace.steps[o.first_step + i];
      w.set_step(g);
      const std::int64_t host = w.run_host(g);
      const ExecStepStats s = ex->run_step(g, assignment_of(o.first_step + i), w);
      walls.add(i, host + s.wall_ns);
      runs.add(i, host + s.wall_ns - s.build_ns);
      if (pass == 0) {
        StepMeasure& m = r.steps[i];
        m.build_ns = s.build_ns;
        m.rebuild_ns = s.rebuild_ns;
        m.rebuilt_procs = s.rebuilt_procs;
        m.signals = s.signals();
        m.waits = s.waits();
        m.blocked_waits = s.blocked_waits();
        m.parks = s.parks();
        m.wait_ns = s.wait_ns();
      }
    }
    walls.end_pass();
    runs.end_pass();
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    r.steps[i].wall_ns = walls.step_median(i);
    r.steps[i].run_ns = runs.step_median(i);
    r.steps[i].sequential_wall_ns = seq_walls.step_median(i);
  }
  r.pass_wall_ns = walls.pass_totals();
  r.sequential_pass_wall_ns = seq_walls.pass_totals();
  r.wall_ns = walls.median_total();
  r.sequential_wall_ns = seq_walls.median_total();
  if (o.policy == Policy::kSequential) {  // its own baseline: speed-up 1 by definition
    r.sequential_wall_ns = r.wall_ns;
    for (StepMeasure& m : r.steps) m.sequential_wall_ns = m.wall_ns;
  }
  r.plans_built = ex->plans_built();
  r.cw = ex->cw();
  r.scope = ex->scope();
  r.order_fallbacks = ex->order_fallbacks();
  if (misses.available()) {
    r.cache_misses = misses.read() - misses0;
  } else {
    r.cache_misses_note = misses.reason();
  }

  if (o.observe) {
    StatsObserver stats;
    LocalityObserver locality;
    TimelineObserver own;  // the attribution's, when the caller records none
    TimelineObserver& recorded = timeline ? *timeline : own;
    const std::size_t first_info = recorded.timeline().step_info.size();
    ex->add_observer(stats);
    ex->add_observer(locality);
    ex->add_observer(recorded);
    for (std::uint32_t i = 0; i < n; ++i) {
      const StepGraph& g = trace.steps[o.first_step + i];
      w.set_step(g);
      ex->run_step(g, assignment_of(o.first_step + i), w);
      r.steps[i].threads = stats.threads();
      r.steps[i].remote_bytes = locality.remote_bytes();
      r.steps[i].migrated_bytes = locality.migrated_bytes();
    }
    ex->clear_observers();
    // Where the observed pass's time went, step by step (docs/explain.md).
    Timeline t = recorded.timeline();
    t.step_info.erase(t.step_info.begin(),
                      t.step_info.begin() + static_cast<std::ptrdiff_t>(first_info));
    if (t.step_info.size() == n) {
      explain::ExplainOptions eo;
      eo.what_ifs = false;
      const explain::Explanation e = explain::explain_timeline(t, "observed pass", eo);
      for (std::uint32_t i = 0; i < n; ++i) r.steps[i].attribution = e.steps[i].attribution;
      r.attribution = e.attribution;
    }
  }
  // Amdahl: the host time is serial, in the sequential run and on the critical path alike.
  const double parallelism = r.span_ns == 0 ? 1.0
                                            : static_cast<double>(r.work_ns + r.host_ns) /
                                                  static_cast<double>(r.span_ns + r.host_ns);
  r.bound = std::max(1.0, std::min(static_cast<double>(r.threads), parallelism));
  if (r.wall_ns > 0 && r.sequential_wall_ns > 0)
    r.speedup = static_cast<double>(r.sequential_wall_ns) / static_cast<double>(r.wall_ns);
  r.efficiency = r.speedup / r.bound;
  return r;
}

}  // namespace tgraph::measure
