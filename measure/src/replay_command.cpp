// SPDX-License-Identifier: MIT
// `tgraph replay`: the assignment (a file, or the steps partitioned), the prediction, the
// replay and its report.
#include "tgraph/measure/replay_command.hpp"

#include <cstdint>
#include <vector>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/measure/report.hpp"
#include "tgraph/model/simulator.hpp"
#include "tgraph/partition/assignment_io.hpp"

namespace tgraph::measure {

ReplayReport replay_command(const ReplayCommand& c) {
  const Trace trace = read_trace(c.trace);
  std::optional<TraceAssignment> as;
  std::vector<std::uint64_t> predicted;
  partition::PartitionNotes notes;
  if (c.replay.policy == replay::Policy::kPartition) {
    as = partition::load_or_partition(trace, c.trace, c.assignment, c.method, c.replay.exec.threads,
                                      &notes);
    predicted = model::predicted_makespans(trace, *as, c.model.cost_model());
  } else if (!c.assignment.empty()) {
    throw OptionError("policy", "an assignment file is only used by {policy} partition");
  }
  replay::TimelineObserver timeline;
  timeline.set_cpu_time(true);  // asked for: interruptions told apart (docs/explain.md)
  ReplayReport r;
  r.result = replay_trace(trace, as ? &*as : nullptr, c.replay, as ? &predicted : nullptr,
                          c.timeline ? &timeline : nullptr);
  r.result.warnings = notes.warnings;
  if (c.timeline) r.timeline = timeline.timeline();
  const std::string label =
      as ? partition::assignment_label(c.assignment, c.method, notes) : c.assignment;
  r.report = c.json ? to_json(r.result, c.trace, label) + "\n"
                    : to_text(r.result, c.trace, c.replay.repeat);
  return r;
}

}  // namespace tgraph::measure
