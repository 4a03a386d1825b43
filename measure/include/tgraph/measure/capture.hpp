// SPDX-License-Identifier: MIT
// A scene's steps captured into a Trace in memory (what the measurements and the experiments
// replay and partition; `tgraph capture` streams to a file instead: samples::capture_scene).
#pragma once

#include <cstdint>
#include <string>

#include "tgraph/graph/trace.hpp"
#include "tgraph/samples/scene.hpp"

namespace tgraph::measure {

/// Steps `steps` steps of a fresh `scene` through a capturing Recorder; the header is the
/// scene's (samples::scene_header, seed 1). Throws std::runtime_error when the capture API
/// reported misuses.
///
///   const Trace t = capture_trace("bars64", 20);
Trace capture_trace(const std::string& scene, std::uint32_t steps,
                    const samples::SceneOptions& options = {});

}  // namespace tgraph::measure
