// SPDX-License-Identifier: MIT
// Transitional: the cost model and its calibration are tgraph::model's
// (tgraph/model/cost_model.hpp). The names below stay reachable as partition's for the files
// that still include this header (apps/cmd_partition.cpp, ode/src/validate.cpp); delete it
// once they name tgraph/model/cost_model.hpp and model:: themselves.
#pragma once

#include "tgraph/model/cost_model.hpp"

namespace tgraph::partition {

using model::CalibrateOptions;
using model::CostModel;
using model::default_calibration_path;
using model::select_cost_model;
using model::SerialWork;

}  // namespace tgraph::partition
