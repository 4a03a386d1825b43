// SPDX-License-Identifier: MIT
// `sticky`: the paper's incremental repartitioning (section 2, "modified static scheduling").
#include <algorithm>
#include <unordered_map>

#include "strategies.hpp"

namespace tgraph::partition::detail {

namespace {

// The price of cutting each edge, by task (both ends): the synchronisation and transfer time
// (cost model) of the edge per execution of the step (a loop body edge counts every
// iteration). Built once per rebalance and shared by its groups.
using CutPrices = std::vector<std::vector<std::pair<TaskId, double>>>;

CutPrices cut_prices(const StepGraph& g, const model::CostModel& model) {
  CutPrices adj(g.tasks.size());
  auto link = [&](const Edge& e) {
    if (e.from == e.to) return;
    const LoopId l = g.tasks[e.to].loop;
    const double runs = l != kNoLoop && g.tasks[e.from].loop == l ? g.loops[l].iterations : 1.0;
    const double c =
        (model.sync_latency_ns + model.per_byte_ns * static_cast<double>(g.data[e.datum].bytes)) *
        runs;
    adj[e.from].push_back({e.to, c});
    adj[e.to].push_back({e.from, c});
  };
  for (const Edge& e : g.edges) link(e);
  for (const Edge& e : g.carried_edges) link(e);
  return adj;
}

// Work units shared by the greedy rebalance and the refinement: a unit is the tasks of one
// object on one processor (a task without object is a unit of its own), among the tasks
// that may move; the others stay where they are. `unit_of` is scratch of one entry per task
// of the step, kNone everywhere on entry and on exit (reset by the destructor), so that a
// group costs its own size, not the step's.
struct Units {
  struct Unit {
    ProcId proc;
    std::uint64_t work = 0;
    std::vector<TaskId> tasks;
  };
  static constexpr std::size_t kNone = SIZE_MAX;
  std::vector<Unit> units;
  std::vector<std::size_t>& unit_of;
  const std::vector<TaskId>& movable;

  Units(const StepGraph& g, const std::vector<std::uint64_t>& work, const std::vector<ProcId>& proc,
        const std::vector<TaskId>& tasks, std::vector<std::size_t>& scratch)
      : unit_of(scratch), movable(tasks) {
    std::unordered_map<std::uint64_t, std::size_t> unit_of_key;
    for (TaskId t : tasks) {
      const ObjectId o = g.tasks[t].object;
      std::size_t u;
      if (o == kNoObject) {
        u = units.size();
        units.push_back({proc[t], 0, {}});
      } else {
        const std::uint64_t key = (static_cast<std::uint64_t>(o) << 32) | proc[t];
        auto [it, fresh] = unit_of_key.try_emplace(key, units.size());
        if (fresh) units.push_back({proc[t], 0, {}});
        u = it->second;
      }
      units[u].work += work[t];
      units[u].tasks.push_back(t);
      unit_of[t] = u;
    }
  }
  ~Units() {
    for (TaskId t : movable) unit_of[t] = kNone;
  }
  Units(const Units&) = delete;
  Units& operator=(const Units&) = delete;

