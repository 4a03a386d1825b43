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
  /// Start of each step on the common time axis (step s begins where step s-1's last
  /// task or wait ended), indexed by step number; size = highest step + 1.
  std::vector<std::int64_t> step_offsets() const;
};

/// The timeline as JSON: {"threads", "steps", "tasks": [{step, thread, task, origin, kind,
/// iteration, start_ns, end_ns}], "waits": [{step, thread, task, start_ns, end_ns, parked}]}
/// (origin and a wait's task null when empty).
std::string timeline_json(const Timeline& t);
/// Parses timeline_json text; throws InputError naming `name` and what is wrong (not JSON,
/// missing field, thread out of range, end before start, times that overflow).
Timeline parse_timeline(std::string_view json, const std::string& name);
/// parse_timeline of the file at `path` (InputError naming it when unreadable or malformed).
Timeline read_timeline(const std::string& path);

}  // namespace tgraph
