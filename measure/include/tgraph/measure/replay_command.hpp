// SPDX-License-Identifier: MIT
// `tgraph replay` as one call: a trace file, its assignment (loaded or partitioned), the
// prediction beside the measure, the report to print and the timeline to write.
#pragma once

#include <optional>
#include <string>

#include "tgraph/graph/timeline.hpp"
#include "tgraph/measure/replay_trace.hpp"
#include "tgraph/partition/strategy.hpp"

namespace tgraph::measure {

/// What `tgraph replay` replays and how it reports.
struct ReplayCommand {
  std::string trace;       ///< the .tgt file
  std::string assignment;  ///< a .tga file (partition policy; empty: partitioned with `method`)
  std::string method;      ///< the strategy without a file (empty: the trace's default)
  partition::NamedOptions model;  ///< the prediction's cost model
  ReplayOptions replay;
  bool timeline = false;  ///< record the observed pass's timeline
  bool json = false;      ///< report as one JSON line (else text)
};

/// The replay, its report and its timeline.
struct ReplayReport {
  ReplayResult result;  ///< result.warnings: what the partitioner warned of
  std::string report;   ///< the JSON line or the text, ready to print
  std::optional<Timeline> timeline;  ///< when ReplayCommand::timeline
};

/// Reads the trace, loads or computes the assignment (partition policy), predicts each step
/// and replays (replay_trace). OptionError for an assignment under another policy and for
/// the options replay_trace refuses; InputError for the files.
ReplayReport replay_command(const ReplayCommand& command);

}  // namespace tgraph::measure
