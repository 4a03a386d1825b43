// SPDX-License-Identifier: MIT
// The ODE scenes (ode-piles, ode-heap, ode-chains) where a verb takes a scene: `run`,
// `capture` and `validate` hand an ode-* scene to tgraph::ode (apps/cmd_ode.cpp); without
// tgraph::ode (libode-dev not found) such a scene is refused by name.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <optional>
#include <string>

namespace tgraph::app {

/// The flags only ODE scenes read.
struct OdeFlags {
  std::string stepper = "quickstep";        ///< quickstep (dWorldQuickStep) or step (dWorldStep)
  std::uint32_t repartition_interval = 10;  ///< partition-guided method: steps between partitions
  std::uint32_t threads = 2;                ///< capture: the threads ODE posts for
  std::string method = "islands-serial";    ///< capture: the policy whose steps are recorded
};

/// True for ode-piles, ode-heap, ode-chains (whether or not tgraph::ode is built).
bool is_ode_scene(const std::string& scene);
/// `--stepper` and `--repartition-interval` (run, validate).
void add_ode_flags(CLI::App* cmd, OdeFlags& flags);
/// `--stepper`, `--threads` and `--method` (capture).
void add_ode_capture_flags(CLI::App* cmd, OdeFlags& flags);

/// `tgraph run --scene ode-*`: prints the report; throws Failure when --check finds "differs".
void run_ode(const std::string& scene, std::optional<std::uint32_t> steps,
             const std::string& method, std::uint32_t threads, std::uint32_t repeat, bool check,
             bool json, double timeout_s, const OdeFlags& flags);
/// `tgraph capture --scene ode-*`.
void capture_ode(const std::string& scene, std::optional<int> steps, const std::string& output,
                 bool json, const OdeFlags& flags);
/// `tgraph validate --scene ode-*`.
void validate_ode(const std::string& scene, std::optional<std::uint32_t> steps,
                  const std::string& method, std::uint32_t threads, std::uint32_t repeat,
                  const std::string& calibration, bool json, const OdeFlags& flags);

}  // namespace tgraph::app
