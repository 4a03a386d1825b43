// SPDX-License-Identifier: MIT
// The structural difference of two steps, by stable task key and object name (`tgraph diff`).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/step_graph.hpp"
#include "tgraph/graph/trace.hpp"

namespace tgraph {

/// Tasks of `g` matched in `prev` by stable key: the i-th task of `g` with a key matches the
/// i-th task of `prev` with the same key; match[t] = task of `prev`, or kNoTask.
std::vector<TaskId> match_tasks_by_key(const StepGraph& g, const StepGraph& prev);

/// A task named across steps.
struct TaskRef {
  TaskId id = 0;  ///< index in its own step
  StableKey key = 0;
  std::string kind;
  std::string object;  ///< object name, empty for none
  /// Added or removed contacts (as "a|b") whose two objects' data the task touches.
  std::vector<std::string> caused_by;
};

/// A dependency named across steps: its two tasks (by key), the datum (by name), its kind.
struct EdgeRef {
  StableKey from = 0, to = 0;
  std::string datum;
  EdgeKind kind = EdgeKind::RAW;
  bool carried = false;  ///< loop-carried edge
};

/// Collision groups that became one (`from` has several groups, `into` one) or one group
/// that became several (`from` one, `into` several), by object names; `contacts` are the
/// added (merge) or removed (split) contacts between objects of different groups.
struct GroupChange {
  std::vector<std::vector<std::string>> from;
  std::vector<std::vector<std::string>> into;
  std::vector<std::string> contacts;
};

/// A matched task whose processor changed between two assignments.
struct ProcessorChange {
  TaskRef task;  ///< in the second step
  ProcId from = 0, to = 0;
};

/// The difference from step A (`before`) to step B (`after`).
struct StepDiff {
  bool same_structure = false;  ///< StepGraph::same_structure
  std::uint64_t matched_tasks = 0;
  std::vector<TaskRef> tasks_added;    ///< in B, not matched in A
  std::vector<TaskRef> tasks_removed;  ///< in A, not matched in B
  std::vector<EdgeRef> edges_added;    ///< between tasks of B, absent from A
  std::vector<EdgeRef> edges_removed;
  std::vector<std::string> contacts_added;  ///< "a|b" by object names
  std::vector<std::string> contacts_removed;
  std::vector<GroupChange> groups_merged;
  std::vector<GroupChange> groups_split;
  std::uint64_t loops_before = 0, loops_after = 0;
  std::vector<ProcessorChange> processor_changes;  ///< filled by add_processor_changes
};

/// Diffs two steps (edges derived). Tasks match by stable key (match_tasks_by_key), edges by
/// their tasks' keys, datum name and kind, contacts and groups by object names: ids may differ
/// between steps.
///
///   StepDiff d = diff_steps(trace.steps[42], trace.steps[43]);
///   std::cout << step_diff_summary(d) << "\n";
StepDiff diff_steps(const StepGraph& before, const StepGraph& after);

/// Fills `d.processor_changes`: matched tasks whose processor differs between `a_before`
/// (an assignment of `before`) and `a_after` (of `after`). The assignments must fit.
void add_processor_changes(StepDiff& d, const StepGraph& before, const Assignment& a_before,
                           const StepGraph& after, const Assignment& a_after);

/// Steps `a` and `b` of `trace` diffed (step_at, naming the field `steps` and `trace_name`),
/// with the processor changes of `assignment` (it fits `trace`) when it is not null.
StepDiff diff_trace_steps(const Trace& trace, const std::string& trace_name, std::size_t a,
                          std::size_t b, const TraceAssignment* assignment);

/// One line: "+3/-4 tasks, +12/-9 edges, contacts +mattress|box, groups merged:
/// {box} + {mattress, ...}" ("no structural change" when there is none).
std::string step_diff_summary(const StepDiff& d);
/// The diff as one JSON object (steps `a` and `b` named in it).
std::string step_diff_json(const StepDiff& d, std::size_t a, std::size_t b);
/// The diff as text: the summary, then one line per task, contact, group change and
/// processor change (edges counted, not listed).
std::string step_diff_text(const StepDiff& d, std::size_t a, std::size_t b);

}  // namespace tgraph
