// SPDX-License-Identifier: MIT
// Executor base (plan cache, timing, validation), the sequential executor and the factory.
#include "tgraph/replay/executor.hpp"

#include <algorithm>
#include <chrono>
#include <string>
#include <string_view>

#include "common.hpp"
#include "planned_executor.hpp"
#include "tgraph/graph/error.hpp"

namespace tgraph::replay {

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

namespace detail {

Csr build_csr(std::size_t n, const std::vector<Edge>& edges, bool by_to) {
  Csr c;
  c.begin.assign(n + 1, 0);
  for (const Edge& e : edges) ++c.begin[(by_to ? e.to : e.from) + 1];
  for (std::size_t i = 0; i < n; ++i) c.begin[i + 1] += c.begin[i];
  c.ids.resize(edges.size());
  std::vector<std::uint32_t> fill(c.begin.begin(), c.begin.end() - 1);
  for (const Edge& e : edges) c.ids[fill[by_to ? e.to : e.from]++] = by_to ? e.from : e.to;
  // Deduplicate each list (several data can link the same pair).
  std::vector<std::uint32_t> nb(n + 1, 0);
  std::vector<TaskId> out;
  out.reserve(c.ids.size());
  for (std::size_t t = 0; t < n; ++t) {
    auto b = c.ids.begin() + c.begin[t], e = c.ids.begin() + c.begin[t + 1];
    std::sort(b, e);
    auto u = std::unique(b, e);
    out.insert(out.end(), b, u);
    nb[t + 1] = static_cast<std::uint32_t>(out.size());
  }
  c.begin = std::move(nb);
  c.ids = std::move(out);
  return c;
}

bool check_unrolled(const ExecGraph& x, LoopId l, std::uint32_t i, std::uint32_t count,
                    Workload& w) {
  const bool stop = leave_loop(x, l, i, w);
  if (stop != (i + 1 == count))
    throw UsageError("loop " + std::to_string(l) + ": the workload's condition " +
                     (stop ? "stops" : "continues") + " after iteration " + std::to_string(i) +
                     ", against its known_iterations");
  return stop;
}

std::vector<std::uint32_t> first_accessor_owner(const ExecGraph& x) {
  std::vector<std::uint32_t> owner(x.graph.data.size(), 0);
  std::vector<bool> seen(x.graph.data.size(), false);
  for (TaskId t = 0; t < x.graph.tasks.size(); ++t)
    for (const Access& a : x.graph.accesses_of(t))
      if (!seen[a.datum]) {
        seen[a.datum] = true;
        owner[a.datum] = x.assignment.proc.empty() ? 0 : x.assignment.proc[t];
      }
  return owner;
}

}  // namespace detail

std::uint64_t ExecStepStats::signals() const {
  std::uint64_t s = 0;
  for (const auto& t : threads) s += t.signals;
  return s;
}
std::uint64_t ExecStepStats::waits() const {
  std::uint64_t s = 0;
  for (const auto& t : threads) s += t.waits;
  return s;
}
std::uint64_t ExecStepStats::blocked_waits() const {
  std::uint64_t s = 0;
  for (const auto& t : threads) s += t.blocked_waits;
  return s;
}
std::uint64_t ExecStepStats::parks() const {
  std::uint64_t s = 0;
  for (const auto& t : threads) s += t.parks;
  return s;
}
std::int64_t ExecStepStats::wait_ns() const {
  std::int64_t s = 0;
  for (const auto& t : threads) s += t.wait_ns;
  return s;
}

struct Executor::CacheEntry {
  std::uint64_t key = 0;
  StepGraph shape;
  Assignment assignment;
  bool has_assignment = false;
  std::vector<bool> reducible;  // Workload::reducible() the plan was lowered with
  ExecGraph exec;
  std::unique_ptr<detail::ExecPlan> plan;
  std::uint64_t bound = 0;  // Workload::instance() holding this plan's buffers
};

Executor::Executor(Policy policy, ExecOptions options) : options_(options), policy_(policy) {}
Executor::~Executor() = default;

CwMode Executor::cw() const { return options_.cw.value_or(CwMode::kReduce); }

ReduceScope Executor::scope() const {
  if (options_.reduce_scope) return *options_.reduce_scope;
  switch (policy_) {
    case Policy::kSequential:
      return ReduceScope::kNone;
    case Policy::kPartition:
      return ReduceScope::kPerProcessor;
    case Policy::kWorksteal:
    case Policy::kBarrier:
    case Policy::kStarpu:
    case Policy::kOmpTasks:
      return ReduceScope::kPerWriter;
  }
  return ReduceScope::kNone;
}

namespace {

/// The plan cache's key of a step's structure: the numbers same_structure() compares (which
/// confirms every hit, names included), hashed word by word in four independent chains.
/// StepGraph::structural_hash() hashes byte by byte for the files that store it (one
/// dependent multiply per byte: tens of microseconds per step for a bars64-sized step, paid
/// on every run_step); this key is never stored. Names are left to the comparison (steps
/// whose numbers agree but whose names differ are told apart by same_structure() all the
/// same).
std::uint64_t structure_key(const StepGraph& g) {
  // Four independent chains (a dependent multiply per word is the cost), joined at the end.
  std::uint64_t h0 = 0x243f6a8885a308d3ull ^ g.tasks.size(),
                h1 = 0x13198a2e03707344ull ^ g.data.size(),
                h2 = 0xa4093822299f31d0ull ^ g.accesses.size(),
                h3 = 0x082efa98ec4e6c89ull ^ ((g.loops.size() << 32) | g.objects.size());
  const auto mix = [](std::uint64_t& h, std::uint64_t v) {
    h = (h ^ v) * 0x9e3779b97f4a7c15ull;
    h ^= h >> 29;
  };
  h3 ^= g.kinds.size() << 48;
  for (const auto& d : g.data) mix(h3, (static_cast<std::uint64_t>(d.object) << 32) ^ d.bytes);
  for (const Task& t : g.tasks) {
    mix(h0, (static_cast<std::uint64_t>(t.kind) << 32) | t.object);
    mix(h1, (static_cast<std::uint64_t>(t.access_count) << 32) | t.loop);
    mix(h2, t.key);
  }
  const auto word = [](const Access& a) {
    return (static_cast<std::uint64_t>(a.datum) << 8) | static_cast<std::uint64_t>(a.mode);
  };
  const std::size_t na = g.accesses.size();
  std::size_t i = 0;
  for (; i + 4 <= na; i += 4) {
    mix(h0, word(g.accesses[i]));
    mix(h1, word(g.accesses[i + 1]));
    mix(h2, word(g.accesses[i + 2]));
    mix(h3, word(g.accesses[i + 3]));
  }
  for (; i < na; ++i) mix(h3, word(g.accesses[i]));
  for (const Loop& l : g.loops) {
    mix(h0, (static_cast<std::uint64_t>(l.condition) << 32) | l.max_iterations);
    mix(h1, (static_cast<std::uint64_t>(l.first) << 32) | l.last);
  }
  mix(h0, h1);
  mix(h0, h2);
  mix(h0, h3);
  return h0;
}

void validate_assignment(const StepGraph& g, const Assignment& a, std::uint32_t threads) {
  if (a.k != threads)
    throw UsageError("assignment has k = " + std::to_string(a.k) + " processors but " +
                     std::to_string(threads) + " threads were asked for");
  if (a.proc.size() != g.tasks.size())
    throw UsageError("assignment covers " + std::to_string(a.proc.size()) +
                     " tasks, the step has " + std::to_string(g.tasks.size()));
  for (std::size_t t = 0; t < a.proc.size(); ++t)
    if (a.proc[t] >= a.k)
      throw UsageError("assignment puts task " + std::to_string(t) + " on processor " +
                       std::to_string(a.proc[t]) + " >= k");
  if (a.order.empty()) return;
  if (a.order.size() != a.k)
    throw UsageError("assignment order has the wrong number of processors");
  std::vector<bool> seen(g.tasks.size(), false);
  for (ProcId p = 0; p < a.k; ++p)
    for (TaskId t : a.order[p]) {
      if (t >= g.tasks.size() || a.proc[t] != p || seen[t])
        throw UsageError("assignment order of processor " + std::to_string(p) + " lists task " +
                         std::to_string(t) + " wrongly");
      seen[t] = true;
    }
  if (std::find(seen.begin(), seen.end(), false) != seen.end())
    throw UsageError("assignment order misses tasks");
}

}  // namespace

ExecStepStats Executor::run_step(const StepGraph& g, const Assignment* a, Workload& w) {
  ExecStepStats stats;
  const std::int64_t t0 = now_ns();
  const bool use_assignment = policy_ == Policy::kPartition;
  if (use_assignment && a == nullptr) throw UsageError("the partition policy needs an assignment");
  const CwMode mode = cw();
  const ReduceScope reduce = scope();
  const std::vector<bool>* reducible = w.reducible();
  // An entry serves this step when its structure, assignment and reducible data are this
  // step's (mode and scope are the executor's own, fixed at construction).
  const auto serves = [&](const CacheEntry& e) {
    return (reducible ? e.reducible == *reducible : e.reducible.empty()) &&
           (!use_assignment || (e.has_assignment && e.assignment == *a)) &&
           e.shape.same_structure(g);
  };
  // The previous step's entry first, confirmed without the key: a structure that repeats
  // (a step without contact changes) skips hashing it.
  std::shared_ptr<CacheEntry> entry;
  if (last_entry_ && serves(*last_entry_)) entry = last_entry_;
  std::uint64_t key = 0;
  if (!entry) {
    key = structure_key(g) * 31 + static_cast<std::uint64_t>(mode) * 7 +
          static_cast<std::uint64_t>(reduce);
    // The assignment is not hashed (one dependent multiply per task on every step): the
    // entries of one structure are few and their assignments are compared (a memcmp) before
    // their structure.
    if (reducible != nullptr)
      key ^= std::hash<std::vector<bool>>{}(*reducible) * 0xff51afd7ed558ccdull;
    for (auto& e : cache_)
      if (e->key == key && serves(*e)) {
        entry = e;
        break;
      }
  }
  if (!entry) {
    if (use_assignment) validate_assignment(g, *a, options_.threads);
    entry = std::make_shared<CacheEntry>();
    entry->key = key;
    if (reducible) entry->reducible = *reducible;
    entry->shape = g;
    entry->shape.edges.clear();
    entry->shape.carried_edges.clear();
    if (use_assignment) {
      entry->assignment = *a;
      entry->has_assignment = true;
    }
    entry->exec = lower(g, use_assignment ? a : nullptr, mode, reduce, reducible,
                        options_.incremental_plans ? &exec_edges_ : nullptr, options_.threads);
    const std::int64_t t_lowered = now_ns();
    entry->plan = build(entry->exec, last_entry_ && options_.incremental_plans
                                         ? last_entry_->plan.get()
                                         : nullptr);
    stats.rebuild_ns = now_ns() - t_lowered;
    stats.rebuilt_procs = rebuilt_procs(*entry->plan);
    ++plans_built_;
    stats.rebuilt = true;
    if (cache_.size() >= 16) cache_.erase(cache_.begin());
    cache_.push_back(entry);
  }
  const bool fresh = entry->bound != w.instance();
  if (fresh) {
    for (auto& e : cache_) e->bound = 0;  // the workload now holds this plan's buffers
    w.bind(entry->exec);
    entry->bound = w.instance();
  }
  const std::int64_t t_built = now_ns();
  if (stats.rebuilt) stats.build_ns = t_built - t0;
  stats.prepare_ns = t_built - t0;
  last_exec_ = &entry->exec;
  last_entry_ = entry;
  for (Observer* o : observers_) o->on_step_begin(entry->exec, options_.threads, t_built);
  try {
    execute(*entry->plan, entry->exec, w, fresh, stats);
  } catch (...) {
    const std::int64_t t_end = now_ns();
    for (Observer* o : observers_) o->on_step_end(t_end);
    throw;
  }
  const std::int64_t t1 = now_ns();
  stats.wall_ns = t1 - t0;
  for (Observer* o : observers_) o->on_step_end(t1);
  return stats;
}

namespace {

/// The sequential executor needs nothing beyond the exec graph: it runs program order.
struct SequentialPlan {};

/// One thread, program order: the reference every other policy is compared with.
class SequentialExecutor final : public detail::PlannedExecutor<SequentialPlan> {
 public:
  explicit SequentialExecutor(ExecOptions o) : PlannedExecutor(Policy::kSequential, o) {}

