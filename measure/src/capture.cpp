// SPDX-License-Identifier: MIT
#include "tgraph/measure/capture.hpp"

#include <stdexcept>

#include "tgraph/capture/recorder.hpp"
#include "tgraph/samples/capture_run.hpp"

namespace tgraph::measure {

Trace capture_trace(const std::string& scene, std::uint32_t steps,
                    const samples::SceneOptions& options) {
  auto sc = samples::make_scene(scene, options);
  capture::Recorder rec(capture::Mode::kCapture);
  Trace trace;
  trace.header = samples::scene_header(*sc, 1);
  for (std::uint32_t s = 0; s < steps; ++s) {
    sc->step(rec);
    trace.steps.push_back(rec.end_step());
  }
  if (rec.errors() != 0)
    throw std::runtime_error(scene + ": the capture API reported " + std::to_string(rec.errors()) +
                             " misuses");
  return trace;
}

}  // namespace tgraph::measure
