// SPDX-License-Identifier: MIT
// Live runs: engine bodies through an executor, timing, observation and the state check.
#include "tgraph/replay/live.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <map>
#include <nlohmann/json.hpp>
#include <unordered_map>

#include "sync.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/median.hpp"
#include "tgraph/replay/lowering.hpp"

namespace tgraph::replay {

// ---- ProgramWorkload ---------------------------------------------------------------------

ProgramWorkload::ProgramWorkload(std::span<const std::function<void()>> bodies,
                                 std::span<const std::function<bool()>> conditions,
                                 std::span<const Accumulator* const> accumulators) {
  set_program(bodies, conditions, accumulators);
}

void ProgramWorkload::set_program(std::span<const std::function<void()>> bodies,
                                  std::span<const std::function<bool()>> conditions,
                                  std::span<const Accumulator* const> accumulators) {
  bodies_ = bodies;
  conditions_ = conditions;
  accumulators_ = accumulators;
  reducible_.resize(accumulators.size());
  for (std::size_t d = 0; d < accumulators.size(); ++d) reducible_[d] = accumulators[d] != nullptr;
}

void ProgramWorkload::bind(const ExecGraph& exec) {
  exec_ = &exec;
  const std::size_t nd = exec.graph.data.size();
  temps_.assign(nd, nullptr);
  redirected_.assign(exec.graph.tasks.size(), 0);
  for (TaskId t = 0; t < exec.graph.tasks.size(); ++t)
    for (const Access& a : exec.graph.accesses_of(t))
      if (exec.datum_origin[a.datum] != a.datum && exec.origin[t] != kNoTask) redirected_[t] = 1;
}

bool ProgramWorkload::needs_touch(DatumId d) const {
  return exec_ != nullptr && d < temps_.size() && exec_->datum_origin[d] != d && !temps_[d];
}

void ProgramWorkload::first_touch(DatumId d) {
  const DatumId origin = exec_->datum_origin[d];
  const Accumulator* acc = origin < accumulators_.size() ? accumulators_[origin] : nullptr;
  if (acc == nullptr)
    throw UsageError("live run: datum '" + exec_->graph.data[origin].name +
                     "' was lowered to temporaries but has no accumulator");
  temps_[d] = acc->make_zero();  // on the thread that owns the temporary
}

void ProgramWorkload::run(const TaskRun& r) {
  const ExecGraph& x = *r.exec;
  if (r.origin == kNoTask) {  // a reducer: target += temps, in the lowering's order
    const Reduction& red = x.reductions[x.reduction[r.task]];
    const Accumulator* acc = accumulators_[red.target];
    for (DatumId t : red.temps) acc->add_and_clear(acc->target, temps_[t].get());
    return;
  }
  const auto& body = bodies_[r.origin];
  if (!body) return;
  if (!redirected_[r.task]) {
    body();
    return;
  }
  // At most a handful of CW accesses per task: redirect them for the body's duration.
  Redirect redirects[16];
  std::size_t n = 0;
  for (const Access& a : x.graph.accesses_of(r.task)) {
    const DatumId origin = x.datum_origin[a.datum];
    if (origin == a.datum || n == 16) continue;
    redirects[n++] = Redirect{accumulators_[origin]->target, temps_[a.datum].get()};
  }
  RedirectScope scope({redirects, n});
  body();
}

bool ProgramWorkload::stop_after(LoopId loop, std::uint32_t) { return conditions_[loop](); }

// ---- state comparison --------------------------------------------------------------------

StateSnapshot snapshot(std::span<const StateRegion> regions) {
  StateSnapshot s;
  for (const StateRegion& r : regions) {
    s.names.push_back(r.name);
    const auto* p = static_cast<const std::uint8_t*>(r.ptr);
    s.bytes.emplace_back(p, p + (p ? r.bytes : 0));
  }
  return s;
}

std::optional<StateDifference> compare(const StateSnapshot& expected, const StateSnapshot& actual) {
  const std::size_t n = std::max(expected.bytes.size(), actual.bytes.size());
  for (std::size_t i = 0; i < n; ++i) {
    const std::string& name = i < expected.names.size() ? expected.names[i] : actual.names[i];
    if (i >= expected.bytes.size() || i >= actual.bytes.size()) return StateDifference{name, 0, 0};
    const auto& a = expected.bytes[i];
    const auto& b = actual.bytes[i];
    if (a == b) continue;
    StateDifference d{name, 0, 0};
    const std::size_t m = std::min(a.size(), b.size());
    bool found = false;
    for (std::size_t j = 0; j < m; ++j)
      if (a[j] != b[j]) {
        if (!found) d.offset = j;
        found = true;
        ++d.differing_bytes;
      }
    d.differing_bytes += std::max(a.size(), b.size()) - m;
    if (!found) d.offset = m;
    return d;
  }
  return std::nullopt;
}

std::string to_string(const StateDifference& d) {
  return "first differing datum " + d.datum + " (byte " + std::to_string(d.offset) + ", " +
         std::to_string(d.differing_bytes) + " bytes differ)";
}

// ---- live runs ---------------------------------------------------------------------------

namespace {

/// Mean measured duration of each exec task in the last step (sampled iterations), for the
/// next step's partitioning: deferred recording measures nothing itself.
class CostObserver : public Observer {
 public:
  void on_step_begin(const ExecGraph& exec, std::uint32_t threads, std::int64_t) override {
    exec_ = &exec;
    begin_.assign(static_cast<std::size_t>(threads) * 8, 0);
    sum_.assign(exec.graph.tasks.size(), 0);
    runs_.assign(exec.graph.tasks.size(), 0);
  }
  void on_begin(std::uint32_t thread, TaskId, std::uint32_t, std::int64_t t) override {
    begin_[thread * 8] = t;
  }
  void on_end(std::uint32_t thread, TaskId task, std::uint32_t, std::int64_t t) override {
    // One writer per task at a time: instances of a task never overlap, and the executors
    // order consecutive instances (dependency or same thread).
    sum_[task] += static_cast<std::uint64_t>(t - begin_[thread * 8]);
    ++runs_[task];
  }
  /// Writes the measured means into `g` (the next step): by task index when `g` has the
  /// structure of the measured step, else by stable key; tasks never measured get 1 ns.
  void apply(const StepGraph& measured, StepGraph& g) const {
    if (exec_ == nullptr) {
      for (Task& t : g.tasks) t.cost_ns = 1;
      return;
    }
    if (&measured == &g || (g.tasks.size() == measured.tasks.size() && g.same_structure(measured))) {
      // Same tasks: an exponential average with the costs already there (half weight to
      // the new sample), so that one preempted step does not look like an imbalance.
      for (TaskId t = 0; t < sum_.size(); ++t) {
        const TaskId o = exec_->origin[t];
        if (o == kNoTask || o >= g.tasks.size() || runs_[t] == 0) continue;
        const std::uint64_t sample = sum_[t] / runs_[t];
        const std::uint64_t old = measured.tasks[o].cost_ns;
        g.tasks[o].cost_ns = std::max<std::uint64_t>(1, old > 1 ? (old + sample) / 2 : sample);
      }
      return;
    }
    std::vector<std::uint64_t> cost(measured.tasks.size(), 0);
    for (TaskId t = 0; t < sum_.size(); ++t) {
      const TaskId o = exec_->origin[t];
      if (o != kNoTask && o < cost.size() && runs_[t] > 0) cost[o] = sum_[t] / runs_[t];
    }
    std::unordered_map<StableKey, std::uint64_t> by_key;
    by_key.reserve(cost.size());
    for (TaskId t = 0; t < cost.size(); ++t) by_key[measured.tasks[t].key] = cost[t];
    for (Task& t : g.tasks) {
      const auto it = by_key.find(t.key);
      t.cost_ns = it != by_key.end() ? std::max<std::uint64_t>(1, it->second) : 1;
    }
  }

