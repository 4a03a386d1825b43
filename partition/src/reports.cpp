// SPDX-License-Identifier: MIT
// JSON, CSV and text renderings of evaluation reports, partition summaries and the grid.
#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

#include "tgraph/graph/json_util.hpp"
#include "tgraph/partition/compare.hpp"
#include "tgraph/partition/evaluate.hpp"

namespace tgraph::partition {

namespace {

using nlohmann::json;

json step_json(const StepReport& r) {
  return {{"tasks", r.tasks},
          {"cut_edges", r.cut_edges},
          {"cut_bytes", r.cut_bytes},
          {"signals", r.signals},
          {"waits", r.waits},
          {"reducers", r.reducers},
          {"transfer_bytes", r.transfer_bytes},
          {"imbalance", r.imbalance},
          {"max_load_ns", r.max_load_ns},
          {"work_ns", r.work_ns},
          {"span_ns", r.span_ns},
          {"host_ns", r.host_ns},
          {"lower_bound_ns", r.lower_bound_ns},
          {"predicted_makespan_ns", r.makespan_ns},
          {"predicted_speedup", r.speedup},
          {"migrated_tasks", r.migrated_tasks},
          {"migrated_bytes", r.migrated_bytes},
          {"partition_ms", r.partition_ms},
          {"quotient_acyclic", r.quotient_acyclic},
          {"ping_pong_pairs", r.ping_pong_pairs},
          {"robust_work_ns", r.robust_work_ns},
          {"robust_max_load_ns", r.robust_max_load_ns},
          {"robust_imbalance", r.robust_imbalance},
          {"robust_predicted_makespan_ns", r.robust_makespan_ns},
          {"robust_predicted_speedup", r.robust_speedup}};
}

json report_object(const Report& rep, bool per_step) {
  json j = step_json(rep.total);
  j["method"] = rep.method;
  j["k"] = rep.k;
  j["model"] = rep.model;
  j["steps"] = rep.steps.size();
  j["imbalance_max"] = rep.imbalance_max;
  j["cyclic_steps"] = rep.cyclic_steps;
  j["predicted_speedup_with_partitioning"] = rep.speedup_with_partitioning;
  j["model_terms"] = rep.model_terms;
  j["costs"] =
      "raw: the recorded costs; robust_*: each task's cost the median of its cost over the "
      "steps of its structure";
  if (per_step) {
    json per = json::array();
    for (std::size_t s = 0; s < rep.steps.size(); ++s) {
      json sj = step_json(rep.steps[s]);
      sj["step"] = s;
      per.push_back(sj);
    }
    j["per_step"] = per;
  }
  return j;
}

// The summary's keys, added to `j`.
void add_summary(json& j, const PartitionSummary& s) {
  j["moved_tasks"] = s.moved_tasks;
  j["reused_steps"] = s.reused_steps;
  j["fallback_steps"] = s.fallback_steps;
  j["rebalanced_steps"] = s.rebalanced_steps;
  if (s.edgecut) j["edgecut"] = *s.edgecut;
}

const StickyMoves* sticky_moves_at(const Comparison& c, std::uint32_t k) {
  for (const StickyMoves& s : c.sticky_moves)
    if (s.k == k) return &s;
  return nullptr;
}

std::string csv_number(const std::optional<double>& v) {
  if (!v) return "";
  std::ostringstream s;
  s << *v;
  return s.str();
}

}  // namespace

std::string report_json(const Report& report, bool per_step) {
  return report_object(report, per_step).dump();
}

std::string report_text(const Report& rep) {
  const StepReport& t = rep.total;
  std::string out;
  char line[512];
  auto add = [&](int n) { out.append(line, static_cast<std::size_t>(std::clamp(n, 0, 511))); };
  add(std::snprintf(line, sizeof line, "method %s, k = %u, %zu steps, cost model: %s\n",
                    rep.method.c_str(), rep.k, rep.steps.size(), rep.model.c_str()));
  add(std::snprintf(
      line, sizeof line,
      "  cut: %llu edges, %llu bytes; %llu signals, %llu waits, %llu reducers, %llu bytes moved\n",
      static_cast<unsigned long long>(t.cut_edges), static_cast<unsigned long long>(t.cut_bytes),
      static_cast<unsigned long long>(t.signals), static_cast<unsigned long long>(t.waits),
      static_cast<unsigned long long>(t.reducers),
      static_cast<unsigned long long>(t.transfer_bytes)));
  add(std::snprintf(
      line, sizeof line, "  imbalance %.3f (worst step %.3f); migrations: %llu tasks, %llu bytes\n",
      t.imbalance, rep.imbalance_max, static_cast<unsigned long long>(t.migrated_tasks),
      static_cast<unsigned long long>(t.migrated_bytes)));
  add(std::snprintf(
      line, sizeof line,
      "  predicted makespan %.3f ms, lower bound %.3f ms, work %.3f ms: speed-up %.2f "
      "(%.2f with %.3f ms partitioning)\n",
      static_cast<double>(t.makespan_ns) / 1e6, static_cast<double>(t.lower_bound_ns) / 1e6,
      static_cast<double>(t.work_ns) / 1e6, t.speedup, rep.speedup_with_partitioning,
      t.partition_ms));
  add(std::snprintf(line, sizeof line,
                    "  robust costs (each task's the median of its key over the steps of its "
                    "structure): imbalance %.3f, predicted makespan %.3f ms, speed-up %.2f\n",
                    t.robust_imbalance, static_cast<double>(t.robust_makespan_ns) / 1e6,
                    t.robust_speedup));
  add(std::snprintf(
      line, sizeof line, "  quotient graph: %s (%llu steps with cycles, %llu ping-pong pairs)\n",
      t.quotient_acyclic ? "acyclic" : "cyclic", static_cast<unsigned long long>(rep.cyclic_steps),
      static_cast<unsigned long long>(t.ping_pong_pairs)));
  return out;
}

std::string partition_json(const TracePartition& tp, const std::string& output) {
  const PartitionSummary s = summarize(tp.stats);
  json per_step = json::array();
  for (std::size_t i = 0; i < tp.stats.size(); ++i) {
    const Stats& st = tp.stats[i];
    json j = {
        {"step", i},           {"partition_ms", st.partition_ms}, {"moved_tasks", st.moved_tasks},
        {"reused", st.reused}, {"fallback", st.fallback},         {"rebalanced", st.rebalanced}};
    if (st.edgecut) j["edgecut"] = *st.edgecut;
    per_step.push_back(j);
  }
  json j = {{"method", tp.assignment.method},
            {"k", tp.assignment.k},
            {"steps", s.steps},
            {"partition_ms", s.partition_ms},
            {"output", output},
            {"placed_by", tp.placed_by},
            {"warnings", tp.warnings}};
  add_summary(j, s);
  j["per_step"] = per_step;
  return j.dump();
}

std::string partition_text(const TracePartition& tp, const std::string& output) {
  const PartitionSummary s = summarize(tp.stats);
  char line[512];
  std::snprintf(line, sizeof line, "method %s, k = %u, %zu steps: %.3f ms partitioning",
                tp.assignment.method.c_str(), tp.assignment.k, s.steps, s.partition_ms);
  std::string out = line;
  if (s.edgecut)
    out += ", edgecut " + std::to_string(*s.edgecut) + " (summed over the steps, in METIS's units)";
  out += ", " + std::to_string(s.moved_tasks) + " tasks moved";
  if (tp.assignment.method == "sticky")
    out += " (steps: " + std::to_string(s.reused_steps) + " reused, " +
           std::to_string(s.fallback_steps) + " fallback to a fresh partition + relabel, " +
           std::to_string(s.rebalanced_steps) + " rebalanced)";
  out += "\n";
  if (!output.empty()) out += "wrote " + output + "\n";
  return out;
}

std::string comparison_json(const Comparison& c, const std::string& trace_name) {
  json rows = json::array();
  for (const CompareRow& r : c.rows) {
    json row = report_object(r.report, false);
    add_summary(row, r.partition);
    row["label"] = row_label(r);
    row["migration_cost"] = optional_json(r.migration_cost);
    row["pareto_makespan"] = r.pareto_makespan;
    row["pareto_cut"] = r.pareto_cut;
    if (r.method == "sticky" && !r.migration_cost)
      if (const StickyMoves* s = sticky_moves_at(c, r.k)) {
        row["moved_over_metis"] = optional_json(s->over_metis());
        row["moved_over_metis_relabel"] = optional_json(s->over_metis_relabel());
      }
    rows.push_back(row);
  }
  json moves = json::array();
  for (const StickyMoves& s : c.sticky_moves)
    moves.push_back({{"k", s.k},
                     {"sticky", s.sticky},
                     {"metis", optional_json(s.metis)},
                     {"metis_relabel", optional_json(s.metis_relabel)},
                     {"sticky_over_metis", optional_json(s.over_metis())},
                     {"sticky_over_metis_relabel", optional_json(s.over_metis_relabel())}});
  json pareto = json::array();
  for (std::size_t i = 0; i < c.rows.size(); ++i) {
    bool first = true;  // one entry per K, at its first row
    for (std::size_t j = 0; j < i; ++j) first = first && c.rows[j].k != c.rows[i].k;
    if (!first) continue;
    json makespan = json::array(), cut = json::array();
    for (const CompareRow& r : c.rows) {
      if (r.k != c.rows[i].k) continue;
      if (r.pareto_makespan) makespan.push_back(row_label(r));
      if (r.pareto_cut) cut.push_back(row_label(r));
    }
    pareto.push_back({{"k", c.rows[i].k}, {"makespan", makespan}, {"cut", cut}});
  }
  return json{{"trace", trace_name},
              {"model", c.model},
              {"rows", rows},
              {"sticky_moves", moves},
              {"sticky_fallback", to_string(c.sticky_fallback)},
              {"pareto", pareto}}
      .dump();
}

std::string comparison_csv(const Comparison& c) {
  std::ostringstream csv;
  csv << "method,k,partition_ms,cut_edges,cut_bytes,signals,reducers,imbalance,migrated_tasks,"
         "predicted_makespan_ns,lower_bound_ns,predicted_speedup,quotient_acyclic,reused_steps,"
         "fallback_steps,rebalanced_steps,moved_over_metis,moved_over_metis_relabel,migration_cost,"
         "pareto_makespan,pareto_cut\n";
  for (const CompareRow& r : c.rows) {
    const StepReport& t = r.report.total;
    const StickyMoves* s =
        r.method == "sticky" && !r.migration_cost ? sticky_moves_at(c, r.k) : nullptr;
    csv << r.method << ',' << r.k << ',' << t.partition_ms << ',' << t.cut_edges << ','
        << t.cut_bytes << ',' << t.signals << ',' << t.reducers << ',' << t.imbalance << ','
        << t.migrated_tasks << ',' << t.makespan_ns << ',' << t.lower_bound_ns << ',' << t.speedup
        << ',' << (t.quotient_acyclic ? 1 : 0) << ',' << r.partition.reused_steps << ','
        << r.partition.fallback_steps << ',' << r.partition.rebalanced_steps << ','
        << csv_number(s ? s->over_metis() : std::nullopt) << ','
        << csv_number(s ? s->over_metis_relabel() : std::nullopt) << ','
        << csv_number(r.migration_cost) << ',' << (r.pareto_makespan ? 1 : 0) << ','
        << (r.pareto_cut ? 1 : 0) << '\n';
  }
  return csv.str();
}

std::string comparison_table(const Comparison& c) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "%-14s %4s %12s %10s %12s %9s %9s %9s %14s %8s %8s\n", "method",
                "k", "partition_ms", "cut_edges", "cut_bytes", "signals", "imbalance", "migrated",
                "makespan_ms", "speedup", "bound");
  out += line;
  for (const CompareRow& r : c.rows) {
    const StepReport& t = r.report.total;
    const double bound = t.lower_bound_ns == 0 ? 1.0
                                               : static_cast<double>(t.work_ns) /
                                                     static_cast<double>(t.lower_bound_ns);
    std::snprintf(
        line, sizeof line, "%-14s %4u %12.3f %10llu %12llu %9llu %9.3f %9llu %14.3f %8.2f %8.2f\n",
        row_label(r).c_str(), r.k, t.partition_ms, static_cast<unsigned long long>(t.cut_edges),
        static_cast<unsigned long long>(t.cut_bytes), static_cast<unsigned long long>(t.signals),
        t.imbalance, static_cast<unsigned long long>(t.migrated_tasks),
        static_cast<double>(t.makespan_ns) / 1e6, t.speedup, bound);
    out += line;
  }
  for (const CompareRow& r : c.rows) {
    if (r.method != "sticky") continue;
    std::snprintf(
        line, sizeof line, "%s k=%u: %llu steps reused, %llu fallback (%s), %llu rebalanced",
        row_label(r).c_str(), r.k, static_cast<unsigned long long>(r.partition.reused_steps),
        static_cast<unsigned long long>(r.partition.fallback_steps),
        r.migration_cost                                   ? "repartition"
        : c.sticky_fallback == StickyFallback::kFresh ? "fresh + relabel"
                                                       : std::string(to_string(c.sticky_fallback)).c_str(),
        static_cast<unsigned long long>(r.partition.rebalanced_steps));
    out += line;
    if (const StickyMoves* s = r.migration_cost ? nullptr : sticky_moves_at(c, r.k)) {
      out += "; moved tasks ";
      out += std::to_string(s->sticky);
      auto against = [&](const char* name, const std::optional<std::uint64_t>& base,
                         const std::optional<double>& q) {
        if (!base) return;
        if (q)
          std::snprintf(line, sizeof line, ", %.3f x %s (%llu)", *q, name,
                        static_cast<unsigned long long>(*base));
        else
          std::snprintf(line, sizeof line, ", %s moved %llu", name,
                        static_cast<unsigned long long>(*base));
        out += line;
      };
      against("metis", s->metis, s->over_metis());
      against("metis-relabel", s->metis_relabel, s->over_metis_relabel());
    }
    out += '\n';
  }
  // Pareto points per K, when the grid compares several methods or costs.
  for (std::size_t i = 0; i < c.rows.size(); ++i) {
    bool first = true;
    std::size_t at_k = 0;
    for (std::size_t j = 0; j < c.rows.size(); ++j) {
      if (c.rows[j].k != c.rows[i].k) continue;
      first = first && j >= i;
      ++at_k;
    }
    if (!first || at_k < 2) continue;
    for (const bool by_makespan : {true, false}) {
      out += "pareto k=" + std::to_string(c.rows[i].k) + ", moved tasks vs " +
             (by_makespan ? "predicted makespan:" : "cut bytes:");
      for (const CompareRow& r : c.rows) {
        if (r.k != c.rows[i].k || !(by_makespan ? r.pareto_makespan : r.pareto_cut)) continue;
        if (by_makespan)
          std::snprintf(line, sizeof line, " %s (%llu, %.3f ms)", row_label(r).c_str(),
                        static_cast<unsigned long long>(r.partition.moved_tasks),
                        static_cast<double>(r.report.total.makespan_ns) / 1e6);
        else
          std::snprintf(line, sizeof line, " %s (%llu, %llu)", row_label(r).c_str(),
                        static_cast<unsigned long long>(r.partition.moved_tasks),
                        static_cast<unsigned long long>(r.report.total.cut_bytes));
        out += line;
      }
      out += '\n';
    }
  }
  return out;
}

}  // namespace tgraph::partition
