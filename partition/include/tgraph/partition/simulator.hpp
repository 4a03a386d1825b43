// SPDX-License-Identifier: MIT
// Transitional: the schedule simulator is tgraph::model's (tgraph/model/simulator.hpp). The
// names below stay reachable as partition's for the files that still include this header
// (ode/src/validate.cpp); delete it once they name tgraph/model/ and model:: themselves.
#pragma once

#include "tgraph/model/simulator.hpp"
#include "tgraph/partition/cost_model.hpp"

namespace tgraph::partition {

using model::Schedule;
using model::simulate;

}  // namespace tgraph::partition