  // Moves unit u (every task of it) to processor q.
  void move(std::size_t u, ProcId q, std::vector<ProcId>& proc, std::vector<std::uint64_t>& load) {
    Unit& un = units[u];
    for (TaskId t : un.tasks) proc[t] = q;
    load[un.proc] -= un.work;
    load[q] += un.work;
    un.proc = q;
  }
};

// Scratch of one rebalance: per-task entries allocated once, whatever the number of groups.
struct Scratch {
  explicit Scratch(std::size_t n) : unit_of(n, Units::kNone), in_set(n, 0) {}
  std::vector<std::size_t> unit_of;
  std::vector<char> in_set;
};

// Moves work off the most loaded processor while that pays: candidates are whole units and
// single tasks of `tasks`, towards any less loaded processor; only their work counts as
// load. A move's gain is how much it lowers the larger of the two loads; its price is the
// cut it adds minus the cut it removes. The best move with gain > price is applied until
// the imbalance is within `tolerance` or no move pays. Each candidate's edges are walked
// once per round (its link to every processor at once), so a round costs the edges of the
// most loaded processor's tasks plus K per candidate.
void greedy_rebalance(const StepGraph& g, const std::vector<std::uint64_t>& work, std::uint32_t k,
                      double tolerance, const CutPrices& adj, const std::vector<TaskId>& tasks,
                      Scratch& scratch, std::vector<ProcId>& proc) {
  Units us(g, work, proc, tasks, scratch.unit_of);
  auto& units = us.units;
  std::vector<std::uint64_t> load(k, 0);
  for (const auto& un : units) load[un.proc] += un.work;
  std::uint64_t total = 0;
  for (std::uint64_t l : load) total += l;
  const double limit = static_cast<double>(total) / k * tolerance;
  std::vector<char>& in_set = scratch.in_set;
  std::vector<double> link(k);  // a candidate's cut price towards each processor
  std::vector<TaskId> one(1);
  for (std::size_t step = 0; step < 4 * tasks.size(); ++step) {
    const auto p = static_cast<ProcId>(std::max_element(load.begin(), load.end()) - load.begin());
    if (static_cast<double>(load[p]) <= limit) break;
    double best_score = 0.0;
    std::size_t best_unit = SIZE_MAX;
    TaskId best_task = kNoTask;
    ProcId best_q = p;
    auto consider = [&](std::size_t u, TaskId single, std::uint64_t w, const std::vector<TaskId>& ts) {
      if (w == 0) return;
      // The price of moving it from p to q is its link to p minus its link to q.
      for (TaskId t : ts) in_set[t] = 1;
      std::fill(link.begin(), link.end(), 0.0);
      for (TaskId t : ts)
        for (const auto& [o, c] : adj[t])
          if (!in_set[o]) link[proc[o]] += c;
      for (TaskId t : ts) in_set[t] = 0;
      for (ProcId q = 0; q < k; ++q) {
        if (q == p || load[q] + w >= load[p]) continue;
        const double gain = static_cast<double>(load[p] - std::max(load[p] - w, load[q] + w));
        const double price = link[p] - link[q];
        if (gain - price > best_score) {
          best_score = gain - price;
          best_unit = u;
          best_task = single;
          best_q = q;
        }
      }
    };
    for (std::size_t u = 0; u < units.size(); ++u)
      if (units[u].proc == p) consider(u, kNoTask, units[u].work, units[u].tasks);
    for (TaskId t : tasks)
      if (proc[t] == p && units[us.unit_of[t]].tasks.size() > 1) {
        one[0] = t;
        consider(us.unit_of[t], t, work[t], one);
      }
    if (best_unit == SIZE_MAX) break;
    if (best_task != kNoTask) {  // split the task off its unit
      auto& from = units[best_unit];
      from.work -= work[best_task];
      from.tasks.erase(std::find(from.tasks.begin(), from.tasks.end(), best_task));
      best_unit = units.size();
      units.push_back({p, work[best_task], {best_task}});
      us.unit_of[best_task] = best_unit;
    }
    us.move(best_unit, best_q, proc, load);
  }
}

// Every task of the step, in order.
std::vector<TaskId> all_tasks(const StepGraph& g) {
  std::vector<TaskId> v(g.tasks.size());
  for (TaskId t = 0; t < v.size(); ++t) v[t] = t;
  return v;
}

// The greedy rebalance group by group (LoopGroups: the tasks outside heavy loops, then each
// heavy loop): a loop's processors meet at every iteration, so each group is balanced on
// its own, moving only its tasks; without heavy loops, the whole step at once. The cut
// prices and the scratch are made once for all groups.
void phase_rebalance(const StepGraph& g, const std::vector<std::uint64_t>& work, std::uint32_t k,
                     double tolerance, const model::CostModel& model, const LoopGroups& lg,
                     std::vector<ProcId>& proc) {
  const CutPrices adj = cut_prices(g, model);
  Scratch scratch(g.tasks.size());
  if (lg.count < 2) {
    greedy_rebalance(g, work, k, tolerance, adj, all_tasks(g), scratch, proc);
    return;
  }
  std::vector<std::vector<TaskId>> groups(lg.count);
  for (TaskId t = 0; t < g.tasks.size(); ++t) groups[lg.group[t]].push_back(t);
  for (const std::vector<TaskId>& tasks : groups)
    greedy_rebalance(g, work, k, tolerance, adj, tasks, scratch, proc);
}

// Refinement from the incremental placement when collision groups merged or split: units
// move to the processor they are most connected to (by cut price, loop iterations counted)
// while no processor's load exceeds the larger of the tolerance and the current maximum,
// in passes until none pays (at most 8), then the greedy rebalance (to `target`) restores
// the balance. A local search of cost O(edges) per pass
// instead of a whole-step partition: what the paper's future work asks for.
void refine(const StepGraph& g, const std::vector<std::uint64_t>& work, std::uint32_t k,
            double tolerance, double target, const model::CostModel& model,
            std::vector<ProcId>& proc) {
  const CutPrices adj = cut_prices(g, model);
  const std::vector<TaskId> every = all_tasks(g);
  Scratch scratch(g.tasks.size());
  {
    Units us(g, work, proc, every, scratch.unit_of);
    std::vector<std::uint64_t> load = loads(work, proc, k);
    std::uint64_t total = 0;
    for (std::uint64_t l : load) total += l;
    const double limit = std::max(static_cast<double>(total) / k * tolerance,
                                  static_cast<double>(*std::max_element(load.begin(), load.end())));
    std::vector<double> ext(k);
    for (int pass = 0; pass < 8; ++pass) {
      bool moved = false;
      for (std::size_t u = 0; u < us.units.size(); ++u) {
        const auto& un = us.units[u];
        if (un.tasks.empty()) continue;
        std::fill(ext.begin(), ext.end(), 0.0);
        for (TaskId t : un.tasks)
          for (const auto& [o, c] : adj[t])
            if (us.unit_of[o] != u) ext[proc[o]] += c;
        const ProcId p = un.proc;
        ProcId best = p;
        double best_gain = 0.0;
        for (ProcId q = 0; q < k; ++q) {
          if (q == p || static_cast<double>(load[q] + un.work) > limit) continue;
          if (ext[q] - ext[p] > best_gain) {
            best_gain = ext[q] - ext[p];
            best = q;
          }
        }
        if (best == p) continue;
        us.move(u, best, proc, load);
        moved = true;
      }
      if (!moved) break;
    }
  }
  greedy_rebalance(g, work, k, target, adj, every, scratch, proc);
}

// SCOTCH_graphRepart from the current assignment. New tasks get their affinity placement
// as "old" part with the smallest migration cost: Scotch 7.0.3 reads uninitialised memory
// (and may crash) when the old partition holds -1 for new vertices.
void scotch_rebalance(const StepGraph& g, std::uint32_t k, const Options& options,
                      const std::vector<TaskId>& match, std::vector<ProcId>& proc) {
  const auto n = static_cast<TaskId>(g.tasks.size());
  const UndirectedGraph pg = library_graph(g);
  const LibraryWeights w = library_weights(pg);
  // Migration cost of a task = bytes of the data it touches, in the edge weights' units.
  long double raw = 0, scaled = 0;
  for (const Edge& e : g.edges) raw += 2.0L * static_cast<long double>(std::max<std::uint64_t>(1, g.data[e.datum].bytes));
  for (const Edge& e : g.carried_edges)
    raw += 2.0L * static_cast<long double>(std::max<std::uint64_t>(1, g.data[e.datum].bytes));
  for (std::int32_t x : w.adjwgt) scaled += x;
  const long double unit = raw > 0 ? scaled / raw : 1.0L;
  std::vector<std::int32_t> old(n), cost(n);
  for (TaskId t = 0; t < n; ++t) {
    old[t] = static_cast<std::int32_t>(proc[t]);
    std::uint64_t bytes = 0;
    for (const Access& acc : g.accesses_of(t)) bytes += g.data[acc.datum].bytes;
    cost[t] = match[t] == kNoTask ? 1
                                  : static_cast<std::int32_t>(std::clamp<long double>(
                                        static_cast<long double>(bytes) * unit, 1.0L, 16777216.0L));
  }
  std::vector<std::uint32_t> part;
  scotch_repart(pg, w, k, options, old, cost, part);
  proc.assign(part.begin(), part.end());
}

/// Reuses the previous step's assignment while the structure is unchanged; otherwise keeps
/// every task found again (by stable key) on its processor, places new tasks by affinity to
/// the data they touch, and only when imbalance exceeds `threshold` times the imbalance the
/// last full partition (or rebalance) reached rebalances so that few existing tasks move:
/// greedy moves of whole objects (default) or Scotch repartitioning with a migration cost.
/// An instance remembers that baseline between the steps of one trace.
///
///   Options o;  o.sticky_threshold = 1.10;  o.rebalance = Rebalance::kGreedy;
///   TracePartition tp = partition_trace(trace, "sticky", 8, o);
class Sticky final : public Strategy {
 public:
  std::string_view name() const override { return "sticky"; }

