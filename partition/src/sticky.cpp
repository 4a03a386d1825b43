// SPDX-License-Identifier: MIT
// `sticky`: the paper's incremental repartitioning (section 2, "modified static scheduling").
#include <algorithm>
#include <unordered_map>

#include "strategies.hpp"

namespace tgraph::partition::detail {

namespace {

// Moves whole units (the tasks of one object on one processor; a task without object is a
// unit of its own) from the most loaded to the least loaded processor, each time the unit
// that best evens the pair (ties: the one with most data on the destination), until the
// imbalance is within `tolerance` or no move improves it. Few, large, local moves.
void greedy_rebalance(const StepGraph& g, const std::vector<std::uint64_t>& work, std::uint32_t k,
                      double tolerance, std::vector<ProcId>& proc) {
  const auto n = static_cast<TaskId>(g.tasks.size());
  struct Unit {
    ProcId proc;
    std::uint64_t work = 0;
    std::vector<TaskId> tasks;
  };
  std::vector<Unit> units;
  std::unordered_map<std::uint64_t, std::size_t> unit_of_key;
  std::vector<std::size_t> unit_of(n);
  for (TaskId t = 0; t < n; ++t) {
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
  std::vector<std::vector<std::pair<TaskId, std::uint64_t>>> adj(n);
  auto link = [&](const Edge& e) {
    if (e.from == e.to) return;
    const std::uint64_t b = std::max<std::uint64_t>(1, g.data[e.datum].bytes);
    adj[e.from].push_back({e.to, b});
    adj[e.to].push_back({e.from, b});
  };
  for (const Edge& e : g.edges) link(e);
  for (const Edge& e : g.carried_edges) link(e);

  std::vector<std::uint64_t> load = loads(work, proc, k);
  std::uint64_t total = 0;
  for (std::uint64_t l : load) total += l;
  const double limit = static_cast<double>(total) / k * tolerance;
  for (std::size_t step = 0; step < units.size(); ++step) {
    const auto p = static_cast<ProcId>(std::max_element(load.begin(), load.end()) - load.begin());
    const auto q = static_cast<ProcId>(std::min_element(load.begin(), load.end()) - load.begin());
    if (static_cast<double>(load[p]) <= limit || p == q) break;
    std::size_t best = SIZE_MAX;
    std::uint64_t best_peak = load[p];
    std::int64_t best_affinity = 0;
    for (std::size_t u = 0; u < units.size(); ++u) {
      const Unit& un = units[u];
      if (un.proc != p || un.work == 0 || un.work >= load[p] - load[q]) continue;
      const std::uint64_t peak = std::max(load[p] - un.work, load[q] + un.work);
      if (peak > best_peak) continue;
      std::int64_t affinity = 0;  // bytes to q minus bytes kept on p
      for (TaskId t : un.tasks)
        for (const auto& [o, b] : adj[t]) {
          if (unit_of[o] == u) continue;
          if (proc[o] == q) affinity += static_cast<std::int64_t>(b);
          if (proc[o] == p) affinity -= static_cast<std::int64_t>(b);
        }
      if (best == SIZE_MAX || peak < best_peak || (peak == best_peak && affinity > best_affinity)) {
        best = u;
        best_peak = peak;
        best_affinity = affinity;
      }
    }
    if (best == SIZE_MAX) break;
    Unit& un = units[best];
    for (TaskId t : un.tasks) proc[t] = q;
    un.proc = q;
    load[p] -= un.work;
    load[q] += un.work;
  }
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
/// the data they touch, and only when imbalance exceeds the threshold rebalances so that
/// few existing tasks move: greedy moves of whole objects (default) or Scotch
/// repartitioning with a migration cost.
///
///   Options o;  o.sticky_threshold = 1.10;  o.rebalance = Rebalance::kGreedy;
///   TracePartition tp = partition_trace(trace, "sticky", 8, o);
class Sticky final : public Strategy {
 public:
  std::string_view name() const override { return "sticky"; }

 private:
  Result do_partition(const StepGraph& g, std::uint32_t k, const Previous& prev,
                      const Options& options) override {
    if (prev.graph == nullptr || prev.assignment->k != k) {
      const std::string base = options.sticky_base == "sticky" ? "metis" : options.sticky_base;
      Result r = make_strategy(base)->partition(g, k, {}, options);
      r.assignment.order.clear();
      return r;
    }
    Result r;
    r.assignment.k = k;
    const auto n = static_cast<TaskId>(g.tasks.size());
    const std::vector<std::uint64_t> work = task_work(g);
    if (g.same_structure(*prev.graph)) {
      // Same graph: reuse as is, unless measured costs drifted past the threshold.
      r.assignment = *prev.assignment;
      if (k == 1 || n <= k || imbalance(loads(work, r.assignment.proc, k)) <= options.sticky_threshold) {
        r.stats.reused = true;
        return r;
      }
      r.assignment.order.clear();
      greedy_rebalance(g, work, k, options.imbalance, r.assignment.proc);
      r.stats.rebalanced = true;
      return r;
    }

    const std::vector<TaskId> match = match_by_key(g, *prev.graph);
    std::vector<ProcId>& proc = r.assignment.proc;
    proc.assign(n, 0);
    std::vector<std::uint64_t> load(k, 0);
    std::vector<std::vector<ProcId>> holders(g.data.size());
    auto hold = [&](TaskId t, ProcId p) {
      for (const Access& acc : g.accesses_of(t)) {
        auto& h = holders[acc.datum];
        if (std::find(h.begin(), h.end(), p) == h.end()) h.push_back(p);
      }
    };
    for (TaskId t = 0; t < n; ++t)
      if (match[t] != kNoTask) {
        proc[t] = prev.assignment->proc[match[t]];
        load[proc[t]] += work[t];
        hold(t, proc[t]);
      }
    // New tasks, in program order: the processor holding most bytes of their data.
    std::vector<std::uint64_t> score(k);
    for (TaskId t = 0; t < n; ++t) {
      if (match[t] != kNoTask) continue;
      std::fill(score.begin(), score.end(), 0);
      for (const Access& acc : g.accesses_of(t))
        for (ProcId p : holders[acc.datum]) score[p] += std::max<std::uint64_t>(g.data[acc.datum].bytes, 1);
      ProcId best = static_cast<ProcId>(std::min_element(load.begin(), load.end()) - load.begin());
      for (ProcId p = 0; p < k; ++p)
        if (score[p] > score[best] || (score[p] == score[best] && load[p] < load[best])) best = p;
      proc[t] = best;
      load[best] += work[t];
      hold(t, best);
    }

    const double before = imbalance(load);
    if (before <= options.sticky_threshold || k == 1 || n <= k) return r;
    switch (options.rebalance) {
      case Rebalance::kGreedy:
        greedy_rebalance(g, work, k, options.imbalance, proc);
        break;
      case Rebalance::kScotch:
        scotch_rebalance(g, k, options, match, proc);
        break;
    }
    r.stats.rebalanced = true;
    return r;
  }
};

}  // namespace

std::unique_ptr<Strategy> make_sticky() { return std::make_unique<Sticky>(); }

}  // namespace tgraph::partition::detail