 private:
  const ExecGraph* exec_ = nullptr;
  std::vector<std::int64_t> begin_;
  std::vector<std::uint64_t> sum_, runs_;
};

/// Time per task kind over the whole run.
class KindObserver : public Observer {
 public:
  void on_step_begin(const ExecGraph& exec, std::uint32_t threads, std::int64_t) override {
    exec_ = &exec;
    slots_.resize(threads);
    for (Slot& s : slots_) s.sum.assign(exec.graph.kinds.size(), {0, 0});
  }
  void on_begin(std::uint32_t thread, TaskId, std::uint32_t, std::int64_t t) override {
    slots_[thread].begin = t;
  }
  void on_end(std::uint32_t thread, TaskId task, std::uint32_t, std::int64_t t) override {
    Slot& s = slots_[thread];
    auto& k = s.sum[exec_->graph.tasks[task].kind];
    k.first += t - s.begin;
    ++k.second;
  }
  void on_step_end(std::int64_t) override {
    for (const Slot& s : slots_)
      for (KindId k = 0; k < s.sum.size(); ++k) {
        auto& tot = total_[exec_->graph.kinds[k]];
        tot.first += s.sum[k].first;
        tot.second += s.sum[k].second;
      }
  }
  const std::map<std::string, std::pair<std::int64_t, std::uint64_t>>& total() const {
    return total_;
  }

