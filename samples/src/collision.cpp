// SPDX-License-Identifier: MIT
// Collision detection: per-body proxies (surface points and bounds), a bounding-box broad
// phase, then a proximity narrow phase between surface points (sphere proxies) and against the
// floor. The proxies and the narrow phases are tasks at the end of each step's graph; the host
// merges their results at the start of the next step (CollisionState in scene_impl.hpp).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>

#include "scene_impl.hpp"

namespace tgraph::samples::detail {
namespace {

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


// Whether box a grown by `by` on every side intersects box b (the broad phase's test).
bool within(const Eigen::AlignedBox3d& a, const Eigen::AlignedBox3d& b, double by) {
  Eigen::AlignedBox3d grown = a;
  grown.min().array() -= by;
  grown.max().array() += by;
  return grown.intersects(b);
}

// Writes a body's proxy from its positions.
void update_proxy(const Body& b, CollisionProxy& p, std::uint64_t epoch) {
  double motion2 = 0.0;
  p.box.setEmpty();
  for (std::size_t k = 0; k < b.surface.size(); ++k) {
    const Vec3 q = b.point(b.surface[k]);
    if (p.filled) motion2 = std::max(motion2, (q - p.points[k]).squaredNorm());
    p.points[k] = q;
    p.box.extend(q);
  }
  p.motion = std::sqrt(motion2);
  p.filled = true;
  p.epoch = epoch;
}

// Narrow phase of one body pair (both with surfaces): point pairs closer than `reach`, found
// from both sides, sorted by (i, j) and without repeats.
std::vector<ContactPair> pair_contacts(const Body& a, const Body& b, const CollisionProxy& pa,
                                       const CollisionProxy& pb, double reach) {
  std::vector<ContactPair> pairs;
  if (!within(pa.box, pb.box, reach)) return pairs;
  const PointGrid grid_b(pb.points, reach);
  for (std::size_t k = 0; k < pa.points.size(); ++k) {
    const Vec3& p = pa.points[k];
    if (pb.box.exteriorDistance(p) >= reach) continue;
    const Index q = grid_b.nearest(p, reach);
    if (q >= 0) pairs.push_back({a.surface[k], b.surface[static_cast<std::size_t>(q)]});
  }
  const PointGrid grid_a(pa.points, reach);
  for (std::size_t k = 0; k < pb.points.size(); ++k) {
    const Vec3& p = pb.points[k];
    if (pa.box.exteriorDistance(p) >= reach) continue;
    const Index q = grid_a.nearest(p, reach);
    if (q >= 0) pairs.push_back({a.surface[static_cast<std::size_t>(q)], b.surface[k]});
  }
  std::sort(pairs.begin(), pairs.end(),
            [](const ContactPair& x, const ContactPair& y) { return x.i != y.i ? x.i < y.i : x.j < y.j; });
  pairs.erase(std::unique(pairs.begin(), pairs.end(),
                          [](const ContactPair& x, const ContactPair& y) { return x.i == y.i && x.j == y.j; }),
              pairs.end());
  return pairs;
}

// Floor phase of one body (with a surface, not fixed): its surface points within the alarm
// distance of the plane, in surface order.
std::vector<Index> floor_points(const Body& b, const CollisionProxy& p, double height, double alarm) {
  std::vector<Index> pts;
  if (p.box.min().y() - b.contact_radius - height >= alarm) return pts;
  for (std::size_t k = 0; k < b.surface.size(); ++k)
    if (p.points[k].y() - b.contact_radius - height < alarm) pts.push_back(b.surface[k]);
  return pts;
}

double reach_of(const Body& a, const Body& b, const CollisionSettings& cs) {
  return a.contact_radius + b.contact_radius + cs.alarm_distance;
}

// Whether bodies i < j are ever tested: both can collide, not on one collision layer.
bool pair_tested(const Scene& scene, const CollisionState& c, std::size_t i, std::size_t j) {
  const Body& a = *scene.bodies()[i];
  const Body& b = *scene.bodies()[j];
  if (a.collision_layer != 0 && a.collision_layer == b.collision_layer) return false;
  if (a.surface.empty() || b.surface.empty()) return false;
  return c.may_collide[i] != 0 || c.may_collide[j] != 0;  // two fixed bodies never move apart
}

// Sizes the collision state once (its storage must not move: tasks point at it).
void prepare(const Scene& scene, Scene::Impl& m) {
  CollisionState& c = m.collide;
  const auto& bodies = scene.bodies();
  if (c.proxies.size() == bodies.size()) return;
  c.proxies.resize(bodies.size());
  c.may_collide.assign(bodies.size(), 0);
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    c.proxies[i].points.resize(bodies[i]->surface.size());
    c.proxies[i].box.setEmpty();
    c.may_collide[i] = bodies[i]->surface.empty() || m.immobile[i] != 0 ? 0 : 1;
  }
  for (std::size_t f = 0; f < m.floors.size(); ++f) c.floor_slots.push_back(std::make_unique<ContactSlot>());
}

// What detection works on: the collision state (sized by prepare()), the settings, the bodies.
struct Detection {
  CollisionState& c;
  const CollisionSettings& cs;
  const std::vector<std::unique_ptr<Body>>& bodies;
  std::size_t n;  // bodies.size()
};

Detection detection_of(Scene& scene, Scene::Impl& m) {
  prepare(scene, m);
  return {m.collide, scene.collision(), scene.bodies(), scene.bodies().size()};
}

ContactSlot& pair_slot(CollisionState& c, int i, int j) {
  auto& slot = c.pair_slots[{i, j}];
  if (!slot) slot = std::make_unique<ContactSlot>();
  return *slot;
}

}  // namespace

