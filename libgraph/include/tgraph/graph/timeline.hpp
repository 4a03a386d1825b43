// SPDX-License-Identifier: MIT
// The timeline of an execution: which thread ran each task instance when, and where threads
// waited. One model: replay's TimelineObserver records it, viz draws it and converts it to
// Chrome trace events, `tgraph replay` writes it as JSON when asked for a timeline and `tgraph timeline`
// reads it back.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "tgraph/graph/step_graph.hpp"

namespace tgraph {

/// One task instance (times from the start of its step).
struct TimelineTask {
  std::uint32_t step = 0;
  std::uint32_t thread = 0;
  TaskId task = 0;                ///< executed task (reducers included)
  std::optional<TaskId> origin;   ///< task of the step graph (empty: a reducer)
  std::string kind;               ///< kind name of the executed task
  std::uint32_t iteration = 0;
  std::int64_t start_ns = 0;
  std::int64_t end_ns = 0;
  /// CPU time the thread spent in the body (CLOCK_THREAD_CPUTIME_ID); -1: not measured.
  /// end_ns - start_ns minus it is the time the OS took the core during the body.
  std::int64_t cpu_ns = -1;
};

/// One blocking wait.
struct TimelineWait {
  std::uint32_t step = 0;
  std::uint32_t thread = 0;
  std::optional<TaskId> task;  ///< the task that waited
  std::int64_t start_ns = 0;
  std::int64_t end_ns = 0;
  bool parked = false;  ///< slept in the kernel
};

/// The executed graph of some steps (the lowered graph an executor ran, reducers included):
/// what each task instance of the timeline depended on, for explanations (tgraph::explain).
/// Steps of one structure share one graph.
struct TimelineGraph {
  std::vector<std::string> kinds;    ///< kind names
  std::vector<std::string> data;     ///< datum names (edges name them)
  std::vector<KindId> task_kind;     ///< per executed task: index into kinds
  std::vector<TaskId> origin;        ///< per executed task: task of the step graph (kNoTask: reducer)
  std::vector<LoopId> task_loop;     ///< per executed task: its loop, or kNoLoop
  std::vector<std::pair<TaskId, TaskId>> loops;  ///< body [first, last); the last is the break
  std::vector<Edge> edges;           ///< intra-step (within one iteration in a loop body)
  std::vector<Edge> carried_edges;   ///< from iteration i to i + 1 of the same loop
  std::vector<std::string> objects;  ///< object names (empty: not recorded)
  /// Per executed task: index into objects, or kNoObject (a reducer, shared work); empty:
  /// not recorded (timelines written before it).
  std::vector<ObjectId> task_object;
  friend bool operator==(const TimelineGraph&, const TimelineGraph&) = default;
};

/// What a timeline knows about one step beyond its events: its executed graph, each task's
/// sequential cost, the loops' iterations, the execution's wall time and the serial phases
/// of the calling thread before it (a live run's recording, partitioning and preparation).
struct TimelineStep {
  std::uint32_t step = 0;
  std::uint32_t graph = 0;       ///< index into Timeline::graphs
  std::int64_t wall_ns = 0;      ///< execution: from the first task's release to the last's join
  std::int64_t record_ns = 0;    ///< serial phases before the execution (calling thread)
  std::int64_t partition_ns = 0;
  std::int64_t prepare_ns = 0;
  /// The part of the serial phases the sequential program runs too (the engine's host work):
  /// sequential work, not lost time.
  std::int64_t host_ns = 0;
  std::vector<std::uint32_t> iterations;  ///< per loop of the graph
  /// Per executed task, the sequential cost of one execution (reducers: 0, the sequential
  /// program has none).
  std::vector<std::int64_t> cost_ns;
  /// The serial phases in all.
  std::int64_t serial_ns() const { return record_ns + partition_ns + prepare_ns; }
};

/// A timeline; steps are laid end to end by step_offsets().
///
///   replay::TimelineObserver observer;          // records a Timeline
///   executor->add_observer(observer);
///   ...
///   write_file_atomic("r.json", timeline_json(observer.timeline()));
///   const Timeline t = read_timeline("r.json");  // the same Timeline back
struct Timeline {
  std::uint32_t threads = 0;
  std::uint32_t steps = 0;  ///< steps observed (recorded or not); at least highest step + 1
  std::vector<TimelineTask> tasks;  ///< step by step, by start time within a step
  std::vector<TimelineWait> waits;
  std::vector<TimelineGraph> graphs;      ///< executed graphs (empty: not recorded)
  std::vector<TimelineStep> step_info;    ///< per recorded step with a graph, by step number
  /// The step_info entry of step `step`, or nullptr.
  const TimelineStep* info(std::uint32_t step) const;
  /// Start of each step on the common time axis (step s begins where step s-1's last
  /// task or wait ended), indexed by step number; size = highest step + 1.
  std::vector<std::int64_t> step_offsets() const;
};

/// The timeline as JSON, one object per event: {"threads", "steps", "tasks": [{step, thread,
/// task, origin, kind, iteration, start_ns, end_ns[, cpu_ns]}], "waits": [{step, thread,
/// task, start_ns, end_ns, parked}]} (origin and a wait's task null when empty), and when
/// recorded "graphs" and "step_info" as compact_timeline_json writes them.
std::string timeline_json(const Timeline& t);
/// The same in columns (docs/trace-format.md, "Timelines"), what write_timeline writes:
/// {"format": "tgraph-timeline", "version": 2, "threads", "steps", "kinds" (the kind names
/// once), "tasks": {step, thread, task, origin, kind, iteration, start_ns, duration_ns[,
/// cpu_ns]} (arrays, one entry per instance; start_ns as the difference from the previous
/// instance of the same step; origin -1 for none), "waits": {step, thread, task, start_ns,
/// duration_ns, parked}, "graphs", "step_info"}.
std::string compact_timeline_json(const Timeline& t);
/// Parses timeline_json or compact_timeline_json text, gzip-compressed or not; throws InputError naming `name` and what is wrong (not JSON, missing
/// field, thread out of range, end before start, times that overflow, an index out of range).
Timeline parse_timeline(std::string_view json, const std::string& name);
/// parse_timeline of the file at `path` (InputError naming it when unreadable or malformed).
Timeline read_timeline(const std::string& path);
/// Writes compact_timeline_json(t) to `path`, gzip-compressed (what read_timeline reads back; zcat
/// shows the JSON), all or nothing (write_file_atomic).
void write_timeline(const std::string& path, const Timeline& t);

}  // namespace tgraph
