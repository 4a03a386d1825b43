// SPDX-License-Identifier: MIT
#include "tgraph/partition/compare.hpp"

#include <cstdio>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/partition/assignment_io.hpp"
#include "tgraph/partition/partition_graph.hpp"

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

std::string row_label(const CompareRow& row) {
  if (!row.migration_cost) return row.method;
  char cost[32];
  std::snprintf(cost, sizeof cost, "%g", *row.migration_cost);
  return row.method + "@" + cost;
}

namespace {

// Marks the rows of each K that no other row of that K dominates in (moved, objective).
template <typename Objective>
void mark_pareto(std::vector<CompareRow>& rows, Objective objective, bool CompareRow::*flag) {
  for (CompareRow& r : rows) {
    r.*flag = true;
    for (const CompareRow& o : rows) {
      if (&o == &r || o.k != r.k) continue;
      const std::uint64_t mo = o.partition.moved_tasks, mr = r.partition.moved_tasks;
      const auto fo = objective(o), fr = objective(r);
      if (mo <= mr && fo <= fr && (mo < mr || fo < fr)) {
        r.*flag = false;
        break;
      }
    }
  }
}

}  // namespace

TracePartition partition_file(const std::string& trace_path, const std::string& method,
                              std::uint32_t k, const Options& options, const std::string& output) {
  const Trace trace = read_trace(trace_path);
  if (k == 0) throw OptionError("k", "expected at least 1");
  TracePartition r = partition_trace(trace, method, k, options);
  if (!output.empty()) write_assignment(output, r.assignment, trace);
  // One measure for every method and step: the strategies report their library's own
  // objective, and some only for the steps they called it on (sticky: step 0).
  for (std::size_t s = 0; s < r.stats.size() && s < trace.steps.size(); ++s)
    r.stats[s].edgecut = edgecut(library_graph(trace.steps[s]), r.assignment.steps[s].proc);
  return r;
}

Comparison compare(const Trace& trace, const std::vector<std::string>& methods,
                   const std::vector<std::uint32_t>& ks, const Options& options,
                   const std::vector<double>& sticky_migration_costs) {
  for (const std::string& m : methods) (void)make_strategy(m);  // unknown names fail first
  for (std::uint32_t k : ks)
    if (k == 0) throw OptionError("k", "expected values >= 1");
  for (double cost : sticky_migration_costs)
    if (!(cost >= 0.0)) throw OptionError("sticky_migration_cost", "expected values >= 0");
  Comparison c;
  c.model = options.model.source;
  auto run = [&](const std::string& m, std::uint32_t k, const Options& o,
                 std::optional<double> cost) {
    const TracePartition tp = partition_trace(trace, m, k, o);
    CompareRow row;
    row.method = m;
    row.k = k;
    row.migration_cost = cost;
    row.partition = summarize(tp.stats);
    row.report = evaluate(trace, tp.assignment, o.model);
    c.rows.push_back(std::move(row));
  };
  c.sticky_fallback = options.sticky_fallback;
  for (const std::string& m : methods)
    for (std::uint32_t k : ks) run(m, k, options, std::nullopt);
  for (double cost : sticky_migration_costs)
    for (std::uint32_t k : ks) {
      Options o = options;
      o.sticky_fallback = StickyFallback::kRepartition;
      o.migration_cost = cost;
      run("sticky", k, o, cost);
    }
  mark_pareto(
      c.rows, [](const CompareRow& r) { return r.report.total.makespan_ns; },
      &CompareRow::pareto_makespan);
  mark_pareto(
      c.rows, [](const CompareRow& r) { return r.report.total.cut_bytes; },
      &CompareRow::pareto_cut);
  for (std::uint32_t k : ks) {
    auto moved = [&](std::string_view method) -> std::optional<std::uint64_t> {
      for (const CompareRow& r : c.rows)
        if (r.method == method && r.k == k && !r.migration_cost) return r.partition.moved_tasks;
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

std::string compare_file(const std::string& trace, const std::vector<std::string>& methods,
                         const std::vector<std::uint32_t>& ks, const Options& options,
                         const std::vector<double>& sticky_migration_costs,
                         const std::string& csv, bool json) {
  const Comparison c = compare(read_trace(trace), methods, ks, options, sticky_migration_costs);
  if (!csv.empty()) write_file_atomic(csv, comparison_csv(c));
  return json ? comparison_json(c, trace) + "\n" : comparison_table(c);
}

}  // namespace tgraph::partition
