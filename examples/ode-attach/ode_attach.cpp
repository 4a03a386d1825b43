// SPDX-License-Identifier: MIT
// An ODE program of its own (towers of boxes and a few balls thrown at them, on a ground
// plane) stepped with dWorldQuickStep, then the same program through tgraph's threading:
// the lines marked "tgraph" are all it takes (docs/ode.md, "Attach an existing program").
//
//   ode_attach STEPS --threads K [--method M] --json
//
// prints one JSON object: check (the final state against ODE self-threaded: "identical",
// "within-tolerance" when no body is further from it than five times the farthest one moves
// with either of two other seeds of ODE's random constraint reordering, else "differs", exit 1
// with a line; docs/ode.md, "The check", has the factor's measured false alarms), speedup
// (ODE self-threaded's time over
// tgraph's, the whole step), threads, method, steps and the times.
#include <ode/ode.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "tgraph/ode/attach.hpp"  // tgraph

namespace {

struct World {
  dWorldID world = nullptr;
  dSpaceID space = nullptr;
  dJointGroupID contacts = nullptr;
  std::vector<dBodyID> bodies;
};

void near_callback(void* data, dGeomID a, dGeomID b) {
  auto* w = static_cast<World*>(data);
  dBodyID ba = dGeomGetBody(a), bb = dGeomGetBody(b);
  dContact c[4] = {};
  const int n = dCollide(a, b, 4, &c[0].geom, sizeof(dContact));
  for (int i = 0; i < n; ++i) {
    c[i].surface.mode = dContactApprox1 | dContactSoftERP;
    c[i].surface.mu = 0.6;
    c[i].surface.soft_erp = 0.4;
    dJointAttach(dJointCreateContact(w->world, w->contacts, &c[i]), ba, bb);
  }
}

World make_world() {
  World w;
  w.world = dWorldCreate();
  dWorldSetGravity(w.world, 0, 0, -9.81);
  w.space = dSweepAndPruneSpaceCreate(nullptr, dSAP_AXES_XYZ);
  w.contacts = dJointGroupCreate(0);
  dCreatePlane(w.space, 0, 0, 1, 0);
  auto body = [&](dGeomID g, dReal x, dReal y, dReal z, dMass& m) {
    dBodyID b = dBodyCreate(w.world);
    dBodySetMass(b, &m);
    dBodySetPosition(b, x, y, z);
    dGeomSetBody(g, b);
    w.bodies.push_back(b);
    return b;
  };
  for (int t = 0; t < 24; ++t)  // 24 towers of 8 boxes, 4 m apart
    for (int k = 0; k < 8; ++k) {
      dMass m;
      dMassSetBoxTotal(&m, 2.0, 0.4, 0.4, 0.4);
      body(dCreateBox(w.space, 0.4, 0.4, 0.4), (t % 6) * 4.0, (t / 6) * 4.0, 0.21 + k * 0.41, m);
    }
  for (int t = 0; t < 24; t += 5) {  // a ball thrown at some of them
    dMass m;
    dMassSetSphereTotal(&m, 5.0, 0.25);
    dBodyID b = body(dCreateSphere(w.space, 0.25), (t % 6) * 4.0 - 2.0, (t / 6) * 4.0, 1.2, m);
    dBodySetLinearVel(b, 6.0, 0, 1.0);
  }
  return w;
}

void destroy(World& w) {
  dJointGroupDestroy(w.contacts);
  dSpaceDestroy(w.space);
  dWorldDestroy(w.world);
}

std::vector<double> positions(const World& w) {
  std::vector<double> p;
  for (dBodyID b : w.bodies) p.insert(p.end(), dBodyGetPosition(b), dBodyGetPosition(b) + 3);
  return p;
}

double max_diff(const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double e = std::abs(a[i] - b[i]);  // NaN: a blown-up body, infinitely far
    d = std::isnan(e) ? std::numeric_limits<double>::infinity() : std::max(d, e);
  }
  return d;
}

