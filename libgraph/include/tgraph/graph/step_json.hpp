// SPDX-License-Identifier: MIT
// One step graph as JSON (what `tgraph export` writes in its json format).
#pragma once

#include <cstddef>
#include <string>

#include "tgraph/graph/step_graph.hpp"

namespace tgraph {

/// The step as an indented JSON object: "step", "objects" (names), "data" (name, object,
/// bytes), "tasks" (id, kind, object, cost_ns, loop, key, accesses), "loops", "edges" and
/// "carried_edges" (from, to, datum, kind, bytes), "contacts" ([a, b] pairs) and "groups".
std::string step_graph_json(const StepGraph& g, std::size_t step);

}  // namespace tgraph
