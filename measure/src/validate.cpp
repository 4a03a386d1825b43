// SPDX-License-Identifier: MIT
// `tgraph validate`'s pipeline: live run, capture + replay, simulation.
#include "tgraph/measure/validate.hpp"

#include <algorithm>
#include <map>
#include <optional>
#include <vector>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/median.hpp"
#include "tgraph/measure/capture.hpp"
#include "tgraph/measure/live.hpp"
#include "tgraph/measure/replay_trace.hpp"
#include "tgraph/model/cost_model.hpp"
#include "tgraph/model/simulator.hpp"
#include "tgraph/partition/strategy.hpp"
#include "tgraph/replay/observer.hpp"
#include "tgraph/replay/thread_binding.hpp"

namespace tgraph::measure {

namespace tr = tgraph::replay;

std::vector<std::uint64_t> live_serial_work(const LiveResult& r) {
  std::vector<std::uint64_t> serial;
  for (const LiveStepMeasure& m : r.steps)
    serial.push_back(static_cast<std::uint64_t>(m.record_ns + m.partition_ns + m.prepare_ns));
  return serial;
}

TraceAssignment live_assignment(const Trace& capture, const std::vector<Assignment>& ran,
                                const std::string& method, std::uint32_t k, bool* live) {
  bool fits = ran.size() == capture.steps.size();
  for (std::size_t s = 0; fits && s < ran.size(); ++s)
    fits = validate(capture.steps[s], ran[s], k).empty();
  if (live != nullptr) *live = fits;
  if (fits) return TraceAssignment{method, k, ran, {}};
  return partition::partition_trace(capture, method, k).assignment;
}

TraceAssignment one_processor(const Trace& trace) {
  TraceAssignment one{"single", 1, {}, {}};
  for (const StepGraph& g : trace.steps)
    one.steps.push_back(Assignment{1, std::vector<ProcId>(g.tasks.size(), 0), {}});
  return one;
}

double live_spin_budget_ns(std::uint32_t k, std::int64_t spin_ns) {
  double budget = static_cast<double>(spin_ns);
  if (k <= tr::hardware_pus()) budget = std::max(budget, static_cast<double>(tr::kLongSpinNs));
  return budget;
}

Validation validate(const ValidateOptions& o) {
  Validation v;
  v.choice = o.method;
  const bool partition = v.choice.policy == replay::Policy::kPartition;
  LiveOptions method_options;  // the method's policy, each round's live run starts from it
  const std::optional<partition::StepPartitioner> part =
      live_partitioner(v.choice, partition::Options{}, method_options);
  v.threads = v.choice.policy == replay::Policy::kSequential ? 1 : o.threads;
  if (v.threads == 0) throw OptionError("threads", "must be at least 1");
  if (o.steps == 0) throw OptionError("steps", "must be at least 1");
  if (o.repeat == 0) throw OptionError("repeat", "must be at least 1");
  model::CostModel model = model::select_cost_model("calibrated", o.calibration);
  v.model = model.source;

  for (std::uint32_t round = 0; round < o.repeat; ++round) {
    ValidationRound r;
    // 1. The live run (the truth), timed against the uninstrumented engine.
    LiveOptions lo = method_options;
    lo.exec.threads = v.threads;
    lo.steps = o.steps;
    lo.repeat = 1;
    // The partition policy's observed passes (the policy's, then the sequential one's)
    // time every body: where the threads' time went, beside the simulated schedule's.
    lo.observe = partition;
    lo.keep_assignments = partition;
    const std::string scene = o.scene;
    const samples::SceneOptions so = o.scene_options;
    const LiveResult live = run_live([scene, so] { return make_live_engine(scene, so); },
                                     part ? &*part : nullptr, lo);
    r.live_ns = live.wall_ns;
    r.engine_ns = live.baseline_wall_ns;
    // The main thread's work between the steps' tasks, as this live run measured it.
    const std::vector<std::uint64_t> serial = live_serial_work(live);
    for (std::uint64_t ns : serial) r.serial_ns += ns;
    for (const LiveStepMeasure& m : live.steps) {
      for (const replay::StatsObserver::Thread& t : m.threads) {
        r.live_body_ns += t.busy_ns;
        r.live_wait_ns += t.wait_ns;
        r.live_idle_ns += t.idle_ns;
      }
    }
    // The simulated threads wait as the live run's did: spinning this long, then parked. The
    // partition executor spins on up to kLongSpinNs while the thread it waits for runs, where
    // every thread has a core of its own.
    model.spin_budget_ns = partition ? live_spin_budget_ns(lo.exec.threads, lo.exec.spin_ns)
                                     : static_cast<double>(lo.exec.spin_ns);

    // 2. A capture of the same steps, replayed with synthetic bodies under the same policy.
    const Trace trace = capture_trace(o.scene, o.steps, o.scene_options);
    for (const StepGraph& g : trace.steps) r.host_ns += g.host_ns;
    // The replay and the simulator run what the live run ran: its assignment of each step,
    // the carried-over ones of changed structures included, when the capture recorded the
    // same steps (the scenes are deterministic); else the strategy's partition of the capture.
    std::optional<TraceAssignment> assignment;
    if (partition) {
      bool ran = false;
      assignment = live_assignment(trace, live.assignments, v.choice.method, v.threads, &ran);
      if (ran) ++v.rounds_with_live_assignments;
    }
    ReplayOptions ro;
    ro.policy = v.choice.policy;
    ro.exec.threads = v.threads;
    ro.repeat = 1;
    ro.observe = false;
    ro.sequential_baseline = v.choice.policy != replay::Policy::kSequential;
    const ReplayResult replayed = replay_trace(trace, assignment ? &*assignment : nullptr, ro);
    r.replay_ns = replayed.wall_ns;
    r.replay_sequential_ns = ro.sequential_baseline ? replayed.sequential_wall_ns : replayed.wall_ns;

    // 3. The simulator's makespan of the same partition (partition policy only).
    if (assignment) {
      std::map<std::string, std::pair<double, double>> by_kind;  // inflated, capture's cost
      std::map<std::string, double> kind_instances;              // the capture's instances
      for (std::size_t s = 0; s < trace.steps.size() && s < assignment->steps.size(); ++s) {
        const StepGraph& g = trace.steps[s];
        std::optional<std::uint64_t> serial_s;
        if (o.live_serial && s < serial.size()) serial_s = serial[s];
        const model::Schedule sched = model::simulate(g, assignment->steps[s], model, serial_s);
        r.predicted_ns += sched.makespan_ns;
        const std::uint64_t before = serial_s.value_or(g.host_ns);
        std::uint64_t body = 0, busy = 0;
        for (ProcId p = 0; p < sched.body_ns.size(); ++p) {
          body += sched.body_ns[p];
          busy += sched.busy_ns[p];
        }
        r.predicted_body_ns += body;
        r.predicted_overhead_ns += busy - body;
        const std::uint64_t phase =
            sched.makespan_ns > before ? (sched.makespan_ns - before) * v.threads : 0;
        r.predicted_wait_ns += phase > busy ? phase - busy : 0;
        for (TaskId t = 0; t < g.tasks.size(); ++t) {
          const double n =
              static_cast<double>(sched.first_instance[t + 1] - sched.first_instance[t]);
          by_kind[g.kind_name(t)].second += static_cast<double>(g.tasks[t].cost_ns) * n;
          kind_instances[g.kind_name(t)] += n;
        }
        for (std::size_t k = 0; k < g.kinds.size() && k < sched.kind_body_ns.size(); ++k)
          by_kind[g.kinds[k]].first += static_cast<double>(sched.kind_body_ns[k]);
      }
      // Each kind's two slow-downs, and both over all kinds weighted by sequential time.
      double live_par = 0, live_seq = 0, pred_inflated = 0, pred_cost = 0;
      for (const KindTime& k : live.kinds) {
        KindInflation ki{k.kind, k.instances, 0, 0};
        ki.live_mean_ns = k.mean_ns;
        ki.sequential_mean_ns = k.sequential_mean_ns;
        if (k.sequential_mean_ns > 0) ki.live = k.mean_ns / k.sequential_mean_ns;
        const auto it = by_kind.find(k.kind);
        if (it != by_kind.end() && it->second.second > 0) {
          ki.predicted = it->second.first / it->second.second;
          const auto n = kind_instances.find(k.kind);
          if (n != kind_instances.end() && n->second > 0)
            ki.captured_mean_ns = it->second.second / n->second;
        }
        if (ki.live > 0 && ki.predicted > 0) {
          const double n = static_cast<double>(k.instances);
          live_par += k.mean_ns * n;
          live_seq += k.sequential_mean_ns * n;
          pred_inflated += it->second.first;
          pred_cost += it->second.second;
        }
        r.kinds.push_back(std::move(ki));
      }
      if (live_seq > 0) r.live_inflation = live_par / live_seq;
      if (pred_cost > 0) r.predicted_inflation = pred_inflated / pred_cost;
      // The live speed-up's reference is the uninstrumented engine, which neither records
      // nor partitions: the simulated one is one processor with the capture's host time
      // (the engine's own work outside the tasks), not the live run's serial work.
      for (std::uint64_t ns :
           model::predicted_makespans(trace, one_processor(trace), model, nullptr))
        r.predicted_sequential_ns += ns;
    }
    if (round == 0) {
      bool host = false;
      for (const StepGraph& g : trace.steps) host = host || g.host_ns > 0;
      v.model_terms = model::model_terms(model, o.live_serial, host);
    }
    v.rounds.push_back(r);
  }

  std::vector<double> live, engine, rep, pred, rl, pl, pr, live_su, rep_su, pred_su, rsl, psl;
  for (const ValidationRound& r : v.rounds) {
    const double l = static_cast<double>(r.live_ns), x = static_cast<double>(r.replay_ns),
                 p = static_cast<double>(r.predicted_ns);
    live.push_back(l);
    engine.push_back(static_cast<double>(r.engine_ns));
    rep.push_back(x);
    pred.push_back(p);
    rl.push_back(x / l);
    pl.push_back(p / l);
    pr.push_back(p / x);
    live_su.push_back(static_cast<double>(r.engine_ns) / l);
    rep_su.push_back(static_cast<double>(r.replay_sequential_ns) / x);
    rsl.push_back(rep_su.back() / live_su.back());
    if (partition) {
      pred_su.push_back(static_cast<double>(r.predicted_sequential_ns) / p);
      psl.push_back(pred_su.back() / live_su.back());
    }
  }
  if (partition && !v.rounds.empty()) {
    std::vector<double> body, wait, li, pi;
    for (const ValidationRound& r : v.rounds) {
      if (r.live_body_ns > 0)
        body.push_back(static_cast<double>(r.predicted_body_ns) /
                       static_cast<double>(r.live_body_ns));
      if (r.live_wait_ns > 0)
        wait.push_back(static_cast<double>(r.predicted_wait_ns) /
                       static_cast<double>(r.live_wait_ns));
      if (r.live_inflation > 0) li.push_back(r.live_inflation);
      if (r.predicted_inflation > 0) pi.push_back(r.predicted_inflation);
    }
    if (!body.empty()) v.body_predicted_over_live = median(body);
    if (!wait.empty()) v.wait_predicted_over_live = median(wait);
    if (!li.empty()) v.live_inflation = median(li);
    if (!pi.empty()) v.predicted_inflation = median(pi);
    // Per kind (the first round's), the medians of its two slow-downs over the rounds.
    for (const KindInflation& k : v.rounds.front().kinds) {
      KindInflation m = k;
      std::vector<double> l, p, lm, sm, cm;
      for (const ValidationRound& r : v.rounds)
        for (const KindInflation& x : r.kinds)
          if (x.kind == k.kind) {
            if (x.live > 0) l.push_back(x.live);
            if (x.predicted > 0) p.push_back(x.predicted);
            if (x.live_mean_ns > 0) lm.push_back(x.live_mean_ns);
            if (x.sequential_mean_ns > 0) sm.push_back(x.sequential_mean_ns);
            if (x.captured_mean_ns > 0) cm.push_back(x.captured_mean_ns);
          }
      m.live = l.empty() ? 0 : median(l);
      m.predicted = p.empty() ? 0 : median(p);
      m.live_mean_ns = lm.empty() ? 0 : median(lm);
      m.sequential_mean_ns = sm.empty() ? 0 : median(sm);
      m.captured_mean_ns = cm.empty() ? 0 : median(cm);
      v.kinds.push_back(std::move(m));
    }
  }
  v.live_speedup = median(live_su);
  v.replay_speedup = median(rep_su);
  v.replay_speedup_over_live = median(rsl);
  if (partition) {
    v.predicted_speedup = median(pred_su);
    v.predicted_speedup_over_live = median(psl);
  }
  v.live_ns = static_cast<std::int64_t>(median(live));
  v.engine_ns = static_cast<std::int64_t>(median(engine));
  v.replay_ns = static_cast<std::int64_t>(median(rep));
  v.predicted_ns = partition ? static_cast<std::uint64_t>(median(pred)) : 0;
  v.replay_over_live = median(rl);
  if (partition) {
    v.predicted_over_live = median(pl);
    v.predicted_over_replay = median(pr);
  }
  return v;
}

}  // namespace tgraph::measure
