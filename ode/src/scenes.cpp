// SPDX-License-Identifier: MIT
#include "tgraph/ode/scenes.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include "tgraph/graph/error.hpp"
#include "tgraph/ode/attach.hpp"
#include "tgraph/replay/observer.hpp"

namespace tgraph::ode {
namespace {

using replay::now_ns;  // the steady clock of every timeline

constexpr int kMaxContacts = 4;

}  // namespace

bool is_scene(std::string_view name) {
  return name == "ode-piles" || name == "ode-heap" || name == "ode-chains";
}

std::vector<std::string> scene_names() { return {"ode-piles", "ode-heap", "ode-chains"}; }

std::uint32_t default_steps(std::string_view scene) { return scene == "ode-heap" ? 400 : 200; }

std::uint32_t Scene::default_steps() const { return ode::default_steps(name_); }

void Scene::near_callback(void* data, dGeomID a, dGeomID b) {
  static_cast<Scene*>(data)->contacts(a, b);
}

void Scene::pair_callback(void* data, dGeomID a, dGeomID b) {
  static_cast<Scene*>(data)->pairs_.emplace_back(a, b);
}

void Scene::contacts(dGeomID a, dGeomID b) {
  dBodyID ba = dGeomGetBody(a), bb = dGeomGetBody(b);
  if (ba == nullptr && bb == nullptr) return;  // two static geoms
  if (skip_connected_ && ba && bb && dAreConnectedExcluding(ba, bb, dJointTypeContact)) return;
  dContact contact[kMaxContacts] = {};
  const int n = dCollide(a, b, kMaxContacts, &contact[0].geom, sizeof(dContact));
  for (int i = 0; i < n; ++i) {
    contact[i].surface.mode = dContactApprox1 | dContactSoftERP;
    contact[i].surface.mu = 0.5;
    contact[i].surface.soft_erp = 0.5;
    dJointID j = dJointCreateContact(world_, contacts_, &contact[i]);
    dJointAttach(j, ba, bb);
  }
}

void Scene::collide() {
  if (shuffle_seed_ == 0) {
    dSpaceCollide(space_, this, &near_callback);
    return;
  }
  pairs_.clear();
  dSpaceCollide(space_, this, &pair_callback);
  std::mt19937_64 draw(shuffle_seed_ * 0x9e3779b97f4a7c15ull + shuffled_steps_++);
  std::shuffle(pairs_.begin(), pairs_.end(), draw);
  for (const auto& [a, b] : pairs_) (draw() & 1) ? contacts(b, a) : contacts(a, b);
}

void Scene::shuffle_contacts(unsigned long seed) { shuffle_seed_ = seed; }

std::unique_ptr<Scene> Scene::make(std::string_view name, Stepper stepper, unsigned long seed) {
  if (!is_scene(name))
    throw InputError(std::string(name), std::nullopt,
                     "unknown ODE scene (ode-piles, ode-heap, ode-chains)");
  std::unique_ptr<Scene> s(new Scene);
  s->name_ = std::string(name);
  s->stepper_ = stepper;
  dRandSetSeed(seed);
  s->world_ = dWorldCreate();
  dWorldSetGravity(s->world_, 0, 0, -9.81);
  dWorldSetAutoDisableFlag(s->world_, 0);  // every body steps every step: constant work
  // Sweep and prune: Debian's 0.16.2 hash space (dHashSpaceCreate) missed box-box pairs of
  // the stacked piles (upper boxes fell through the lower ones; a simple, quadtree or SAP
  // space finds them), docs/ode.md.
  s->space_ = dSweepAndPruneSpaceCreate(nullptr, dSAP_AXES_XYZ);
  s->contacts_ = dJointGroupCreate(0);
  s->geoms_.push_back(dCreatePlane(s->space_, 0, 0, 1, 0));
  auto box = [&](double x, double y, double z, double sx, double sy, double sz, double angle) {
    dBodyID b = dBodyCreate(s->world_);
    dMass m;
    dMassSetBoxTotal(&m, 1.0, sx, sy, sz);
    dBodySetMass(b, &m);
    dBodySetPosition(b, x, y, z);
    if (angle != 0) {
      dMatrix3 r;
      dRFromAxisAndAngle(r, 0, 0, 1, angle);
      dBodySetRotation(b, r);
    }
    dGeomID g = dCreateBox(s->space_, sx, sy, sz);
    dGeomSetBody(g, b);
    s->bodies_.push_back(b);
    s->geoms_.push_back(g);
    return b;
  };
  if (name == "ode-piles") {
    // 32 piles of 20 boxes (0.5 m): 5 layers of 2 x 2, 3 m apart on an 8 x 4 grid.
    const double e = 0.5, gap = 0.02;
    s->length_ = e;
    for (int px = 0; px < 8; ++px)
      for (int py = 0; py < 4; ++py)
        for (int layer = 0; layer < 5; ++layer)
          for (int i = 0; i < 4; ++i) {
            const double x = px * 3.0 + (i % 2) * (e + gap);
            const double y = py * 3.0 + (i / 2) * (e + gap);
            const double z = e / 2 + gap + layer * (e + gap);
            box(x, y, z, e, e, e, 0);
          }
  } else if (name == "ode-heap") {
    // 288 boxes (0.3 m) dropped in 8 layers of 6 x 6 (2 cm apart), every other layer
    // shifted by a third of a box (bricks), into a 3 m x 3 m bin with 1.5 m walls.
    const double e = 0.3, side = 3.0, wall = 0.2, height = 1.5, pitch = e + 0.02;
    s->length_ = e;
    for (int k = 0; k < 4; ++k) {
      const double off = side / 2 + wall / 2;
      const bool along_x = k < 2;
      const double sign = k % 2 ? 1.0 : -1.0;
      dGeomID w = dCreateBox(s->space_, along_x ? side + 2 * wall : wall,
                             along_x ? wall : side + 2 * wall, height);
      dGeomSetPosition(w, along_x ? 0 : sign * off, along_x ? sign * off : 0, height / 2);
      s->geoms_.push_back(w);
    }
    for (int layer = 0; layer < 8; ++layer)
      for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j) {
          const double shift = (layer % 2) * 0.1;
          box(-0.8 + i * pitch + shift, -0.8 + j * pitch - shift, e / 2 + 0.02 + layer * pitch, e,
              e, e, 0);
        }
  } else {
    // ode-chains: 24 chains of 16 hinged links (0.15 m), hung from 3 m, starting horizontal.
    const double len = 0.15, w = 0.05, top = 3.0;
    s->length_ = len;
    s->skip_connected_ = true;
    for (int c = 0; c < 24; ++c) {
      const double y = (c % 6) * 0.6, x0 = (c / 6) * 3.0;
      dBodyID prev = nullptr;
      for (int k = 0; k < 16; ++k) {
        dBodyID b = box(x0 + len / 2 + k * len, y, top, len, w, w, 0);
        dJointID h = dJointCreateHinge(s->world_, nullptr);
        dJointAttach(h, b, prev);  // the first link hinged to the world
        dJointSetHingeAnchor(h, x0 + k * len, y, top);
        dJointSetHingeAxis(h, 0, 1, 0);
        s->hinges_.push_back(h);
        prev = b;
      }
    }
  }
  return s;
}

