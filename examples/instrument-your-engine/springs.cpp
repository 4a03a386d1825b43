// SPDX-License-Identifier: MIT
// A small engine instrumented with tgraph's capture API as docs/instrumenting.md shows: a
// square sheet of particles joined by springs, explicit Euler, then a few iterations of
// spring-length projection until the residual is small (a dynamic loop). It writes one
// trace frame per step, reads the trace back and checks what it must contain.
//
//   springs STEPS OUT.tgt      (exit 0: trace written and checked; 1: check failed; 2: usage)
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "tgraph/capture/recorder.hpp"
#include "tgraph/graph/trace_io.hpp"

namespace {

using tgraph::AccessMode;
using tgraph::DatumId;
using tgraph::KindId;
using tgraph::ObjectId;

constexpr int kSide = 4;  // kSide x kSide particles
constexpr int kParticles = kSide * kSide;
constexpr double kDt = 4e-3, kStiffness = 20.0, kDamping = 0.05, kRest = 0.1;

// The engine's own state: it knows nothing about tgraph.
struct Vec2 {
  double x = 0, y = 0;
};
struct Particle {
  std::string name;
  Vec2 x, v, f, delta;
  double mass = 0.01;
  bool pinned = false;
};
struct Spring {
  std::string name;
  int a = 0, b = 0;
  // Component methods, unchanged by the instrumentation.
  void add_force(std::vector<Particle>& p) const {
    const double dx = p[b].x.x - p[a].x.x, dy = p[b].x.y - p[a].x.y;
    const double len = std::max(std::hypot(dx, dy), 1e-12);
    const double rel = (p[b].v.x - p[a].v.x) * dx / len + (p[b].v.y - p[a].v.y) * dy / len;
    const double s = kStiffness * (len - kRest) + kDamping * rel;
    p[a].f.x += s * dx / len, p[a].f.y += s * dy / len;
    p[b].f.x -= s * dx / len, p[b].f.y -= s * dy / len;
  }
  double project(std::vector<Particle>& p) const {  // Jacobi: half the error to each end
    const double dx = p[b].x.x - p[a].x.x, dy = p[b].x.y - p[a].x.y;
    const double len = std::max(std::hypot(dx, dy), 1e-12), err = len - 1.02 * kRest;
    if (err <= 0) return 0;  // only over-stretched springs are corrected
    p[a].delta.x += 0.25 * err * dx / len, p[a].delta.y += 0.25 * err * dy / len;
    p[b].delta.x -= 0.25 * err * dx / len, p[b].delta.y -= 0.25 * err * dy / len;
    return err;
  }
};

struct Engine {
  std::vector<Particle> particles;
  std::vector<Spring> springs;
  double residual = 0;
  bool converged = false;

  Engine() {
    for (int i = 0; i < kParticles; ++i) {
      Particle p;
      p.name = "p" + std::to_string(i);
      p.x = {kRest * (i % kSide), -kRest * (i / kSide)};
      p.pinned = i < kSide;  // the top row hangs
      particles.push_back(p);
    }
    for (int i = 0; i < kParticles; ++i) {
      if (i % kSide + 1 < kSide) springs.push_back({"s" + std::to_string(i) + "r", i, i + 1});
      if (i + kSide < kParticles) springs.push_back({"s" + std::to_string(i) + "d", i, i + kSide});
    }
  }
};

// The instrumentation: ids declared once, one task per component-method call.
struct Instrumented {
  tgraph::capture::Recorder rec{tgraph::capture::Mode::kCapture};
  Engine& e;
  struct Ids {
    ObjectId obj;
    DatumId x, v, f, delta;
  };
  std::vector<Ids> ids;
  std::vector<ObjectId> spring_obj;
  ObjectId solver;
  DatumId residual, converged;
  KindId reset, spring_force, integrate, clear_delta, project, apply_delta, check;

  explicit Instrumented(Engine& engine) : e(engine) {
    reset = rec.kind("resetForce");
    spring_force = rec.kind("addForce");
    integrate = rec.kind("integrateExplicitEuler");
    clear_delta = rec.kind("clearDelta");
    project = rec.kind("projectLength");
    apply_delta = rec.kind("applyDelta");
    check = rec.kind("checkResidual");
    constexpr std::uint64_t kVec = sizeof(Vec2);
    for (Particle& p : e.particles) {
      const ObjectId o = rec.object(p.name);
      ids.push_back({o, rec.datum(p.name + ".x", o, kVec, &p.x),
                     rec.datum(p.name + ".v", o, kVec, &p.v),
                     rec.datum(p.name + ".f", o, kVec, &p.f),
                     rec.datum(p.name + ".delta", o, kVec, &p.delta)});
    }
    for (const Spring& s : e.springs) spring_obj.push_back(rec.object(s.name));
    solver = rec.object("solver");
    residual = rec.datum("solver.residual", solver, sizeof(double), &e.residual);
    converged = rec.datum("solver.converged", solver, sizeof(bool), &e.converged);
  }

