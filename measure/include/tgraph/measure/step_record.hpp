// SPDX-License-Identifier: MIT
// The per-step record every measurement shares (a replayed step, a live step).
#pragma once

#include <cstdint>
#include <vector>

#include <optional>

#include "tgraph/explain/explain.hpp"
#include "tgraph/replay/observer.hpp"

namespace tgraph::measure {

/// One step of a measured run: its wall time (median over the timed passes), the plan
/// build of the first pass, and the threads of the observed pass. Written to JSON once
/// (report.hpp) for replays and live runs alike.
struct StepRecord {
  std::int64_t wall_ns = 0;   ///< median over the timed passes
  std::int64_t build_ns = 0;  ///< lowering and plan build in the first pass (0: reused)
  /// The plan part of build_ns (per-processor programs, without lowering), first pass.
  std::int64_t rebuild_ns = 0;
  std::uint32_t rebuilt_procs = 0;  ///< processors whose program was (re)built, first pass
  std::vector<replay::StatsObserver::Thread> threads;  ///< from the observed pass
  /// The observed pass's lost time by cause (explain::explain_timeline; docs/explain.md).
  std::optional<explain::Attribution> attribution;
};

}  // namespace tgraph::measure