 private:
  std::unique_ptr<SequentialPlan> build_plan(const ExecGraph&) override {
    return std::make_unique<SequentialPlan>();
  }

  void run(SequentialPlan&, const ExecGraph& x, Workload& w, bool fresh,
           ExecStepStats& stats) override {
    const StepGraph& g = x.graph;
    if (fresh) detail::touch_all(g, w);
    stats.threads.assign(1, {});
    stats.loop_iterations.assign(g.loops.size(), 0);
    ThreadCounters& c = stats.threads[0];
    const std::vector<Observer*>& obs = observers();
    const bool observe = !obs.empty();
    const std::uint32_t stride = observe_stride();
    auto run_task = [&](TaskId t, std::uint32_t it) {
      if (observe && detail::sampled(it, stride)) detail::notify_begin(obs, 0, t, it);
      w.run(TaskRun{&x, t, x.origin[t], it, 0});
      if (observe && detail::sampled(it, stride)) detail::notify_end(obs, 0, t, it);
      ++c.tasks;
    };
    detail::walk_step(
        g, [] { return false; }, [&](TaskId t) { run_task(t, 0); },
        [&](LoopId l) {
          const Loop& loop = g.loops[l];
          std::uint32_t it = 0;
          for (;; ++it) {
            for (TaskId u = loop.first; u < loop.last; ++u) run_task(u, it);
            if (detail::leave_loop(x, l, it, w)) break;
          }
          stats.loop_iterations[l] = it + 1;
        });
  }
};

}  // namespace

std::unique_ptr<Executor> make_sequential_executor(const ExecOptions& options) {
  ExecOptions o = options;
  o.threads = 1;  // one thread, whatever was asked for
  return std::make_unique<SequentialExecutor>(o);
}

std::unique_ptr<Executor> make_registered_executor(Policy policy, const ExecOptions& options);

std::unique_ptr<Executor> make_executor(Policy policy, const ExecOptions& options) {
  if (options.threads == 0) throw OptionError("threads", "must be at least 1");
  if (options.threads > 1024 && policy != Policy::kSequential)
    throw OptionError("threads", "must be at most 1024");
  // The partition policy's temporaries are its processors' (kPerProcessor); the per-writer and
  // per-thread scopes are the dynamic policies' choices (a sequential run takes any scope, to
  // reproduce another policy's reduction order).
  if (policy == Policy::kPartition && options.reduce_scope &&
      *options.reduce_scope != ReduceScope::kPerProcessor)
    throw OptionError("reduce_scope",
                      "applies to the dynamic policies (worksteal, barrier, starpu, omp-tasks); the "
                      "partition policy reduces per processor");
  return make_registered_executor(policy, options);  // registry.cpp
}

}  // namespace tgraph::replay
