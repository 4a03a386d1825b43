// SPDX-License-Identifier: MIT
// What `tgraph info` reports about a trace: size, work, span and shape, per step and in total.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "tgraph/graph/trace.hpp"

namespace tgraph {

/// One step's line of the summary.
struct StepSummary {
  std::uint64_t tasks = 0;
  std::uint64_t edges = 0;  ///< intra-step + loop-carried
  std::uint64_t edges_carried = 0;  ///< of which loop-carried (iteration i to i + 1)
  std::uint64_t data = 0;
  std::uint64_t loops = 0;
  std::vector<std::uint32_t> loop_iterations;  ///< per loop
  std::uint64_t work_ns = 0;
  std::uint64_t span_ns = 0;
  std::uint64_t work_tasks = 0;  ///< unit costs (compute_unit_metrics), when summarised with them
  std::uint64_t span_tasks = 0;  ///< unit costs: hop count of the critical path
  std::uint64_t host_ns = 0;  ///< StepGraph::host_ns: serial engine time outside the tasks
  double parallelism = 0.0;
  /// The same with robust costs (robust_costs: each task's median over its structure's steps).
  std::uint64_t robust_work_ns = 0;
  std::uint64_t robust_span_ns = 0;
  double robust_parallelism = 0.0;
  std::uint64_t contacts = 0;
  std::uint64_t collision_groups = 0;  ///< distinct group ids (1 when none are recorded)
  bool contacts_changed = false;       ///< contact set differs from the previous step's
  std::uint64_t structure = 0;         ///< StepGraph::structural_hash
  bool structure_changed = false;      ///< structure differs from the previous step's
  std::string change;  ///< when it does: step_diff_summary of the previous step -> this one
};

/// The whole trace.
struct TraceSummary {
  TraceHeader header;
  std::uint64_t steps = 0;
  std::uint64_t tasks = 0;  ///< over all steps
  std::uint64_t tasks_min = 0, tasks_max = 0;
  double tasks_mean = 0.0;
  std::uint64_t edges = 0;          ///< intra-step + loop-carried, all steps
  std::uint64_t edges_carried = 0;  ///< of which loop-carried
  std::uint64_t data_max = 0;  ///< data of the largest step
  std::uint64_t loops = 0;
  std::uint64_t loop_iterations = 0;
  std::uint32_t max_loop_iterations = 0;  ///< in one loop of one step
  std::uint64_t work_ns = 0;
  std::uint64_t span_ns = 0;  ///< sum of the steps' spans
  std::uint64_t span_max_ns = 0;  ///< the longest step's span
  bool unit_cost = false;     ///< the *_tasks figures were computed
  std::uint64_t work_tasks = 0;     ///< unit costs: task runs over all steps
  std::uint64_t span_tasks = 0;     ///< unit costs: sum of the steps' spans in tasks
  std::uint64_t span_tasks_max = 0;  ///< unit costs: the longest step's span in tasks
  double unit_parallelism = 0.0;     ///< unit costs: work_tasks / span_tasks
  std::uint64_t host_ns = 0;  ///< sum of the steps' host times (outside the tasks)
  double parallelism = 0.0;   ///< work / span (0 when the span is 0)
  /// work, span and parallelism with robust costs (robust_costs), which one interrupted
  /// task of the capture does not bend.
  std::uint64_t robust_work_ns = 0;
  std::uint64_t robust_span_ns = 0;
  std::uint64_t robust_span_max_ns = 0;
  double robust_parallelism = 0.0;
  std::uint64_t distinct_structures = 0;
  std::uint64_t contact_changes = 0;
  std::uint64_t last_step_collision_groups = 0;
  std::vector<StepSummary> per_step;
};

/// What summarize_trace computes beyond the timed figures.
struct SummaryOptions {
  /// Also the unit-cost work and span (compute_unit_metrics), in tasks. Always on for a
  /// trace without costs (all zero), whose timed span says nothing.
  bool unit_cost = false;
};

/// Computes the summary (compute_metrics on every step; edges must be derived).
///
///   TraceSummary s = summarize_trace(read_trace("b.tgt"));
///   std::cout << trace_summary_text(s, "b.tgt");
TraceSummary summarize_trace(const Trace& trace, const SummaryOptions& options = {});

/// The JSON of `tgraph info`: one object (header, totals, "per_step" array).
std::string trace_summary_json(const TraceSummary& s, const std::string& trace_name);
/// `tgraph info`'s text: one "name   value" line per figure, then one line per step whose
/// structure changed.
std::string trace_summary_text(const TraceSummary& s, const std::string& trace_name);

}  // namespace tgraph