// Steps the world: ODE alone when `method` is empty, else through tgraph, ODE's random numbers
// (its constraint reordering draws them) seeded with `seed`. Returns ns.
std::int64_t run(World& w, int steps, const std::string& method, unsigned threads,
                 unsigned long seed) {
  dRandSetSeed(seed);
  const auto t0 = std::chrono::steady_clock::now();
  if (method.empty()) {
    for (int i = 0; i < steps; ++i) {
      dSpaceCollide(w.space, &w, &near_callback);
      dWorldQuickStep(w.world, 0.005);
      dJointGroupEmpty(w.contacts);
    }
  } else {
    tgraph::ode::AttachOptions options;                   // tgraph
    options.method = tgraph::ode::choose_method(method);  // tgraph
    options.threads = threads;                            // tgraph
    tgraph::ode::Attachment attach(w.world, options);     // tgraph
    for (int i = 0; i < steps; ++i) {
      attach.collide(w.space, &w, &near_callback);  // tgraph: was dSpaceCollide
      attach.quick_step(0.005);                     // tgraph: was dWorldQuickStep
      dJointGroupEmpty(w.contacts);
    }
  }
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - t0)
      .count();
}

int usage() {
  std::fprintf(stderr, "usage: ode_attach STEPS --threads K [--method M] --json\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) return usage();
  const int steps = std::atoi(argv[1]);
  unsigned threads = 2;
  std::string method = "islands-serial";
  bool json = false;
  for (int i = 2; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--threads") && i + 1 < argc) {
      threads = static_cast<unsigned>(std::atoi(argv[++i]));
    } else if (!std::strcmp(argv[i], "--method") && i + 1 < argc) {
      method = argv[++i];
    } else if (!std::strcmp(argv[i], "--json")) {
      json = true;
    } else {
      return usage();
    }
  }
  if (steps <= 0) return usage();
  dInitODE2(0);
  try {
    World ref = make_world(), other1 = make_world(), other2 = make_world(), mine = make_world();
    const std::int64_t sequential_ns = run(ref, steps, "", threads, 0);
    run(other1, steps, "", threads, 1);
    run(other2, steps, "", threads, 2);
    const std::int64_t ns = run(mine, steps, method, threads, 0);
    const std::vector<double> p_ref = positions(ref), p_mine = positions(mine);
    const double diff = max_diff(p_mine, p_ref);
    // Five times the seeds' spread, as tgraph's own check (docs/ode.md, "The check").
    const double tolerance =
        5.0 * std::max(max_diff(positions(other1), p_ref), max_diff(positions(other2), p_ref));
    const char* check = diff == 0           ? "identical"
                        : diff <= tolerance ? "within-tolerance"
                                            : "differs";
    const double speedup = static_cast<double>(sequential_ns) / static_cast<double>(ns);
    if (json)
      std::printf(
          "{\"check\":\"%s\",\"speedup\":%.4f,\"threads\":%u,\"method\":\"%s\",\"steps\":%d,"
          "\"wall_ns\":%lld,\"sequential_wall_ns\":%lld,\"max_abs_diff\":%.6g,\"tolerance\":%.6g}"
          "\n",
          check, speedup, threads, method.c_str(), steps, static_cast<long long>(ns),
          static_cast<long long>(sequential_ns), diff, tolerance);
    else
      std::printf(
          "%d steps: %s at %u threads %.3f s, ODE self-threaded %.3f s: speed-up %.2f; check %s\n",
          steps, method.c_str(), threads, static_cast<double>(ns) / 1e9,
          static_cast<double>(sequential_ns) / 1e9, speedup, check);
    for (World* w : {&ref, &other1, &other2, &mine}) destroy(*w);
    dCloseODE();
    if (std::string(check) != "differs") return 0;
    std::fprintf(stderr,
                 "ode_attach: %s at %u threads differs from ODE self-threaded: a body %.6g m "
                 "away, tolerance %.6g m\n",
                 method.c_str(), threads, diff, tolerance);
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ode_attach: %s\n", e.what());
    return 2;
  }
}