 private:
  Result do_partition(const StepGraph& g, std::uint32_t k, const Previous& prev,
                      const Options& options) override {
    const std::vector<std::uint64_t> work = task_work(g);
    // Imbalances are phased (loop_imbalance): a heavy loop's processors meet every iteration.
    const LoopGroups lg = loop_groups(g, work, options.loop_share);
    const auto phased = [&](const std::vector<ProcId>& proc) {
      return phased_imbalance(lg, work, proc, k);
    };
    if (prev.graph == nullptr || prev.assignment->k != k) {
      Result r = base_partition(g, k, options);
      r.assignment.order.clear();
      polish(g, work, k, options, lg, r.assignment.proc);
      remember(r.assignment.proc, phased(r.assignment.proc));
      return r;
    }
    // The imbalance the last full partition or rebalance reached: what the graph's
    // granularity allows. Rebalance only when the current one is `threshold` times worse.
    const double baseline = prev.assignment->proc == last_proc_
                                ? baseline_
                                : loop_imbalance(*prev.graph, *prev.assignment, options.loop_share);
    const double trigger = std::max(options.sticky_threshold, baseline * options.sticky_threshold);
    const double target = std::max(options.imbalance, baseline);
    Result r;
    r.assignment.k = k;
    const auto n = static_cast<TaskId>(g.tasks.size());
    if (g.same_structure(*prev.graph)) {
      // Same graph: reuse as is, unless measured costs drifted past the trigger.
      r.assignment = *prev.assignment;
      if (k == 1 || n <= k || phased(r.assignment.proc) <= trigger) {
        r.stats.reused = true;
        remember(r.assignment.proc, baseline);
        return r;
      }
      r.assignment.order.clear();
      phase_rebalance(g, work, k, target, options.model, lg, r.assignment.proc);
      r.stats.rebalanced = true;
      remember(r.assignment.proc, phased(r.assignment.proc));
      return r;
    }

    const std::vector<TaskId> match = match_by_key(g, *prev.graph);
    std::size_t matched = 0;
    for (TaskId m : match) matched += m != kNoTask ? 1 : 0;
    const bool reshaped =
        g.loops.size() != prev.graph->loops.size() || 4 * matched < 3 * static_cast<std::size_t>(n);
    if (reshaped && options.sticky_fallback == StickyFallback::kFresh) {
      // The shape changed too much to patch (solver loops merged or split, or over a quarter
      // of the tasks are new): partition afresh, then rename the parts so that as many
      // tasks as possible stay where they were (as `metis-relabel` does every step).
      r = base_partition(g, k, options);
      r.assignment.order.clear();
      relabel_to_previous(g, prev, r.assignment);
      polish(g, work, k, options, lg, r.assignment.proc);
      r.stats.fallback = true;
      remember(r.assignment.proc, phased(r.assignment.proc));
      return r;
    }
    std::vector<ProcId>& proc = r.assignment.proc;
    proc.assign(n, 0);
    std::vector<std::uint64_t> load(k, 0);
    std::vector<bool> placed(n, false);
    for (TaskId t = 0; t < n; ++t)
      if (match[t] != kNoTask) {
        proc[t] = prev.assignment->proc[match[t]];
        load[proc[t]] += work[t];
        placed[t] = true;
      }
    // New tasks, in program order: the processor holding most bytes of their data.
    place_by_affinity(g, work, k, placed, proc, load);

    if (reshaped) {
      // kRepartition: Scotch repartitions with the incremental placement as the old
      // partition, trading the cut against migrated load (emraval x bytes each task
      // touches). kRefine: a local search from the incremental placement.
      if (k > 1 && n > k) {
        if (options.sticky_fallback == StickyFallback::kRepartition)
          scotch_rebalance(g, k, options, match, proc);
        else
          refine(g, work, k, options.imbalance, target, options.model, proc);
      }
      r.stats.fallback = true;
      remember(proc, phased(proc));
      return r;
    }
    if (k == 1 || n <= k || phased(proc) <= trigger) {
      remember(proc, baseline);
      return r;
    }
    switch (options.rebalance) {
      case Rebalance::kGreedy:
        phase_rebalance(g, work, k, target, options.model, lg, proc);
        break;
      case Rebalance::kScotch:
        scotch_rebalance(g, k, options, match, proc);
        break;
    }
    r.stats.rebalanced = true;
    remember(proc, phased(proc));
    return r;
  }

