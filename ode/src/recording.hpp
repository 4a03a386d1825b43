// SPDX-License-Identifier: MIT
// A step's log of calls (runtime.hpp) as a tgraph StepGraph.
#pragma once

#include "runtime.hpp"
#include "tgraph/graph/step_graph.hpp"

namespace tgraph::ode::detail {

/// One task per segment of a call, in start order (topological), kind = the call's name,
/// key = (name, instance, occurrence, segment). Data, one per declared relation: a segment's
/// end (W by it, R by the call's next segment and by the calls posted there), a releasee's
/// releases (CW by each releasing segment, R by the releasee's first segment), a wait's
/// signal (CW by the signalling segments, R by the segment after the wait). Edges derived.
StepGraph build_step_graph(const StepLog& log);

}  // namespace tgraph::ode::detail
