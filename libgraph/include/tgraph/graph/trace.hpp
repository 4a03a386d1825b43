// SPDX-License-Identifier: MIT
// A trace: header plus the step graphs of a capture.
#pragma once

#include <string>
#include <vector>

#include "tgraph/graph/step_graph.hpp"

namespace tgraph {

/// Where a trace came from.
struct TraceHeader {
  std::string scene;
  std::string engine;
  std::string machine;
  std::string tgraph_version;
  friend bool operator==(const TraceHeader&, const TraceHeader&) = default;
};

/// Header and the sequence of steps, each with derived edges.
struct Trace {
  TraceHeader header;
  std::vector<StepGraph> steps;
  friend bool operator==(const Trace&, const Trace&) = default;
};

/// trace.steps[step]; an OptionError of the options field `field` ("<field>: trace
/// <trace_name> has N steps, no step <step>") when out of range (the verbs that take one
/// step of a trace).
const StepGraph& step_at(const Trace& trace, std::size_t step, const std::string& trace_name,
                         const std::string& field = "step");

/// This machine for trace headers: "<cpu model>, N hardware threads".
std::string machine_description();

/// True when the contact set of step `i` differs from step `i - 1` (false for step 0).
bool contacts_changed(const Trace& trace, std::size_t i);

}  // namespace tgraph
