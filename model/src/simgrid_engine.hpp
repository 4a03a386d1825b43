// SPDX-License-Identifier: MIT
// Between the SimGrid engine (simgrid_engine.cpp: the steps as s4u activities) and the
// process that hosts it (simgrid_process.cpp).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "tgraph/graph/trace.hpp"
#include "tgraph/model/simulation.hpp"

namespace tgraph::model::detail {

/// What one simulation of a trace on the loaded platform gives: per-step predictions, or
/// the reason the platform cannot run the assignment (`input_error`).
struct PlatformRun {
  std::vector<StepPrediction> steps;
  std::uint64_t hosts = 0, cores = 0;
  std::string input_error;
};

/// Maps processors to the platform's cores and simulates every step; the platform must be
/// loaded into this process's SimGrid engine already.
PlatformRun run_on_loaded_platform(const Trace& trace, const TraceAssignment& a,
                                   const SimulatedPlatform& platform);

}  // namespace tgraph::model::detail
