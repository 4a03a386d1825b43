// SPDX-License-Identifier: MIT
#include "tgraph/partition/compare.hpp"

#include "tgraph/graph/error.hpp"

namespace tgraph::partition {

PartitionSummary summarize(const std::vector<Stats>& stats) {
  PartitionSummary s;
  s.steps = stats.size();
  for (const Stats& st : stats) {
    s.partition_ms += st.partition_ms;
    s.moved_tasks += st.moved_tasks;
    s.reused_steps += st.reused ? 1 : 0;
    s.fallback_steps += st.fallback ? 1 : 0;
    s.rebalanced_steps += st.rebalanced ? 1 : 0;
    if (st.edgecut) s.edgecut = s.edgecut.value_or(0) + *st.edgecut;
  }
  return s;
}

namespace {

std::optional<double> ratio(std::uint64_t a, const std::optional<std::uint64_t>& b) {
  if (!b || *b == 0) return std::nullopt;
  return static_cast<double>(a) / static_cast<double>(*b);
}

}  // namespace

std::optional<double> StickyMoves::over_metis() const { return ratio(sticky, metis); }
std::optional<double> StickyMoves::over_metis_relabel() const {
  return ratio(sticky, metis_relabel);
}

Comparison compare(const Trace& trace, const std::vector<std::string>& methods,
                   const std::vector<std::uint32_t>& ks, const Options& options) {
  for (const std::string& m : methods) (void)make_strategy(m);  // unknown names fail first
  for (std::uint32_t k : ks)
    if (k == 0) throw UsageError("-k: expected values >= 1");
  Comparison c;
  c.model = options.model.source;
  for (const std::string& m : methods)
    for (std::uint32_t k : ks) {
      const TracePartition tp = partition_trace(trace, m, k, options);
      CompareRow row;
      row.method = m;
      row.k = k;
      row.partition = summarize(tp.stats);
      row.report = evaluate(trace, tp.assignment, options.model);
      c.rows.push_back(std::move(row));
    }
  for (std::uint32_t k : ks) {
    auto moved = [&](std::string_view method) -> std::optional<std::uint64_t> {
      for (const CompareRow& r : c.rows)
        if (r.method == method && r.k == k) return r.partition.moved_tasks;
      return std::nullopt;
    };
    const std::optional<std::uint64_t> sticky = moved("sticky");
    if (!sticky) continue;
    bool seen = false;  // a K listed twice gets one entry
    for (const StickyMoves& s : c.sticky_moves) seen = seen || s.k == k;
    if (!seen) c.sticky_moves.push_back({k, *sticky, moved("metis"), moved("metis-relabel")});
  }
  return c;
}

}  // namespace tgraph::partition
