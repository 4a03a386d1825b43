// SPDX-License-Identifier: MIT
#include "builders.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace tgraph::samples::detail {
namespace {

// Corner offsets of the documented hexahedron node order.
constexpr std::array<std::array<int, 3>, 8> kCorner = {
    {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}};
// Faces (corner indices, counter-clockwise seen from outside) and their outward axis.
constexpr std::array<std::array<int, 4>, 6> kFace = {{{0, 4, 7, 3},   // -x
                                                      {1, 2, 6, 5},   // +x
                                                      {0, 1, 5, 4},   // -y
                                                      {3, 7, 6, 2},   // +y
                                                      {0, 3, 2, 1},   // -z
                                                      {4, 5, 6, 7}}}; // +z
constexpr std::array<std::array<int, 3>, 6> kFaceDir = {
    {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}}};

double max_edge(const StateVec& pts, const std::vector<std::array<Index, 3>>& tris) {
  double m = 0.0;
  for (const auto& t : tris)
    for (int e = 0; e < 3; ++e) m = std::max(m, (pts.col(t[static_cast<std::size_t>(e)]) - pts.col(t[static_cast<std::size_t>((e + 1) % 3)])).norm());
  return m;
}

}  // namespace

HexMesh make_hex_grid(const std::array<int, 3>& n, const Vec3& size, const Vec3& center, Shape shape) {
  HexMesh mesh;
  mesh.dims = n;
  const int nx = n[0], ny = n[1], nz = n[2];
  const int ex = nx - 1, ey = ny - 1, ez = nz - 1;
  mesh.spacing = Vec3(size.x() / ex, size.y() / ey, size.z() / ez);
  const Vec3 lo = center - 0.5 * size;
  auto grid_pos = [&](int i, int j, int k) {
    return Vec3(lo.x() + i * mesh.spacing.x(), lo.y() + j * mesh.spacing.y(), lo.z() + k * mesh.spacing.z());
  };
  auto elem_id = [&](int i, int j, int k) { return static_cast<std::size_t>(i + ex * (j + ey * k)); };
  std::vector<char> kept(static_cast<std::size_t>(ex * ey * ez), 0);
  for (int k = 0; k < ez; ++k)
    for (int j = 0; j < ey; ++j)
      for (int i = 0; i < ex; ++i) {
        bool keep = true;
        if (shape == Shape::kEllipsoid) {
          const Vec3 c = grid_pos(i, j, k) + 0.5 * mesh.spacing;
          keep = ((c - center).array() / (0.5 * size).array()).square().sum() <= 1.0;
        }
        kept[elem_id(i, j, k)] = keep ? 1 : 0;
      }
  auto is_kept = [&](int i, int j, int k) {
    return i >= 0 && j >= 0 && k >= 0 && i < ex && j < ey && k < ez && kept[elem_id(i, j, k)] != 0;
  };
  // Nodes used by kept elements, numbered in grid order.
  std::vector<Index> node_of(static_cast<std::size_t>(nx * ny * nz), -1);
  for (int k = 0; k < ez; ++k)
    for (int j = 0; j < ey; ++j)
      for (int i = 0; i < ex; ++i)
        if (is_kept(i, j, k))
          for (const auto& c : kCorner)
            node_of[static_cast<std::size_t>((i + c[0]) + nx * ((j + c[1]) + ny * (k + c[2])))] = 0;
  Index count = 0;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const auto g = static_cast<std::size_t>(i + nx * (j + ny * k));
        if (node_of[g] < 0) continue;
        node_of[g] = count++;
        mesh.grid_node.push_back(static_cast<Index>(g));
      }
  mesh.nodes.resize(3, count);
  for (Index v = 0; v < count; ++v) {
    const auto g = static_cast<int>(mesh.grid_node[static_cast<std::size_t>(v)]);
    mesh.nodes.col(v) = grid_pos(g % nx, (g / nx) % ny, g / (nx * ny));
  }
  mesh.node_volume.assign(static_cast<std::size_t>(count), 0.0);
  const double vol = mesh.spacing.prod();
  std::vector<char> on_surface(static_cast<std::size_t>(count), 0);
  for (int k = 0; k < ez; ++k)
    for (int j = 0; j < ey; ++j)
      for (int i = 0; i < ex; ++i) {
        if (!is_kept(i, j, k)) continue;
        std::array<Index, 8> e{};
        for (std::size_t c = 0; c < 8; ++c)
          e[c] = node_of[static_cast<std::size_t>((i + kCorner[c][0]) + nx * ((j + kCorner[c][1]) + ny * (k + kCorner[c][2])))];
        for (Index v : e) mesh.node_volume[static_cast<std::size_t>(v)] += vol / 8.0;
        for (std::size_t f = 0; f < 6; ++f) {
          if (is_kept(i + kFaceDir[f][0], j + kFaceDir[f][1], k + kFaceDir[f][2])) continue;
          const auto& q = kFace[f];
          mesh.triangles.push_back({e[static_cast<std::size_t>(q[0])], e[static_cast<std::size_t>(q[1])], e[static_cast<std::size_t>(q[2])]});
          mesh.triangles.push_back({e[static_cast<std::size_t>(q[0])], e[static_cast<std::size_t>(q[2])], e[static_cast<std::size_t>(q[3])]});
          for (int c : q) on_surface[static_cast<std::size_t>(e[static_cast<std::size_t>(c)])] = 1;
        }
        mesh.elements.push_back(e);
      }
  for (Index v = 0; v < count; ++v)
    if (on_surface[static_cast<std::size_t>(v)] != 0) mesh.surface.push_back(v);
  return mesh;
}

