// SPDX-License-Identifier: MIT
// The scaling sweep's ODE scenes (docs/ode.md): their names, methods, reference run and
// records through ode::run_scene. In a build without tgraph::ode no scene is an ODE scene:
// an `ode-` name is refused with the reason, and the runs are never asked for.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "tgraph/experiment/scaling.hpp"

namespace tgraph::experiment::detail {

/// ODE self-threaded, ODE's own pool (the peer), work stealing and the partition-guided method.
const std::vector<std::string>& default_ode_methods();

/// NAME as an ODE scene (its own step count, 40 when quick), or nullopt when it is none; an
/// `ode-` name in a build without ODE: OptionError("scenes") naming why.
std::optional<ScalingScene> ode_scene(const std::string& name, bool quick);

/// The ODE scenes' names (empty without ODE), for the error of an unknown scene.
std::vector<std::string> ode_scene_names();

/// --methods for the ODE scenes, each checked by ode::choose_method (OptionError("methods")).
std::vector<std::string> checked_ode_methods(const std::vector<std::string>& methods);

/// A record's policy and method names for an ODE scene: ode::choose_method's.
std::pair<std::string, std::string> ode_policy_and_method(const std::string& method);

/// An ODE scene's reference: ODE self-threaded (the calling thread, unpinned), median pass.
ScalingReference ode_reference(const ScalingScene& s, const ScalingPlan& p);

/// An ODE scene's run of METHOD on K threads with its check, as its record (HEAD: the fields
/// every record has).
ScalingRecord ode_record(const ScalingScene& s, const std::string& method, std::uint32_t k,
                         const ScalingPlan& p, ScalingRecord head);

}  // namespace tgraph::experiment::detail
