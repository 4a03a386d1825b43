// SPDX-License-Identifier: MIT
// Geometry builders for the scenes: hexahedral grids, rigid surfaces, spring sets.
#pragma once

#include <array>
#include <vector>

#include "tgraph/samples/force_field.hpp"

namespace tgraph::samples::detail {

/// Shape of a volumetric grid object.
enum class Shape : std::uint8_t { kBox = 0, kEllipsoid = 1 };

/// A hexahedral mesh built from a regular grid (elements outside the shape dropped).
struct HexMesh {
  StateVec nodes;                                 ///< rest positions
  std::array<int, 3> dims{};                      ///< grid nodes per axis (before masking)
  std::vector<Index> grid_node;                   ///< node -> grid index i + nx (j + ny k)
  std::vector<std::array<Index, 8>> elements;
  std::vector<double> node_volume;                ///< lumped volume (1/8 of each element)
  std::vector<Index> surface;                     ///< nodes on the boundary faces
  std::vector<std::array<Index, 3>> triangles;    ///< boundary quads split in two
  Vec3 spacing = Vec3::Zero();
};

/// Grid of nx x ny x nz nodes filling `size`, centred at `center`.
HexMesh make_hex_grid(const std::array<int, 3>& nodes, const Vec3& size, const Vec3& center, Shape shape);

/// Springs along the edges, face diagonals and body diagonals of every element (a
/// "deformable grid" mass-spring model), each with rest length from the rest positions.
std::vector<Spring> grid_springs(const HexMesh& mesh, double stiffness);

/// Surface of a rigid box (res x res points per face) or sphere, in the body frame.
struct RigidSurface {
  StateVec points;
  std::vector<std::array<Index, 3>> triangles;
  double spacing = 0.0;
};
RigidSurface box_surface(const Vec3& size, int res);
RigidSurface sphere_surface(double radius, int res);

}  // namespace tgraph::samples::detail