  // The base method's partition afresh (METIS by default), its phases balanced separately
  // (Options::sticky_phases) unless Options::phases says otherwise.
  static Result base_partition(const StepGraph& g, std::uint32_t k, const Options& options) {
    const std::string base = options.sticky_base == "sticky" ? "metis" : options.sticky_base;
    Options o = options;
    if (o.phases == 0) o.phases = options.sticky_phases;
    return make_strategy(base)->partition(g, k, {}, o);
  }

  // A multi-constraint METIS partition often misses its tolerance on some heavy loop; the
  // greedy rebalance, loop by loop, brings each group to it where moves pay.
  static void polish(const StepGraph& g, const std::vector<std::uint64_t>& work, std::uint32_t k,
                     const Options& options, const LoopGroups& lg, std::vector<ProcId>& proc) {
    if (k > 1 && g.tasks.size() > k && lg.count > 1)
      phase_rebalance(g, work, k, options.imbalance, options.model, lg, proc);
  }

  void remember(const std::vector<ProcId>& proc, double baseline) {
    last_proc_ = proc;
    baseline_ = baseline;
  }

  // The assignment returned last and the imbalance baseline it carries (see do_partition).
  std::vector<ProcId> last_proc_;
  double baseline_ = 1.0;
};

}  // namespace

std::unique_ptr<Strategy> make_sticky() { return std::make_unique<Sticky>(); }

}  // namespace tgraph::partition::detail
