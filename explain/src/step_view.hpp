// SPDX-License-Identifier: MIT
// One step of a timeline as explain reads it: its instances, each one's predecessors among
// them (the graph unrolled over the loops' iterations), its thread's previous instance.
#pragma once

#include <cstdint>
#include <vector>

#include "tgraph/graph/timeline.hpp"

namespace tgraph::explain::detail {

inline constexpr std::uint32_t kNone = 0xffffffffu;

/// One observed task instance of the step.
struct Instance {
  TaskId task = 0;
  std::uint32_t iteration = 0;
  std::uint32_t thread = 0;
  std::int64_t start = 0, end = 0;
  std::int64_t cpu = -1;
  std::int64_t cost = 0;       ///< sequential cost
  bool reducer = false;        ///< no origin: the runtime's own work
  std::uint32_t prev = kNone;  ///< previous instance on the same thread
  std::uint32_t latest = kNone;  ///< the predecessor instance that ended last
  std::int64_t ready = 0;      ///< its end (0 without predecessors)
  DatumId datum = 0;           ///< the datum of the edge from `latest`
  std::uint32_t pred_begin = 0, pred_end = 0;  ///< into StepView::preds
  /// The part of the body the OS took (wall - CPU time), when the CPU time is known.
  std::int64_t interrupted() const { return cpu < 0 ? 0 : std::max<std::int64_t>(0, end - start - cpu); }
};

/// A recorded blocking wait, clipped to the step.
struct Wait {
  std::uint32_t thread = 0;
  std::int64_t start = 0, end = 0;
  bool parked = false;
};

/// The step: instances sorted by start, per-thread order, predecessors.
struct StepView {
  const TimelineGraph* graph = nullptr;
  const TimelineStep* info = nullptr;
  std::uint32_t threads = 0;
  std::int64_t wall = 0;  ///< the execution window [0, wall]
  std::vector<Instance> instances;
  std::vector<std::uint32_t> preds;  ///< instance indices
  std::vector<std::vector<std::uint32_t>> by_thread;  ///< instance indices in start order
  std::vector<Wait> waits;
  std::uint64_t unobserved = 0;
  std::int64_t span = 0;  ///< critical path at sequential costs, loops unrolled
};

/// Builds the view of step `info` of `t`.
StepView make_view(const Timeline& t, const TimelineStep& info);

}  // namespace tgraph::explain::detail