void detect_collisions(Scene& scene, Scene::Impl& m) {
  const auto [c, cs, bodies, n] = detection_of(scene, m);
  // Results stamped with the last program's epoch were computed from the positions it left.
  // (The epoch is copied: clang 14 cannot capture a structured binding.)
  const std::uint64_t last_epoch = c.epoch;
  const auto fresh = [last_epoch](std::uint64_t epoch) {
    return last_epoch != 0 && epoch == last_epoch;
  };
  c.host_narrow = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (!fresh(c.proxies[i].epoch)) update_proxy(*bodies[i], c.proxies[i], 0);

  // Floor: surface points within the alarm distance of the plane.
  for (std::size_t f = 0; f < m.floors.size(); ++f) {
    FloorContactForceField& floor = *m.floors[f];
    const Body& b = *floor.body_a();
    const std::size_t i = static_cast<std::size_t>(m.body_index.at(&b));
    ContactSlot& slot = *c.floor_slots[f];
    if (c.may_collide[i] == 0) {
      floor.set_points({});
    } else if (fresh(slot.epoch)) {
      floor.set_points(std::move(slot.floor_points));
    } else {
      std::vector<Index> pts = floor_points(b, c.proxies[i], floor.height(), cs.alarm_distance);
      if (!pts.empty()) ++c.host_narrow;  // a floor contact no task covered
      floor.set_points(std::move(pts));
    }
  }

  // Body pairs: broad phase on boxes, narrow phase on sphere proxies (both directions).
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      Body& a = *bodies[i];
      Body& b = *bodies[j];
      const auto key = std::make_pair(static_cast<int>(i), static_cast<int>(j));
      std::vector<ContactPair> pairs;
      if (pair_tested(scene, c, i, j)) {
        auto found = c.pair_slots.find(key);
        if (found != c.pair_slots.end() && fresh(found->second->epoch)) {
          pairs = std::move(found->second->pairs);
        } else {
          const double reach = reach_of(a, b, cs);
          if (within(c.proxies[i].box, c.proxies[j].box, reach)) {  // a narrow phase no task covered
            ++c.host_narrow;
            pairs = pair_contacts(a, b, c.proxies[i], c.proxies[j], reach);
          }
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

void plan_detection(Scene& scene, Scene::Impl& m) {
  const auto [c, cs, bodies, n] = detection_of(scene, m);
  c.planned_pairs.clear();
  c.planned_floors.clear();
  // How far each body may move in this step: twice what it moved in the last one. A body that
  // moves farther is caught by the next merge's host narrow phase (the results do not change).
  std::vector<double> margin(n);
  for (std::size_t i = 0; i < n; ++i) margin[i] = c.may_collide[i] != 0 ? 2.0 * c.proxies[i].motion : 0.0;
  for (std::size_t f = 0; f < m.floors.size(); ++f) {
    const Body& b = *m.floors[f]->body_a();
    const std::size_t i = static_cast<std::size_t>(m.body_index.at(&b));
    if (c.may_collide[i] != 0 &&
        c.proxies[i].box.min().y() - margin[i] - b.contact_radius - m.floors[f]->height() < cs.alarm_distance)
      c.planned_floors.push_back(static_cast<int>(f));
  }
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      if (!pair_tested(scene, c, i, j)) continue;
      const double grow = reach_of(*bodies[i], *bodies[j], cs) + margin[i] + margin[j];
      if (!within(c.proxies[i].box, c.proxies[j].box, grow)) continue;
      c.planned_pairs.emplace_back(static_cast<int>(i), static_cast<int>(j));
      pair_slot(c, static_cast<int>(i), static_cast<int>(j));
    }
  }
  c.epoch = c.next_epoch++;
}

void declare_detection(Scene& scene, Scene::Impl& m, capture::Recorder& rec) {
  for (const auto& [i, j] : m.collide.planned_pairs) {
    // The pair's interaction object: the one its contact field's tasks use, when it has one.
    const ObjectId obj = rec.object("contact[" + scene.bodies()[static_cast<std::size_t>(i)]->name() + "|" +
                                    scene.bodies()[static_cast<std::size_t>(j)]->name() + "]");
    m.bind.object_body[obj] = i;
  }
}

void record_detection(Scene& scene, Scene::Impl& m, capture::Recorder& rec,
                      const std::function<DatumId(int)>& x_of) {
  CollisionState& c = m.collide;
  Binding& b = m.bind;
  const CollisionSettings* cs = &scene.collision();
  const auto& bodies = scene.bodies();
  if (b.body_proxy.size() != bodies.size()) b.body_proxy.assign(bodies.size(), kNoDatum);
  if (b.floor_contacts.size() != m.floors.size()) b.floor_contacts.assign(m.floors.size(), kNoDatum);
  const std::uint64_t* epoch = &c.epoch;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i]->surface.empty()) continue;
    const Body* body = bodies[i].get();
    CollisionProxy* proxy = &c.proxies[i];
    DatumId& d = b.body_proxy[i];
    if (d == kNoDatum)
      d = rec.datum(body->name() + ".proxy", b.body_object[i],
                    static_cast<std::uint64_t>(proxy->points.size()) * sizeof(Vec3), proxy->points.data());
    rec.task(b.update_proxy, b.body_object[i], {{x_of(static_cast<int>(i)), AccessMode::R}, {d, AccessMode::W}},
             [body, proxy, epoch] { update_proxy(*body, *proxy, *epoch); });
  }
  for (const auto& [i, j] : c.planned_pairs) {
    const Body* a = bodies[static_cast<std::size_t>(i)].get();
    const Body* o = bodies[static_cast<std::size_t>(j)].get();
    const ObjectId obj = rec.object("contact[" + a->name() + "|" + o->name() + "]");
    auto d = b.pair_contacts.find({i, j});
    if (d == b.pair_contacts.end())
      d = b.pair_contacts
              .emplace(std::make_pair(i, j),
                       rec.datum("contact[" + a->name() + "|" + o->name() + "].set", obj,
                                 static_cast<std::uint64_t>(a->surface.size() + o->surface.size()) *
                                     sizeof(ContactPair)))
              .first;
    const CollisionProxy* pa = &c.proxies[static_cast<std::size_t>(i)];
    const CollisionProxy* po = &c.proxies[static_cast<std::size_t>(j)];
    ContactSlot* slot = &pair_slot(c, i, j);
    const double reach = reach_of(*a, *o, *cs);
    rec.task(b.collide_pair, obj,
             {{b.body_proxy[static_cast<std::size_t>(i)], AccessMode::R},
              {b.body_proxy[static_cast<std::size_t>(j)], AccessMode::R},
              {d->second, AccessMode::W}},
             [a, o, pa, po, slot, reach, epoch] {
               slot->pairs = pair_contacts(*a, *o, *pa, *po, reach);
               slot->epoch = *epoch;
             });
  }
  for (int f : c.planned_floors) {
    const FloorContactForceField* floor = m.floors[static_cast<std::size_t>(f)].get();
    const Body* body = floor->body_a();
    const std::size_t i = static_cast<std::size_t>(m.body_index.at(body));
    DatumId& d = b.floor_contacts[static_cast<std::size_t>(f)];
    if (d == kNoDatum)
      d = rec.datum(floor->name() + ".points", b.body_object[i],
                    static_cast<std::uint64_t>(body->surface.size()) * sizeof(Index));
    const CollisionProxy* proxy = &c.proxies[i];
    ContactSlot* slot = c.floor_slots[static_cast<std::size_t>(f)].get();
    rec.task(b.collide_floor, b.body_object[i], {{b.body_proxy[i], AccessMode::R}, {d, AccessMode::W}},
             [body, floor, proxy, slot, cs, epoch] {
               slot->floor_points = floor_points(*body, *proxy, floor->height(), cs->alarm_distance);
               slot->epoch = *epoch;
             });
  }
}

}  // namespace tgraph::samples::detail
