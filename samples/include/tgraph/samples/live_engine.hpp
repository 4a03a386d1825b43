// SPDX-License-Identifier: MIT
// The samples engine behind replay's live-run interface.
#pragma once

#include <memory>
#include <string>

#include "tgraph/replay/live.hpp"
#include "tgraph/samples/scene.hpp"

namespace tgraph::samples {

/// A fresh scene stepped through a deferred-mode recorder (record_step) or an uninstrumented
/// one (plain_step); state() lists every datum with storage (positions, velocities, forces,
/// solver vectors and scalars).
///
///   replay::EngineFactory make = [] { return make_live_engine("bars64"); };
///   replay::LiveResult r = replay::run_live(make, &partitioner, options);
std::unique_ptr<replay::LiveEngine> make_live_engine(const std::string& scene,
                                                     const SceneOptions& options = {});

}  // namespace tgraph::samples
