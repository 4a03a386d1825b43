// SPDX-License-Identifier: MIT
// The engine's scenes as viz's tests draw them, read from traces captured once into
// tests/data/traces (viz's tests do not link the engine):
//   tgraph capture --scene fig2 --steps 3 -o tests/data/traces/fig2.tgt
//   tgraph capture --scene bars64 --steps 2 -o tests/data/traces/bars64.tgt
#pragma once

#include <stdexcept>
#include <string>

#include "tgraph/graph/trace_io.hpp"

namespace tgraph::viz::testing {

/// The first `steps` steps of the scene's captured trace.
inline Trace scene_trace(const std::string& scene, int steps) {
  Trace t = read_trace(std::string(TGRAPH_TEST_DATA) + "/traces/" + scene + ".tgt");
  if (steps < 0 || static_cast<std::size_t>(steps) > t.steps.size())
    throw std::out_of_range(scene + ".tgt has " + std::to_string(t.steps.size()) + " steps");
  t.steps.resize(static_cast<std::size_t>(steps));
  return t;
}

/// Step `step` of the scene's captured trace.
inline StepGraph scene_step(const std::string& scene, int step) {
  return scene_trace(scene, step + 1).steps.back();
}

}  // namespace tgraph::viz::testing
