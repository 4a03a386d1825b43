// SPDX-License-Identifier: MIT
// Offline evaluation of the assignments of a trace.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/model/cost_model.hpp"

namespace tgraph::partition {

/// Evaluation of one step's assignment.
struct StepReport {
  std::uint64_t tasks = 0;
  std::uint64_t cut_edges = 0;        ///< dependencies (intra + loop-carried) between processors
  std::uint64_t cut_bytes = 0;        ///< their datum bytes
  std::uint64_t signals = 0;          ///< simulated signals (per execution)
  std::uint64_t waits = 0;            ///< simulated waits (per execution)
  std::uint64_t reducers = 0;         ///< CW groups whose writers span processors (per execution)
  std::uint64_t transfer_bytes = 0;   ///< bytes read across processors (per execution)
  double imbalance = 1.0;             ///< max load / mean load
  std::uint64_t max_load_ns = 0;
  std::uint64_t work_ns = 0;
  std::uint64_t span_ns = 0;
  std::uint64_t host_ns = 0;          ///< serial engine time outside the tasks (StepGraph::host_ns)
  std::uint64_t lower_bound_ns = 0;   ///< host + max(ceil(work / K), span)
  std::uint64_t makespan_ns = 0;      ///< predicted by simulate() (host time included)
  double speedup = 1.0;               ///< (work + host) / makespan
  std::uint64_t migrated_tasks = 0;   ///< tasks (by stable key) whose processor changed
  std::uint64_t migrated_bytes = 0;   ///< bytes of the data those tasks access
  double partition_ms = 0.0;
  bool quotient_acyclic = true;       ///< processor graph of intra-step cross edges acyclic
  std::uint64_t ping_pong_pairs = 0;  ///< processor pairs with cross edges both ways
  // The same under robust costs (each task's cost the median of its stable key's over the
  // steps of its structure, graph::robust_costs: what one interrupted task cannot bend).
  std::uint64_t robust_work_ns = 0;
  std::uint64_t robust_max_load_ns = 0;
  double robust_imbalance = 1.0;
  std::uint64_t robust_makespan_ns = 0;  ///< predicted by simulate() (host time included)
  double robust_speedup = 1.0;           ///< (robust work + host) / robust makespan
};

/// Evaluation of a whole trace's assignment.
struct Report {
  std::string method;
  std::uint32_t k = 1;
  std::string model;                  ///< cost model source
  std::vector<StepReport> steps;
  StepReport total;  ///< sums; imbalance = sum max load / sum mean load; speedup = (work + host) / makespan
  double imbalance_max = 1.0;         ///< worst step
  std::uint64_t cyclic_steps = 0;     ///< steps whose quotient graph has a cycle
  double speedup_with_partitioning = 1.0;  ///< (work + host) / (makespan + partition time)
  std::vector<std::string> model_terms;    ///< what the prediction charged (model_terms())
};

/// Evaluates `a` on `trace`; throws InputError (naming `a_name`) when the assignment does
/// not fit the trace (step count, task count, processor range, order). `serial_ns` (when
/// not null): the main thread's serial work per step that the simulation charges instead
/// of the host time (simulate()).
Report evaluate(const Trace& trace, const TraceAssignment& a, const model::CostModel& model,
                const std::string& a_name = "<assignment>",
                const std::vector<std::uint64_t>* serial_ns = nullptr);

/// The evaluation of the assignment file `assignment` of the trace file `trace` under `model`,
/// charging `serial`'s work per step (none: the trace's host time): report_json and a newline
/// when `json`, else report_text. InputError for the files, OptionError for `serial`.
std::string evaluate_files(const std::string& trace, const std::string& assignment,
                           const model::CostModel& model, const model::SerialWork& serial,
                           bool json);

/// The JSON of an evaluation: the totals' keys, method, k, model, steps, imbalance_max,
/// cyclic_steps, predicted_speedup_with_partitioning and (when `per_step`) one object per step.
std::string report_json(const Report& report, bool per_step = true);

/// An evaluation's text: method, k, cut, synchronisation, balance, migrations, predicted
/// makespan and the quotient graph, five lines.
std::string report_text(const Report& report);

/// The quotient graph of step `g` under `a` (quotient_graph) with the signals between
/// processors counted by simulate(): which versions cross does not depend on the cost model
/// or on timing. Throws tgraph::Error when `a` does not fit `g`.
QuotientGraph step_quotient(const StepGraph& g, const Assignment& a);

/// What no partition of a step over `k` processors beats (StepReport::lower_bound_ns): its
/// host work, then max(ceil(work / k), span).
constexpr std::uint64_t step_lower_bound_ns(std::uint64_t host_ns, std::uint64_t work_ns,
                                            std::uint64_t span_ns, std::uint32_t k) {
  return host_ns + std::max<std::uint64_t>((work_ns + k - 1) / k, span_ns);
}

/// Checks that `a` fits `trace`; throws InputError naming `a_name` otherwise.
void check_fits(const Trace& trace, const TraceAssignment& a, const std::string& a_name);

}  // namespace tgraph::partition