  tgraph::StepGraph step() {
    Engine* en = &e;
    rec.begin_step();
    for (std::size_t i = 0; i < ids.size(); ++i)
      rec.task(reset, ids[i].obj, {{ids[i].f, AccessMode::W}}, [en, i] {
        en->particles[i].f = {0, -9.81 * en->particles[i].mass};
      });
    for (std::size_t s = 0; s < e.springs.size(); ++s) {
      const Ids &a = ids[e.springs[s].a], &b = ids[e.springs[s].b];
      // Any range of accesses works: here an array built at run time.
      const std::array<tgraph::Access, 6> acc = {{{a.x, AccessMode::R},
                                                  {b.x, AccessMode::R},
                                                  {a.v, AccessMode::R},
                                                  {b.v, AccessMode::R},
                                                  {a.f, AccessMode::CW},
                                                  {b.f, AccessMode::CW}}};
      rec.task(spring_force, spring_obj[s], acc,
               [en, s] { en->springs[s].add_force(en->particles); });
    }
    for (std::size_t i = 0; i < ids.size(); ++i)
      rec.task(integrate, ids[i].obj,
               {{ids[i].f, AccessMode::R}, {ids[i].v, AccessMode::RW}, {ids[i].x, AccessMode::RW}},
               [en, i] {
                 Particle& p = en->particles[i];
                 if (p.pinned) return;
                 p.x.x += kDt * p.v.x, p.x.y += kDt * p.v.y;
                 p.v.x += kDt * p.f.x / p.mass, p.v.y += kDt * p.f.y / p.mass;
               });
    // Dynamic loop: project spring lengths until the residual is small (at most 20 times).
    const tgraph::LoopId loop = rec.begin_loop(converged, 20);
    do {
      for (std::size_t i = 0; i < ids.size(); ++i)
        rec.task(clear_delta, ids[i].obj, {{ids[i].delta, AccessMode::W}},
                 [en, i] { en->particles[i].delta = {}; });
      for (std::size_t s = 0; s < e.springs.size(); ++s) {
        const Ids &a = ids[e.springs[s].a], &b = ids[e.springs[s].b];
        std::vector<tgraph::Access> acc = {{a.x, AccessMode::R},
                                           {b.x, AccessMode::R},
                                           {a.delta, AccessMode::CW},
                                           {b.delta, AccessMode::CW},
                                           {residual, AccessMode::CW}};
        rec.task(project, spring_obj[s], acc,
                 [en, s] { en->residual += en->springs[s].project(en->particles); });
      }
      for (std::size_t i = 0; i < ids.size(); ++i)
        rec.task(
            apply_delta, ids[i].obj,
            {{ids[i].delta, AccessMode::R}, {ids[i].x, AccessMode::RW}, {ids[i].v, AccessMode::RW}},
            [en, i] {  // position-based correction: the velocity follows the position
              Particle& p = en->particles[i];
              if (p.pinned) return;
              p.x.x += p.delta.x, p.x.y += p.delta.y;
              p.v.x += p.delta.x / kDt, p.v.y += p.delta.y / kDt;
            });
      rec.task(check, solver, {{residual, AccessMode::RW}, {converged, AccessMode::W}}, [en] {
        en->converged = en->residual < 2e-3;
        en->residual = 0;
      });
    } while (!rec.conditional_break(loop, [en] { return en->converged; }));
    rec.end_loop(loop);
    return rec.end_step();
  }
};

int fail(const std::string& what) {
  std::fprintf(stderr, "springs: check failed: %s\n", what.c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3 || std::atoi(argv[1]) < 1) {
    std::fprintf(stderr, "usage: springs STEPS OUT.tgt\n");
    return 2;
  }
  const int steps = std::atoi(argv[1]);
  const std::string out = argv[2];
  try {
    Engine engine;
    Instrumented inst(engine);
    tgraph::TraceHeader header{"springs 4x4", "instrument-your-engine (explicit Euler)", "unknown",
                               TGRAPH_PACKAGE_VERSION};
    tgraph::TraceWriter writer(out, header);
    std::vector<std::uint32_t> iterations;
    for (int s = 0; s < steps; ++s) {
      const tgraph::StepGraph g = inst.step();
      iterations.push_back(g.loops.at(0).iterations);
      writer.append(g);
    }
    writer.close();
    if (inst.rec.errors() != 0) return fail("the recorder counted API misuses");

    // Read back and check: every step has the same structure, the expected tasks and loop.
    const tgraph::Trace t = tgraph::read_trace(out);
    const std::size_t particles = engine.particles.size(), springs = engine.springs.size();
    const std::size_t tasks = 4 * particles + 2 * springs + 2;  // + check + loop.break
    if (t.steps.size() != static_cast<std::size_t>(steps)) return fail("step count");
    for (std::size_t s = 0; s < t.steps.size(); ++s) {
      const tgraph::StepGraph& g = t.steps[s];
      if (g.tasks.size() != tasks) return fail("step " + std::to_string(s) + ": task count");
      if (g.loops.size() != 1 || g.loops[0].iterations != iterations[s])
        return fail("step " + std::to_string(s) + ": loop iterations");
      if (!g.same_structure(t.steps[0])) return fail("step " + std::to_string(s) + ": structure");
      // addForce writes p.f (CW); integrate reads it: a RAW edge from every spring into both
      // of its particles' integrate tasks.
      std::size_t raw_into_integrate = 0;
      for (const tgraph::Edge& edge : g.edges)
        if (edge.kind == tgraph::EdgeKind::RAW && g.kind_name(edge.from) == "addForce" &&
            g.kind_name(edge.to) == "integrateExplicitEuler")
          ++raw_into_integrate;
      if (raw_into_integrate != 2 * springs) return fail("addForce -> integrate edges");
    }
    std::printf("springs: %d steps, %zu tasks per step, loop iterations %u..%u -> %s\n", steps,
                tasks, *std::min_element(iterations.begin(), iterations.end()),
                *std::max_element(iterations.begin(), iterations.end()), out.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "springs: %s\n", e.what());
    return 1;
  }
  return 0;
}
