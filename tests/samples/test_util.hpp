// SPDX-License-Identifier: MIT
// Helpers shared by the samples tests.
#pragma once

#include <string>

#include "tgraph/capture/recorder.hpp"
#include "tgraph/samples/scene.hpp"

namespace tgraph::samples::test {

/// Runs `steps` steps uninstrumented.
inline void run(Scene& scene, int steps) {
  capture::Recorder rec(capture::Mode::kOff);
  for (int s = 0; s < steps; ++s) {
    scene.step(rec);
    rec.end_step();
  }
}

/// Runs a deferred step program sequentially, as an executor would: tasks in program order,
/// each loop body repeated until its condition holds or max_iterations is reached.
/// Returns the iterations run per loop.
inline std::vector<std::uint32_t> run_program(capture::StepProgram& p) {
  std::vector<std::uint32_t> iterations;
  const StepGraph& g = p.graph;
  std::size_t next_loop = 0;
  for (TaskId t = 0; t < g.tasks.size();) {
    if (next_loop < g.loops.size() && g.loops[next_loop].first == t) {
      const Loop& loop = g.loops[next_loop];
      std::uint32_t it = 0;
      for (;;) {
        for (TaskId u = loop.first; u < loop.last; ++u)
          if (p.bodies[u]) p.bodies[u]();
        ++it;
        if (p.conditions[next_loop]() || (loop.max_iterations != 0 && it >= loop.max_iterations)) break;
      }
      iterations.push_back(it);
      t = loop.last;
      ++next_loop;
      continue;
    }
    if (p.bodies[t]) p.bodies[t]();
    ++t;
  }
  return iterations;
}

/// A scene file's text with a header and the given lines.
inline std::string scene_text(const std::string& body) { return "tgraph-scene 1\n" + body; }

}  // namespace tgraph::samples::test
