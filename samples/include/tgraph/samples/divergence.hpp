// SPDX-License-Identifier: MIT
// A simulation that diverges stops with an error naming the step, the object and the
// quantity (checks run by Scene::step; settings in SolverSettings; samples/scenes/README.md).
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace tgraph::samples {

/// The simulated state stopped making physical sense: a non-finite position, velocity or
/// force, kinetic energy beyond the energy bound, or a CG solve that ended at its iteration
/// limit without converging on SolverSettings::cg_stall_steps consecutive steps. Not a
/// tgraph::Error (the input may be valid): the command line exits with status 1.
class DivergenceError : public std::runtime_error {
 public:
  /// `step` is the 0-based index of the step whose result diverged.
  DivergenceError(std::uint64_t step, std::string object, std::string quantity,
                  const std::string& detail);
  /// 0-based index of the step whose result diverged.
  std::uint64_t step() const { return step_; }
  /// Body or solver concerned.
  const std::string& object() const { return object_; }
  /// "position", "velocity", "force", "kinetic energy" or "CG residual".
  const std::string& quantity() const { return quantity_; }

 private:
  std::uint64_t step_;
  std::string object_;
  std::string quantity_;
};

}  // namespace tgraph::samples
