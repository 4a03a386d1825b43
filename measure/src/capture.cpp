// SPDX-License-Identifier: MIT
#include "tgraph/measure/capture.hpp"

#include <stdexcept>

#include "tgraph/capture/recorder.hpp"
#include "tgraph/capture/write_step.hpp"
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
    if (rec.step_errors() != 0)  // the misuse named, as tgraph capture names it
      throw std::runtime_error(scene + " step " + std::to_string(s) + ": " +
                               capture::step_misuse_line(rec));
  }
  return trace;
}

}  // namespace tgraph::measure