Scene::~Scene() {
  if (contacts_) dJointGroupDestroy(contacts_);
  if (space_) dSpaceDestroy(space_);  // destroys its geoms
  if (world_) dWorldDestroy(world_);  // and its bodies and joints
}

StepTime Scene::step(Attachment* attach) {
  StepTime t;
  if (attach) {
    const std::int64_t before = attach->stats().collide_ns;
    attach->collide(space_, this, &near_callback);
    t.collide_ns = attach->stats().collide_ns - before;
    const std::int64_t w0 = now_ns();
    attach->world_step(stepper_, kDt);
    t.world_ns = now_ns() - w0;
  } else {
    const std::int64_t c0 = now_ns();
    collide();
    const std::int64_t c1 = now_ns();
    if (stepper_ == Stepper::kQuickStep)
      dWorldQuickStep(world_, kDt);
    else
      dWorldStep(world_, kDt);
    t.collide_ns = c1 - c0;
    t.world_ns = now_ns() - c1;
  }
  dJointGroupEmpty(contacts_);
  return t;
}

void Scene::nudge(double dx) {
  for (dBodyID b : bodies_) {
    const dReal* p = dBodyGetPosition(b);
    dBodySetPosition(b, p[0] + dx, p[1], p[2]);
  }
}

std::vector<double> Scene::state() const {
  std::vector<double> s;
  s.reserve(bodies_.size() * 13);
  for (dBodyID b : bodies_) {
    for (const dReal* v : {dBodyGetPosition(b), dBodyGetQuaternion(b), dBodyGetLinearVel(b),
                           dBodyGetAngularVel(b)}) {
      const int n = v == dBodyGetQuaternion(b) ? 4 : 3;
      for (int i = 0; i < n; ++i) s.push_back(v[i]);
    }
  }
  return s;
}

double Scene::depth_below_floor() const {
  double depth = -1e300;
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    dVector3 sides;
    dGeomBoxGetLengths(dBodyGetFirstGeom(bodies_[i]), sides);
    for (int corner = 0; corner < 8; ++corner) {
      dVector3 p;
      dBodyGetRelPointPos(bodies_[i], (corner & 1 ? 0.5 : -0.5) * sides[0],
                          (corner & 2 ? 0.5 : -0.5) * sides[1],
                          (corner & 4 ? 0.5 : -0.5) * sides[2], p);
      depth = std::max(depth, -static_cast<double>(p[2]));
    }
  }
  return depth;
}

double Scene::max_speed() const {
  double v = 0;
  for (dBodyID b : bodies_) {
    const dReal* l = dBodyGetLinearVel(b);
    v = std::max(v, std::sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]));
  }
  return v;
}

double Scene::rms_speed() const {
  double sum = 0;
  for (dBodyID b : bodies_) {
    const dReal* l = dBodyGetLinearVel(b);
    sum += l[0] * l[0] + l[1] * l[1] + l[2] * l[2];
  }
  return bodies_.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(bodies_.size()));
}

double Scene::max_angular_speed() const {
  double v = 0;
  for (dBodyID b : bodies_) {
    const dReal* a = dBodyGetAngularVel(b);
    v = std::max(v, std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]));
  }
  return v;
}

double Scene::max_joint_error() const {
  double e = 0;
  for (dJointID h : hinges_) {
    dVector3 a, b;
    dJointGetHingeAnchor(h, a);
    dJointGetHingeAnchor2(h, b);
    const double d = std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                               (a[2] - b[2]) * (a[2] - b[2]));
    e = std::max(e, d / length_);
  }
  return e;
}

}  // namespace tgraph::ode
