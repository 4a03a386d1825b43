// SPDX-License-Identifier: MIT
// Collision detection (sequential, outside the task graph): bounding-box broad phase, then a
// proximity narrow phase between surface points (sphere proxies) and against the floor.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

#include "scene_impl.hpp"

namespace tgraph::samples::detail {
namespace {

struct Surface {
  std::vector<Vec3> points;  // world positions of the surface points
  Eigen::AlignedBox3d box;
};

// Points of a surface sorted into a uniform grid, for neighbour queries.
class PointGrid {
 public:
  PointGrid(const std::vector<Vec3>& pts, double cell) : pts_(pts), inv_(1.0 / cell) {
    entries_.reserve(pts.size());
    for (std::size_t i = 0; i < pts.size(); ++i) entries_.push_back({key(cell_of(pts[i])), static_cast<Index>(i)});
    std::sort(entries_.begin(), entries_.end());
  }

  // Nearest point within `radius` of p, or -1.
  Index nearest(const Vec3& p, double radius) const {
    const auto c = cell_of(p);
    Index best = -1;
    double best_d2 = radius * radius;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const std::uint64_t k = key({c[0] + dx, c[1] + dy, c[2] + dz});
          auto it = std::lower_bound(entries_.begin(), entries_.end(), std::pair<std::uint64_t, Index>{k, -1});
          for (; it != entries_.end() && it->first == k; ++it) {
            const double d2 = (pts_[static_cast<std::size_t>(it->second)] - p).squaredNorm();
            if (d2 < best_d2 || (d2 == best_d2 && best >= 0 && it->second < best)) {
              best_d2 = d2;
              best = it->second;
            }
          }
        }
    return best;
  }

 private:
  std::array<std::int64_t, 3> cell_of(const Vec3& p) const {
    return {static_cast<std::int64_t>(std::floor(p.x() * inv_)), static_cast<std::int64_t>(std::floor(p.y() * inv_)),
            static_cast<std::int64_t>(std::floor(p.z() * inv_))};
  }
  static std::uint64_t key(const std::array<std::int64_t, 3>& c) {
    const auto u = [](std::int64_t v) { return static_cast<std::uint64_t>(v + (1 << 20)) & 0x1fffffu; };
    return (u(c[0]) << 42) | (u(c[1]) << 21) | u(c[2]);
  }

  const std::vector<Vec3>& pts_;
  double inv_;
  std::vector<std::pair<std::uint64_t, Index>> entries_;
};

}  // namespace

void detect_collisions(Scene& scene, Scene::Impl& m) {
  const CollisionSettings& cs = scene.collision();
  const auto& bodies = scene.bodies();
  const std::size_t n = bodies.size();
  std::vector<Surface> surf(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Body& b = *bodies[i];
    surf[i].points.reserve(b.surface.size());
    for (Index p : b.surface) {
      surf[i].points.push_back(b.point(p));
      surf[i].box.extend(surf[i].points.back());
    }
  }

  // Floor: surface points within the alarm distance of the plane.
  for (const auto& floor : m.floors) {
    const Body& b = *floor->body_a();
    const std::size_t i = static_cast<std::size_t>(m.body_index.at(&b));
    std::vector<Index> pts;
    if (m.immobile[i] == 0 && !surf[i].points.empty() && surf[i].box.min().y() - b.contact_radius - floor->height() < cs.alarm_distance)
      for (std::size_t k = 0; k < b.surface.size(); ++k)
        if (surf[i].points[k].y() - b.contact_radius - floor->height() < cs.alarm_distance)
          pts.push_back(b.surface[k]);
    floor->set_points(std::move(pts));
  }

  // Body pairs: broad phase on boxes, narrow phase on sphere proxies (both directions).
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      Body& a = *bodies[i];
      Body& b = *bodies[j];
      const auto key = std::make_pair(static_cast<int>(i), static_cast<int>(j));
      const double reach = a.contact_radius + b.contact_radius + cs.alarm_distance;
      std::vector<ContactPair> pairs;
      const bool same_layer = a.collision_layer != 0 && a.collision_layer == b.collision_layer;
      const bool both_fixed = m.immobile[i] != 0 && m.immobile[j] != 0;
      if (!same_layer && !both_fixed && !surf[i].points.empty() && !surf[j].points.empty()) {
        Eigen::AlignedBox3d grown = surf[i].box;
        grown.min().array() -= reach;
        grown.max().array() += reach;
        if (grown.intersects(surf[j].box)) {
          const PointGrid grid_b(surf[j].points, reach);
          for (std::size_t k = 0; k < surf[i].points.size(); ++k) {
            const Vec3& p = surf[i].points[k];
            if (surf[j].box.exteriorDistance(p) >= reach) continue;
            const Index q = grid_b.nearest(p, reach);
            if (q >= 0) pairs.push_back({a.surface[k], b.surface[static_cast<std::size_t>(q)]});
          }
          const PointGrid grid_a(surf[i].points, reach);
          for (std::size_t k = 0; k < surf[j].points.size(); ++k) {
            const Vec3& p = surf[j].points[k];
            if (surf[i].box.exteriorDistance(p) >= reach) continue;
            const Index q = grid_a.nearest(p, reach);
            if (q >= 0) pairs.push_back({a.surface[static_cast<std::size_t>(q)], b.surface[k]});
          }
          std::sort(pairs.begin(), pairs.end(),
                    [](const ContactPair& x, const ContactPair& y) { return x.i != y.i ? x.i < y.i : x.j < y.j; });
          pairs.erase(std::unique(pairs.begin(), pairs.end(),
                                  [](const ContactPair& x, const ContactPair& y) { return x.i == y.i && x.j == y.j; }),
                      pairs.end());
        }
      }
      auto it = m.contacts.find(key);
      if (pairs.empty()) {
        if (it != m.contacts.end()) m.contacts.erase(it);
        continue;
      }
      if (it == m.contacts.end())
        it = m.contacts
                 .emplace(key, std::make_unique<ContactForceField>("contact[" + a.name() + "|" + b.name() + "]", &a,
                                                                   &b, cs.stiffness, cs.damping, cs.friction))
                 .first;
      it->second->set_pairs(std::move(pairs));
    }
  }
}

}  // namespace tgraph::samples::detail
