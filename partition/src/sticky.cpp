// SPDX-License-Identifier: MIT
// `sticky`: the paper's incremental repartitioning (section 2, "modified static scheduling").
#include <algorithm>

#include "strategies.hpp"

namespace tgraph::partition::detail {

namespace {

/// Reuses the previous step's assignment while the structure is unchanged; otherwise keeps
/// every task found again (by stable key) on its processor, places new tasks by affinity to
/// the data they touch, and only when imbalance exceeds the threshold repartitions with
/// Scotch at a migration cost so that few existing tasks move.
///
///   Options o;  o.sticky_threshold = 1.10;  o.migration_cost = 1.0;
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
    if (g.same_structure(*prev.graph)) {
      r.assignment = *prev.assignment;
      r.stats.reused = true;
      return r;
    }

    const auto n = static_cast<TaskId>(g.tasks.size());
    const std::vector<std::uint64_t> work = task_work(g);
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

    // Rebalance: Scotch repartitioning, cut + emraval x migrated bytes.
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
      old[t] = match[t] != kNoTask ? static_cast<std::int32_t>(proc[t]) : -1;
      std::uint64_t bytes = 0;
      for (const Access& acc : g.accesses_of(t)) bytes += g.data[acc.datum].bytes;
      cost[t] = static_cast<std::int32_t>(
          std::clamp<long double>(static_cast<long double>(bytes) * unit, 1.0L, 16777216.0L));
    }
    std::vector<std::uint32_t> part;
    scotch_repart(pg, w, k, options, old, cost, part);
    const std::vector<ProcId> candidate(part.begin(), part.end());
    if (imbalance(loads(work, candidate, k)) < before) {
      proc = candidate;
      r.stats.rebalanced = true;
      r.stats.edgecut = edgecut(pg, proc);
    }
    return r;
  }
};

}  // namespace

std::unique_ptr<Strategy> make_sticky() { return std::make_unique<Sticky>(); }

}  // namespace tgraph::partition::detail
