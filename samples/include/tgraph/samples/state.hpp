// SPDX-License-Identifier: MIT
// State vectors of the physics engine: 3 x n matrices, one column per node (or DOF group).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string_view>

namespace tgraph::samples {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
/// A state vector of one object: column i is node i (rigid bodies: column 0 linear,
/// column 1 angular).
using StateVec = Eigen::Matrix3Xd;
using Index = Eigen::Index;

/// The state vectors every mechanical object holds (SOFA's VecId).
enum class VecId : std::uint8_t {
  kX = 0,   ///< positions
  kV = 1,   ///< velocities
  kF = 2,   ///< forces
  kDv = 3,  ///< velocity change (implicit solver unknown)
  kR = 4,   ///< CG residual
  kP = 5,   ///< CG search direction
  kQ = 6,   ///< CG matrix-vector product
};
inline constexpr int kVecCount = 7;

/// "x", "v", "f", "dv", "r", "p" or "q".
constexpr std::string_view to_string(VecId id) {
  switch (id) {
    case VecId::kX: return "x";
    case VecId::kV: return "v";
    case VecId::kF: return "f";
    case VecId::kDv: return "dv";
    case VecId::kR: return "r";
    case VecId::kP: return "p";
    case VecId::kQ: return "q";
  }
  return "?";
}

}  // namespace tgraph::samples
