// SPDX-License-Identifier: MIT
// The JSON and text of the three measurements: `tgraph replay`, `tgraph run` and
// `tgraph validate`. Their per-step records share one writer (StepRecord's keys).
#pragma once

#include <cstdint>
#include <string>

#include "tgraph/measure/live.hpp"
#include "tgraph/measure/replay_trace.hpp"
#include "tgraph/measure/validate.hpp"

namespace tgraph::measure {

/// The replay as one JSON object (keys: policy, threads, steps, wall_ns, per_step, speedup,
/// efficiency, signals, wait_ns, remote_bytes, migrated_bytes, predicted_makespan_ns, ...).
std::string to_json(const ReplayResult& r);
/// A replay's JSON report: to_json(r) plus the trace's name and how its assignment was
/// obtained (a .tga path, "<method> (computed)", or "" for the other policies).
std::string to_json(const ReplayResult& r, const std::string& trace_name,
                    const std::string& assignment);
/// A replay's text report of `r`, a replay of `trace_name` with `repeat` passes.
std::string to_text(const ReplayResult& r, const std::string& trace_name, std::uint32_t repeat);

/// The live run as one JSON object (keys as a replay's where they mean the same).
std::string to_json(const LiveResult& r);
/// A scene's live run as JSON: to_json(r) plus the scene and the method (strategy or policy).
std::string to_json(const LiveResult& r, const std::string& scene, const std::string& method);
/// A scene's live run as text: `r`: a run of `scene` with `method` (strategy or policy),
/// `repeat` timed passes; the check line when one was made.
std::string to_text(const LiveResult& r, const std::string& scene, const std::string& method,
                    std::uint32_t repeat);

/// A validation's JSON (ratios replay / live, predicted / live, predicted / replay).
std::string to_json(const Validation& v, const ValidateOptions& options);
/// A validation's text.
std::string to_text(const Validation& v, const ValidateOptions& options);

}  // namespace tgraph::measure
