// SPDX-License-Identifier: MIT
#include "tgraph/experiment/results.hpp"

#include <cmath>
#include <cstdio>

#include "tgraph/graph/error.hpp"

namespace tgraph::experiment {
namespace {

std::string join_row(const std::vector<std::string>& cells) {
  std::string s;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    if (i) s += ',';
    s += csv_cell(cells[i]);
  }
  return s + "\n";
}

std::string opt(const std::optional<double>& v) { return v ? number_text(*v) : std::string(); }

}  // namespace

std::string csv_cell(std::string_view text) {
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(text);
  std::string s = "\"";
  for (char c : text) {
    if (c == '"') s += '"';
    s += c;
  }
  return s + "\"";
}

std::string number_text(double v) {
  if (!std::isfinite(v)) return {};
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::vector<std::string> result_columns() {
  return {"experiment",
          "scene",
          "subobjects",
          "method",
          "policy",
          "threads",
          "threads_kind",
          "measured_live_ms_per_step",
          "measured_engine_ms_per_step",
          "measured_live_speedup",
          "measured_integration_speedup",
          "measured_step_speedup",
          "measured_core_bound",
          "measured_record_ms_per_step",
          "measured_graph_update_ms_per_step",
          "measured_partition_ms_per_step",
          "measured_build_ms_per_step",
          "measured_plans_built",
          "measured_structure_changes",
          "measured_signals",
          "measured_replay_ms_per_step",
          "measured_replay_sequential_ms_per_step",
          "measured_replay_speedup",
          "predicted_speedup",
          "predicted_integration_speedup",
          "predicted_step_speedup",
          "predicted_ms_per_step",
          "predicted_work_ms_per_step",
          "predicted_imbalance",
          "predicted_migrated_tasks",
          "predicted_partition_ms_per_step",
          "failure"};
}

std::string results_csv(const std::vector<ResultRow>& rows, std::uint32_t cores) {
  std::string out = join_row(result_columns());
  for (const ResultRow& r : rows) {
    TGRAPH_ASSERT(!r.measured || r.threads <= cores);
    std::vector<std::string> c = {r.experiment,
                                  r.scene,
                                  r.subobjects ? std::to_string(*r.subobjects) : std::string(),
                                  r.method,
                                  r.policy,
                                  std::to_string(r.threads),
                                  std::string(r.threads_kind(cores))};
    if (r.measured) {
      const Measured& m = *r.measured;
      for (double v : {m.live_ms_per_step, m.engine_ms_per_step, m.live_speedup,
                       m.integration_speedup, m.step_speedup, m.core_bound,
                       m.record_ms_per_step, m.graph_update_ms_per_step, m.partition_ms_per_step,
                       m.build_ms_per_step})
        c.push_back(number_text(v));
      for (std::uint64_t v : {m.plans_built, m.structure_changes, m.signals})
        c.push_back(std::to_string(v));
      c.push_back(opt(m.replay_ms_per_step));
      c.push_back(opt(m.replay_sequential_ms_per_step));
      c.push_back(opt(m.replay_speedup));
    } else {
      c.resize(c.size() + 16);
    }
    if (r.predicted) {
      const Predicted& p = *r.predicted;
      for (double v : {p.speedup, p.integration_speedup, p.step_speedup, p.ms_per_step,
                       p.work_ms_per_step, p.imbalance})
        c.push_back(number_text(v));
      c.push_back(std::to_string(p.migrated_tasks));
      c.push_back(number_text(p.partition_ms_per_step));
    } else {
      c.resize(c.size() + 8);
    }
    c.push_back(r.failure);
    out += join_row(c);
  }
  return out;
}

std::vector<std::string> step_columns() {
  return {"method",       "threads",   "step",       "structure_changed",
          "step_ms",      "engine_ms", "record_ms",  "graph_update_ms",
          "partition_ms", "build_ms",  "execute_ms", "migrated_tasks"};
}

std::string steps_csv(const std::vector<StepRow>& rows) {
  std::string out = join_row(step_columns());
  for (const StepRow& r : rows)
    out += join_row(
        {r.method, std::to_string(r.threads), std::to_string(r.step),
         r.structure_changed ? "1" : "0", number_text(r.step_ms), number_text(r.engine_ms),
         number_text(r.record_ms), number_text(r.graph_update_ms), number_text(r.partition_ms),
         number_text(r.build_ms), number_text(r.execute_ms), std::to_string(r.migrated_tasks)});
  return out;
}

}  // namespace tgraph::experiment