 private:
  struct alignas(64) Slot {
    std::int64_t begin = 0;
    std::vector<std::pair<std::int64_t, std::uint64_t>> sum;  // by kind: ns, instances
  };
  const ExecGraph* exec_ = nullptr;
  std::vector<Slot> slots_;
  std::map<std::string, std::pair<std::int64_t, std::uint64_t>> total_;
};

struct PassResult {
  std::vector<LiveStepMeasure> steps;
  std::int64_t wall_ns = 0;
  std::vector<Assignment> assignments;  // when recorded
  StateSnapshot state;
  std::uint64_t signals = 0, waits = 0, blocked_waits = 0, parks = 0;
};

/// Imbalance (max over mean of the processors' work) of `a` on `g` (cost x runs).
double imbalance(const StepGraph& g, const Assignment& a) {
  std::vector<double> load(a.k, 0.0);
  double total = 0;
  for (TaskId t = 0; t < g.tasks.size() && t < a.proc.size(); ++t) {
    const double w = static_cast<double>(g.tasks[t].cost_ns) * static_cast<double>(g.runs(t));
    load[a.proc[t]] += w;
    total += w;
  }
  if (total <= 0 || a.k == 0) return 1.0;
  return *std::max_element(load.begin(), load.end()) / (total / a.k);
}

/// Loop iteration counts for the partitioner: the last step's, by loop index when the
/// structure is the same, else their mean (a deferred recording runs no iteration).
void apply_iterations(const std::vector<std::uint32_t>& last, bool same, StepGraph& g) {
  if (last.empty()) return;
  std::uint64_t sum = 0;
  for (std::uint32_t i : last) sum += i;
  const auto mean = static_cast<std::uint32_t>(std::max<std::uint64_t>(1, sum / last.size()));
  for (LoopId l = 0; l < g.loops.size(); ++l)
    g.loops[l].iterations = same && l < last.size() ? std::max(1u, last[l]) : mean;
}

// One pass of the engine through `ex`. `fixed` (optional): the assignment of each step
// instead of the partitioner's.
PassResult run_pass(const EngineFactory& make_engine, const LivePartitioner* partitioner,
                    Executor& ex, const LiveOptions& o, bool feed_costs, bool keep_assignments,
                    bool keep_state, const std::vector<Assignment>* fixed,
                    StatsObserver* stats) {
  PassResult r;
  std::unique_ptr<LiveEngine> engine = make_engine();
  ProgramWorkload w;
  CostObserver costs;
  if (feed_costs) ex.add_observer(costs);
  const bool partition = ex.policy() == Policy::kPartition;
  LiveStep cur;             // the program in use
  StepGraph prev_graph;     // the graph of the previous recorded program
  Assignment assignment;    // the assignment in use
  std::vector<std::uint32_t> last_iterations;
  bool have_prev = false;
  try {
    for (std::uint32_t s = 0; s < o.steps; ++s) {
      LiveStepMeasure m;
      const std::int64_t t0 = now_ns();
      LiveStep next = engine->record_step(o.reuse_structure);
      const bool reused = next.reuse_previous && s > 0;
      if (!reused) {
        if (next.reuse_previous) throw UsageError("live run: the engine reused a program at step 0");
        if (partition && s > 0) prev_graph = std::move(cur.graph);
        cur = std::move(next);
      }
      m.recorded = !reused;
      if (!reused) m.graph_update_ns = cur.graph_update_ns;
      const std::int64_t t1 = now_ns();
      if (partition) {
        const StepGraph& measured = reused ? cur.graph : prev_graph;
        if (feed_costs) {
          if (have_prev) {
            costs.apply(measured, cur.graph);
          } else {
            for (Task& t : cur.graph.tasks) t.cost_ns = 1;
          }
        }
        apply_iterations(last_iterations, reused, cur.graph);
        if (fixed != nullptr) {
          if (s >= fixed->size())
            throw UsageError("live check: no assignment for step " + std::to_string(s));
          assignment = (*fixed)[s];
        } else if (!have_prev || !reused || o.repartition_every_step ||
                   imbalance(cur.graph, assignment) > 1.0 + o.rebalance_tolerance) {
          assignment = (*partitioner)(cur.graph, ex.threads(), have_prev ? &measured : nullptr,
                                      have_prev ? &assignment : nullptr);
          m.partitioned = true;
        }
        have_prev = true;
      }
      const std::int64_t t2 = now_ns();
      w.set_program(cur.bodies, cur.conditions, cur.accumulators);
      const ExecStepStats ss = ex.run_step(cur.graph, partition ? &assignment : nullptr, w);
      const std::int64_t t3 = now_ns();
      m.record_ns = t1 - t0;
      m.partition_ns = t2 - t1;
      m.prepare_ns = ss.prepare_ns;
      m.build_ns = ss.build_ns;
      m.rebuild_ns = ss.rebuild_ns;
      m.rebuilt_procs = ss.rebuilt_procs;
      m.execute_ns = ss.wall_ns - ss.prepare_ns;
      m.wall_ns = t3 - t0;
      m.rebuilt = ss.rebuilt;
      m.loop_iterations = ss.loop_iterations;
      last_iterations = ss.loop_iterations;
      if (stats != nullptr) m.threads = stats->threads();
      r.signals += ss.signals();
      r.waits += ss.waits();
      r.blocked_waits += ss.blocked_waits();
      r.parks += ss.parks();
      r.wall_ns += m.wall_ns;
      r.steps.push_back(std::move(m));
      if (keep_assignments) r.assignments.push_back(assignment);
    }
  } catch (...) {
    ex.clear_observers();
    throw;
  }
  if (feed_costs) ex.clear_observers();
  if (keep_state) r.state = snapshot(engine->state());
  return r;
}

}  // namespace

LiveResult run_live(const EngineFactory& make_engine, const LivePartitioner* partitioner,
                    const LiveOptions& o) {
  if (o.steps == 0) throw UsageError("--steps must be at least 1");
  if (o.repeat == 0) throw UsageError("--repeat must be at least 1");
  if (o.policy == Policy::kPartition && (partitioner == nullptr || !*partitioner))
    throw UsageError("the partition policy needs a partitioning method");
  LiveResult res;
  res.policy = o.policy;
  // A fresh executor per pass: its threads and pinning end with the pass, so the
  // uninstrumented engine that follows runs where the OS puts it, as users run it (the
  // partition executor pins the calling thread to the first core while it lives).
  auto make = [&o] {
    auto e = make_executor(o.policy, o.exec);
    e->set_observe_stride(o.cost_stride);
    return e;
  };
  std::unique_ptr<Executor> ex = make();
  res.threads = ex->threads();
  res.cw = ex->cw();
  res.scope = ex->scope();
  ex.reset();
  const bool partition = o.policy == Policy::kPartition;

  std::vector<PassResult> passes;
  std::vector<std::vector<std::int64_t>> baseline_steps(o.steps);
  const std::uint32_t baseline_cores =
      o.exec.pin ? std::min<std::uint32_t>({res.threads, detail::hardware_pus(), 4}) : 1;
  res.baseline_core_pass_wall_ns.assign(baseline_cores, {});
  for (std::uint32_t pass = 0; pass < o.repeat; ++pass) {
    if (o.baseline) {
      // The uninstrumented engine on each of the first cores the run uses (cores of a VM
      // can differ in speed; a sequential run could land on either), the fastest kept.
      std::int64_t best = 0;
      std::vector<std::int64_t> best_steps;
      detail::SavedBinding saved;
      detail::save_binding(saved);
      for (std::uint32_t c = 0; c < baseline_cores; ++c) {
        if (o.exec.pin) detail::pin_current_thread(c);
        std::unique_ptr<LiveEngine> engine = make_engine();
        std::int64_t total = 0;
        std::vector<std::int64_t> steps(o.steps);
        for (std::uint32_t s = 0; s < o.steps; ++s) {
          const std::int64_t t0 = now_ns();
          engine->plain_step();
          steps[s] = now_ns() - t0;
          total += steps[s];
        }
        res.baseline_core_pass_wall_ns[c].push_back(total);
        if (best == 0 || total < best) {
          best = total;
          best_steps = std::move(steps);
        }
      }
      detail::restore_binding(saved);
      for (std::uint32_t s = 0; s < o.steps; ++s) baseline_steps[s].push_back(best_steps[s]);
    }
    if (!ex) ex = make();
    passes.push_back(run_pass(make_engine, partitioner, *ex, o, partition, pass == 0 && o.check,
                              pass == 0 && o.check, nullptr, nullptr));
    res.plans_built += ex->plans_built();
    res.order_fallbacks += ex->order_fallbacks();
    ex.reset();
    res.pass_wall_ns.push_back(passes.back().wall_ns);
  }
  res.signals = passes[0].signals;
  res.waits = passes[0].waits;
  res.blocked_waits = passes[0].blocked_waits;
  res.parks = passes[0].parks;
  res.steps.resize(o.steps);
  for (std::uint32_t s = 0; s < o.steps; ++s) {
    LiveStepMeasure& m = res.steps[s];
    auto med = [&](std::int64_t LiveStepMeasure::*field) {
      std::vector<std::int64_t> v;
      for (const PassResult& p : passes) v.push_back(p.steps[s].*field);
      return median(std::move(v));
    };
    m.wall_ns = med(&LiveStepMeasure::wall_ns);
    m.record_ns = med(&LiveStepMeasure::record_ns);
    m.partition_ns = med(&LiveStepMeasure::partition_ns);
    m.prepare_ns = med(&LiveStepMeasure::prepare_ns);
    m.execute_ns = med(&LiveStepMeasure::execute_ns);
    m.build_ns = passes[0].steps[s].build_ns;
    m.rebuild_ns = passes[0].steps[s].rebuild_ns;
    m.rebuilt_procs = passes[0].steps[s].rebuilt_procs;
    m.graph_update_ns = passes[0].steps[s].graph_update_ns;
    m.rebuilt = passes[0].steps[s].rebuilt;
    m.recorded = passes[0].steps[s].recorded;
    m.partitioned = passes[0].steps[s].partitioned;
    m.loop_iterations = passes[0].steps[s].loop_iterations;
    m.baseline_ns = median(baseline_steps[s]);
  }
  res.wall_ns = median(res.pass_wall_ns);
  for (const auto& core : res.baseline_core_pass_wall_ns) {
    const std::int64_t m = median(core);
    if (m > 0 && (res.baseline_wall_ns == 0 || m < res.baseline_wall_ns)) res.baseline_wall_ns = m;
  }
  if (res.baseline_wall_ns > 0 && baseline_cores == res.threads)
    for (const auto& core : res.baseline_core_pass_wall_ns)
      res.core_bound += static_cast<double>(res.baseline_wall_ns) / static_cast<double>(median(core));
  if (res.wall_ns > 0 && res.baseline_wall_ns > 0)
    res.speedup = static_cast<double>(res.baseline_wall_ns) / static_cast<double>(res.wall_ns);

  if (o.observe) {
    // The policy with per-thread and per-kind observers (every instance), then sequential.
    StatsObserver stats;
    KindObserver kinds;
    ex = make();
    ex->set_observe_stride(1);
    ex->add_observer(stats);
    ex->add_observer(kinds);
    PassResult observed;
    try {
      observed = run_pass(make_engine, partitioner, *ex, o, partition, false, false, nullptr, &stats);
    } catch (...) {
      ex->clear_observers();
      throw;
    }
    ex->clear_observers();
    for (std::uint32_t s = 0; s < o.steps; ++s) res.steps[s].threads = observed.steps[s].threads;
    KindObserver seq_kinds;
    if (o.policy != Policy::kSequential) {
      ExecOptions so = o.exec;
      so.threads = 1;
      auto seq = make_executor(Policy::kSequential, so);
      seq->add_observer(seq_kinds);
      run_pass(make_engine, nullptr, *seq, o, false, false, false, nullptr, nullptr);
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
  }

  if (o.check) {
    // A sequential run with the same reduction order (see the header).
    ExecOptions ro = o.exec;
    std::unique_ptr<Executor> ref;
    const std::vector<Assignment>* fixed = nullptr;
    if (res.cw == CwMode::kSerialize || o.policy == Policy::kSequential) {
      ro.threads = 1;
      ro.reduce_scope = ReduceScope::kNone;
      ref = make_executor(Policy::kSequential, ro);
      res.check_reference = "sequential executor, program order";
    } else if (partition) {
      ro.partition.serial = true;
      ref = make_executor(Policy::kPartition, ro);
      fixed = &passes[0].assignments;
      res.check_reference =
          "serial partition executor, same assignments and per-processor reducers";
    } else {
      ro.threads = 1;
      ro.reduce_scope = res.scope;
      ref = make_executor(Policy::kSequential, ro);
      res.check_reference = "sequential executor, same per-writer reducers";
    }
    try {
      const PassResult reference =
          run_pass(make_engine, partitioner, *ref, o, false, false, true, fixed, nullptr);
      res.difference = compare(reference.state, passes[0].state);
      res.data_compared = reference.state.names.size();
    } catch (const UsageError& e) {
      // The reference could not follow the same steps (its graphs differ): a difference.
      res.difference = StateDifference{std::string("structure: ") + e.what(), 0, 0};
    }
    res.check = res.difference ? "differs" : "identical";
  }
  return res;
}

std::string to_json(const LiveResult& r) {
  using nlohmann::json;
  json per_step = json::array();
  std::int64_t record = 0, part = 0, prepare = 0, build = 0, execute = 0;
  std::vector<StatsObserver::Thread> totals;
  for (const LiveStepMeasure& m : r.steps) {
    json threads = json::array();
    if (totals.size() < m.threads.size()) totals.resize(m.threads.size());
    for (std::size_t i = 0; i < m.threads.size(); ++i) {
      const auto& t = m.threads[i];
      threads.push_back({{"busy_ns", t.busy_ns},
                         {"wait_ns", t.wait_ns},
                         {"idle_ns", t.idle_ns},
                         {"tasks", t.tasks}});
      totals[i].busy_ns += t.busy_ns;
      totals[i].wait_ns += t.wait_ns;
      totals[i].idle_ns += t.idle_ns;
      totals[i].tasks += t.tasks;
    }
    record += m.record_ns;
    part += m.partition_ns;
    prepare += m.prepare_ns;
    build += m.build_ns;
    execute += m.execute_ns;
    per_step.push_back({{"wall_ns", m.wall_ns},
                        {"engine_wall_ns", m.baseline_ns},
                        {"record_ns", m.record_ns},
                        {"partition_ns", m.partition_ns},
                        {"prepare_ns", m.prepare_ns},
                        {"build_ns", m.build_ns},
                        {"rebuild_ns", m.rebuild_ns},
                        {"rebuilt_procs", m.rebuilt_procs},
                        {"rebuild_over_wall", m.wall_ns > 0 ? static_cast<double>(m.rebuild_ns) /
                                                                  static_cast<double>(m.wall_ns)
                                                            : 0.0},
                        {"graph_update_ns", m.graph_update_ns},
                        {"execute_ns", m.execute_ns},
                        {"rebuilt", m.rebuilt},
                        {"recorded", m.recorded},
                        {"partitioned", m.partitioned},
                        {"loop_iterations", m.loop_iterations},
                        {"threads", threads}});
  }
  json threads = json::array();
  for (const auto& t : totals)
    threads.push_back(
        {{"busy_ns", t.busy_ns}, {"wait_ns", t.wait_ns}, {"idle_ns", t.idle_ns}, {"tasks", t.tasks}});
  json kinds = json::array();
  for (const KindTime& k : r.kinds) {
    json e = {{"kind", k.kind}, {"instances", k.instances}, {"mean_ns", k.mean_ns}};
    e["sequential_mean_ns"] = k.sequential_mean_ns > 0 ? json(k.sequential_mean_ns) : json(nullptr);
    e["ratio"] = k.sequential_mean_ns > 0 ? json(k.mean_ns / k.sequential_mean_ns) : json(nullptr);
    kinds.push_back(std::move(e));
  }
  json j = {{"policy", std::string(to_string(r.policy))},
            {"threads", r.threads},
            {"cw", std::string(to_string(r.cw))},
            {"reduce_scope", std::string(to_string(r.scope))},
            {"steps", r.steps.size()},
            {"repeat", r.pass_wall_ns.size()},
            {"wall_ns", r.wall_ns},
            {"pass_wall_ns", r.pass_wall_ns},
            {"engine_wall_ns", r.baseline_wall_ns},
            {"engine_core_pass_wall_ns", r.baseline_core_pass_wall_ns},
            {"sequential_wall_ns", r.baseline_wall_ns},
            {"speedup", r.speedup},
            {"core_bound", r.core_bound},
            {"breakdown",
             {{"record_ns", record},
              {"partition_ns", part},
              {"prepare_ns", prepare},
              {"build_ns", build},
              {"execute_ns", execute}}},
            {"threads_total", threads},
            {"kinds", kinds},
            {"signals", r.signals},
            {"waits", r.waits},
            {"blocked_waits", r.blocked_waits},
            {"parks", r.parks},
            {"plans_built", r.plans_built},
            {"order_fallbacks", r.order_fallbacks},
            {"per_step", per_step}};
  if (!r.check.empty()) {
    j["check"] = r.check;
    j["check_reference"] = r.check_reference;
    j["data_compared"] = r.data_compared;
    if (r.difference)
      j["first_difference"] = {{"datum", r.difference->datum},
                               {"offset", r.difference->offset},
                               {"differing_bytes", r.difference->differing_bytes}};
  }
  return j.dump();
}

std::string to_json(const LiveResult& r, const std::string& scene, const std::string& method) {
  auto j = nlohmann::json::parse(to_json(r));
  j["scene"] = scene;
  j["method"] = method;
  return j.dump();
}

std::string to_text(const LiveResult& r, const std::string& scene, const std::string& method,
                    std::uint32_t repeat) {
  std::string out;
  char line[512];
  const auto add = [&](int n) {
    out.append(line, static_cast<std::size_t>(std::clamp(n, 0, 511)));
  };
  const auto ms = [](auto ns) { return static_cast<double>(ns) / 1e6; };
  add(std::snprintf(
      line, sizeof line, "run %s: %zu steps, %s (%s), %u threads, cw %s: %.3f ms (median of %u)\n",
      scene.c_str(), r.steps.size(), std::string(to_string(r.policy)).c_str(), method.c_str(),
      r.threads, std::string(to_string(r.cw)).c_str(), ms(r.wall_ns), repeat));
  if (r.baseline_wall_ns > 0)
    add(std::snprintf(line, sizeof line, "  uninstrumented engine %.3f ms   speed-up %.2f\n",
                      ms(r.baseline_wall_ns), r.speedup));
  const auto b = nlohmann::json::parse(to_json(r))["breakdown"];
  add(std::snprintf(line, sizeof line,
                    "  record %.3f ms, partition %.3f ms, plans %.3f ms, execute %.3f ms\n",
                    b["record_ns"].get<double>() / 1e6, b["partition_ns"].get<double>() / 1e6,
                    b["prepare_ns"].get<double>() / 1e6, b["execute_ns"].get<double>() / 1e6));
  if (!r.check.empty())
    add(std::snprintf(line, sizeof line, "  check against %s: %s (%zu data compared)\n",
                      r.check_reference.c_str(), r.difference ? "DIFFERS" : "identical bit for bit",
                      r.data_compared));
  return out;
}

}  // namespace tgraph::replay
