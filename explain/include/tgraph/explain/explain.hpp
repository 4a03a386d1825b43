// SPDX-License-Identifier: MIT
// Where the time of a step went: its executed critical path, its lost processor time split
// into named causes that add up to it, and what-ifs (virtual speed-ups, after Coz) through
// the built-in simulator or on the executed schedule. Works on a tgraph::Timeline that carries its steps' graphs
// (replay::TimelineObserver records them; docs/explain.md defines every figure).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tgraph/graph/timeline.hpp"

namespace tgraph::explain {

/// The causes of lost processor time, in ns (docs/explain.md, "Causes"). Their sum is
/// Attribution::lost_ns.
struct Causes {
  std::int64_t serial = 0;           ///< threads x the calling thread's serial phases - host work
  std::int64_t imbalance = 0;        ///< the assignment's heaviest thread beyond what K allows
  std::int64_t dependency_wait = 0;  ///< waiting for a writer on another thread, beyond the rest
  std::int64_t handoff = 0;          ///< from the writer's end to the waiter running (spin, park)
  std::int64_t interruption = 0;     ///< bodies' wall time beyond their thread's CPU time
  std::int64_t inflation = 0;        ///< bodies' CPU time beyond their sequential cost
  std::int64_t runtime = 0;          ///< reducers, and ready tasks not yet started (plans, steals)
  std::int64_t starvation = 0;       ///< idle for lack of ready work: the graph's span
  std::int64_t residual = 0;         ///< what the timeline does not account for
  /// The sum of the nine.
  std::int64_t sum() const;
  Causes& operator+=(const Causes& o);
};

/// The names of the causes, in the order of the struct ("serial", ..., "residual").
const std::vector<std::string_view>& cause_names();
/// The cause called `name` (one of cause_names()).
std::int64_t& cause(Causes& c, std::string_view name);
/// The same, read only.
std::int64_t cause(const Causes& c, std::string_view name);

/// Lost processor time of a step or a run: threads x makespan - sequential work, and its causes.
struct Attribution {
  std::int64_t lost_ns = 0;
  Causes causes;
  Attribution& operator+=(const Attribution& o);
};

/// How a link of the critical path spends its time.
enum class Link : unsigned char {
  kBody = 0,     ///< a task body
  kWait = 1,     ///< the path waits on its own thread (the runtime between two tasks, a join)
  kHandoff = 2,  ///< from a writer's end on one thread to its reader's start on another
  kSerial = 3,   ///< the calling thread's serial phases before the execution
};
/// "body", "wait", "handoff" or "serial".
std::string_view to_string(Link link);

/// One link of the executed critical path; times from the step's start (serial phases
/// included).
struct PathLink {
  std::optional<TaskId> task;  ///< executed task (the body, or the task waited into)
  std::string kind;            ///< its kind ("" for none)
  std::uint32_t thread = 0;
  std::uint32_t iteration = 0;
  std::int64_t start_ns = 0;
  std::int64_t end_ns = 0;
  Link link = Link::kBody;
};

/// A writer other threads waited for (a dependency wait, named).
struct LateWriter {
  TaskId task = 0;        ///< executed task of the writer
  std::string kind;
  std::string datum;      ///< the datum its reader waited for
  std::int64_t wait_ns = 0;   ///< readers' time waiting for it, data not ready
  std::int64_t late_ns = 0;   ///< how long after its own inputs were ready it started
};

/// One virtual speed-up: the step's (or run's) time if `target` changed as `change` says.
struct WhatIf {
  std::string target;  ///< a kind's or an object's name, or a cause ("handoff", "parks", ...)
  std::string change;  ///< "10% faster", "50% faster", "free", ...
  std::int64_t predicted_ns = 0;
  std::int64_t gain = 0;  ///< makespan - predicted_ns
  /// What predicted it: "simulator" (tgraph::model::simulate on the step's executed graph)
  /// or "executed_schedule" (the schedule as it ran, re-timed); docs/explain.md.
  std::string model;
  std::string scope;  ///< what target names: "kind", "object" or "cause"
};

/// The explanation of one step.
struct StepExplanation {
  std::uint32_t step = 0;
  std::uint32_t threads = 0;
  std::int64_t makespan_ns = 0;  ///< serial phases + execution
  std::int64_t serial_ns = 0;
  std::int64_t work_ns = 0;      ///< sequential work: the instances' costs + host work
  std::int64_t span_ns = 0;      ///< the graph's critical path at sequential costs
  std::uint64_t instances = 0;
  std::uint64_t unobserved = 0;  ///< instances the loops' iterations imply but the timeline lacks
  Attribution attribution;
  /// The makespan along the critical path: "work" (sequential cost of its bodies), and
  /// serial, inflation, interruption, handoff, runtime; adds up to makespan_ns.
  std::vector<std::pair<std::string, std::int64_t>> makespan_split;
  std::vector<PathLink> critical_path;  ///< chronological
  std::vector<LateWriter> late_writers;  ///< the largest first (at most 5)
  std::vector<WhatIf> what_if;          ///< the largest gain first
  /// The built-in simulator's makespan of the step unchanged, what its what-ifs are scaled
  /// against (0: not simulated: no what-ifs asked, or a step the simulator cannot run);
  /// beyond ExplainOptions::simulator_fit of makespan_ns, the what-ifs are re-timed.
  std::int64_t simulated_ns = 0;
};

/// A whole timeline's explanation.
struct Explanation {
  std::uint32_t threads = 0;
  std::vector<StepExplanation> steps;
  Attribution attribution;  ///< the steps' sum
  std::vector<WhatIf> what_if;  ///< summed over the steps, the largest gain first
};

/// What to compute.
struct ExplainOptions {
  bool what_ifs = true;
  /// A step's what-ifs come from the built-in simulator when its simulated makespan
  /// unchanged is within this fraction of the observed one (|simulated / observed - 1|),
  /// else from the executed schedule (docs/explain.md).
  double simulator_fit = 0.25;
  /// Only this step (by number); nullopt: every step with a graph.
  std::optional<std::uint32_t> step;
};

/// Explains every step of `t` that has a graph (Timeline::step_info); InputError naming
/// `name` when none has (a timeline written before graphs were recorded) or `options.step`
/// is not one of them.
///
///   const Explanation e = explain_timeline(read_timeline("r.json"), "r.json");
///   std::cout << explanation_text(e);
Explanation explain_timeline(const Timeline& t, const std::string& name,
                             const ExplainOptions& options = {});

/// Sets the sequential cost of every task of `t` whose kind is in `mean_ns_by_kind` to that
/// mean (a live run's per-kind means in its observed sequential pass: its graphs' own costs
/// were measured in parallel, inflation included); other tasks keep theirs.
void set_kind_costs(Timeline& t, const std::vector<std::pair<std::string, double>>& mean_ns_by_kind);

/// The attribution as JSON: {"lost_ns", "causes": {serial, ..., residual}}.
std::string attribution_json(const Attribution& a);
/// `tgraph explain --json`: {"threads", "attribution", "what_if", "steps": [{step,
/// makespan_ns, work_ns, span_ns, attribution, makespan_split, critical_path: [{task, kind,
/// thread, start_ns, end_ns, link}], late_writers, what_if: [{target, change,
/// predicted_ns, gain, model, scope}], simulated_ns}]}.
std::string explanation_json(const Explanation& e);
/// `tgraph explain`'s table: one line per step (causes in % of the lost time), then the
/// run's causes and its what-ifs; with one step, its critical path and late writers too.
std::string explanation_text(const Explanation& e, const std::string& name);

}  // namespace tgraph::explain