std::vector<Spring> grid_springs(const HexMesh& mesh, double stiffness) {
  static constexpr std::array<std::array<int, 2>, 28> kPairs = {{
      {0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6}, {6, 7}, {7, 4}, {0, 4}, {1, 5},
      {2, 6}, {3, 7},                                                   // edges
      {0, 7}, {4, 3}, {1, 6}, {2, 5}, {0, 5}, {1, 4}, {3, 6}, {7, 2}, {0, 2}, {3, 1},
      {4, 6}, {5, 7},                                                   // face diagonals
      {0, 6}, {1, 7}, {2, 4}, {3, 5}}};                                 // body diagonals
  std::vector<std::pair<Index, Index>> pairs;
  pairs.reserve(mesh.elements.size() * kPairs.size());
  for (const auto& e : mesh.elements)
    for (const auto& p : kPairs) {
      Index a = e[static_cast<std::size_t>(p[0])], b = e[static_cast<std::size_t>(p[1])];
      if (a > b) std::swap(a, b);
      pairs.emplace_back(a, b);
    }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  std::vector<Spring> springs;
  springs.reserve(pairs.size());
  for (const auto& [a, b] : pairs)
    springs.push_back({a, b, (mesh.nodes.col(a) - mesh.nodes.col(b)).norm(), stiffness});
  return springs;
}

RigidSurface box_surface(const Vec3& size, int res) {
  // res points along the longest edge; the other edges get the same spacing (at least 2).
  const double spacing = size.maxCoeff() / (res - 1);
  std::array<int, 3> n{};
  for (int a = 0; a < 3; ++a) n[static_cast<std::size_t>(a)] = std::max(2, static_cast<int>(std::lround(size[a] / spacing)) + 1);
  RigidSurface s;
  auto lin = [&](int i, int j, int k) { return static_cast<std::size_t>(i + n[0] * (j + n[1] * k)); };
  std::vector<Index> id(static_cast<std::size_t>(n[0] * n[1] * n[2]), -1);
  std::vector<Vec3> pts;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        if (!(i == 0 || j == 0 || k == 0 || i == n[0] - 1 || j == n[1] - 1 || k == n[2] - 1)) continue;
        id[lin(i, j, k)] = static_cast<Index>(pts.size());
        pts.push_back(Vec3(static_cast<double>(i) / (n[0] - 1), static_cast<double>(j) / (n[1] - 1),
                           static_cast<double>(k) / (n[2] - 1)) -
                      Vec3::Constant(0.5));
      }
  s.points.resize(3, static_cast<Index>(pts.size()));
  for (std::size_t p = 0; p < pts.size(); ++p) s.points.col(static_cast<Index>(p)) = pts[p].cwiseProduct(size);
  // Each face: fix one axis at its first or last layer, walk the other two.
  for (int axis = 0; axis < 3; ++axis) {
    const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
    for (int side : {0, n[static_cast<std::size_t>(axis)] - 1})
      for (int u = 0; u + 1 < n[static_cast<std::size_t>(a1)]; ++u)
        for (int v = 0; v + 1 < n[static_cast<std::size_t>(a2)]; ++v) {
          auto idx = [&](int du, int dv) {
            std::array<int, 3> c{};
            c[static_cast<std::size_t>(axis)] = side;
            c[static_cast<std::size_t>(a1)] = u + du;
            c[static_cast<std::size_t>(a2)] = v + dv;
            return id[lin(c[0], c[1], c[2])];
          };
          s.triangles.push_back({idx(0, 0), idx(1, 0), idx(1, 1)});
          s.triangles.push_back({idx(0, 0), idx(1, 1), idx(0, 1)});
        }
  }
  s.spacing = max_edge(s.points, s.triangles) / std::sqrt(2.0);
  return s;
}

RigidSurface sphere_surface(double radius, int res) {
  RigidSurface s = box_surface(Vec3::Ones(), res);
  for (Index i = 0; i < s.points.cols(); ++i) s.points.col(i) = radius * s.points.col(i).normalized();
  s.spacing = max_edge(s.points, s.triangles) / std::sqrt(2.0);
  return s;
}

}  // namespace tgraph::samples::detail
