// SPDX-License-Identifier: MIT
// The two builders of a step's picture (graph_view.cpp chooses): the task view with its
// synchronisation nodes (task_view.cpp) and the aggregated view (ViewOptions::collapse)
// (collapsed_view.cpp).
#pragma once

#include <cstdint>
#include <string>

#include "tgraph/graph/step_graph.hpp"
#include "tgraph/viz/critical_path.hpp"
#include "tgraph/viz/graph_view.hpp"

namespace tgraph::viz::detail {

/// `v` with three significant digits ("%.3g").
std::string sig3(double v);

/// Adds the task-level picture (Collapse::kNone) of `g` to `v`; `cp` marks the critical path.
void build_task_view(const StepGraph& g, const ViewOptions& o, const CriticalPath* cp,
                     GraphView& v);
/// Adds the aggregated picture of `g` (every Collapse but kNone) to `v`.
void build_collapsed_view(const StepGraph& g, const ViewOptions& o, const CriticalPath* cp,
                          GraphView& v);

}  // namespace tgraph::viz::detail
