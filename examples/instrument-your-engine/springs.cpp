// SPDX-License-Identifier: MIT
// A small engine instrumented with tgraph's capture API as docs/instrumenting.md shows: a
// cloth made of sub-sheets of particles joined by springs, neighbouring sub-sheets sewn
// together by seams of springs, explicit Euler, then a few iterations of spring-length
// projection until the residual is small (a dynamic loop). One task is one component method
// on one sub-sheet (or one seam), so a step has a few dozen tasks of tens of microseconds.
// It writes one trace frame per step, reads the trace back and checks what it must contain;
// with --live it also runs its steps on K threads through tgraph's executor, checks the
// state bit for bit against the sequential engine and prints the result (`tgraph run`'s).
//
//   springs STEPS OUT.tgt [--live K [--method M] [--repeat R] [--json] [--verify-accesses]]
//   (exit 0: trace written and checked, live state identical; 1: a check failed; 2: usage)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>
#include <string>
#include <vector>

#include "tgraph/capture/recorder.hpp"
#include "tgraph/graph/cumulative.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/trace_io.hpp"
#ifdef SPRINGS_LIVE
#include "tgraph/measure/adapter.hpp"
#include "tgraph/measure/verify.hpp"
#endif

namespace {

using tgraph::AccessMode;
using tgraph::DatumId;
using tgraph::KindId;
using tgraph::ObjectId;
using tgraph::capture::Recorder;

constexpr int kSheetsX = 4, kSheetsY = 2;  // sub-sheets across and down
constexpr int kSide = 48;                  // kSide x kSide particles per sub-sheet
constexpr int kMaxIterations = 12;         // of the projection loop
constexpr double kDt = 4e-3, kStiffness = 20.0, kDamping = 0.05, kRest = 0.1, kMass = 0.01;

// The engine's own state and component methods: it knows nothing about tgraph.
struct Vec2 {
  double x = 0, y = 0;
};
struct Sheet {
  std::string name;
  std::vector<Vec2> x, v, f, delta;
  std::vector<char> pinned;

  void reset_force() {
    for (Vec2& fi : f) fi = {0, -9.81 * kMass};
  }
  void integrate() {
    for (std::size_t i = 0; i < x.size(); ++i) {
      if (pinned[i]) continue;
      x[i].x += kDt * v[i].x, x[i].y += kDt * v[i].y;
      v[i].x += kDt * f[i].x / kMass, v[i].y += kDt * f[i].y / kMass;
    }
  }
  void clear_delta() { std::fill(delta.begin(), delta.end(), Vec2{}); }
  void apply_delta() {  // position-based correction: the velocity follows the position
    for (std::size_t i = 0; i < x.size(); ++i) {
      if (pinned[i]) continue;
      x[i].x += delta[i].x, x[i].y += delta[i].y;
      v[i].x += delta[i].x / kDt, v[i].y += delta[i].y / kDt;
    }
  }
};
// Springs from particles of sheet `sa` to particles of sheet `sb`: a sub-sheet's own springs
// (sa == sb) or a seam between two neighbours.
struct SpringSet {
  struct Spring {
    int a = 0, b = 0;
  };
  std::string name;
  int sa = 0, sb = 0;
  std::vector<Spring> springs;

  void add_force(const Sheet& A, const Sheet& B, std::vector<Vec2>& fa,
                 std::vector<Vec2>& fb) const {
    for (const Spring& s : springs) {
      const double dx = B.x[s.b].x - A.x[s.a].x, dy = B.x[s.b].y - A.x[s.a].y;
      const double len = std::max(std::sqrt(dx * dx + dy * dy), 1e-12);
      const double rel = ((B.v[s.b].x - A.v[s.a].x) * dx + (B.v[s.b].y - A.v[s.a].y) * dy) / len;
      const double k = (kStiffness * (len - kRest) + kDamping * rel) / len;
      fa[s.a].x += k * dx, fa[s.a].y += k * dy;
      fb[s.b].x -= k * dx, fb[s.b].y -= k * dy;
    }
  }
  double project(const Sheet& A, const Sheet& B, std::vector<Vec2>& da,
                 std::vector<Vec2>& db) const {  // Jacobi: a quarter of the error to each end
    double residual = 0;
    for (const Spring& s : springs) {
      const double dx = B.x[s.b].x - A.x[s.a].x, dy = B.x[s.b].y - A.x[s.a].y;
      const double len = std::max(std::sqrt(dx * dx + dy * dy), 1e-12), err = len - 1.02 * kRest;
      if (err <= 0) continue;  // only over-stretched springs are corrected
      da[s.a].x += 0.25 * err * dx / len, da[s.a].y += 0.25 * err * dy / len;
      db[s.b].x -= 0.25 * err * dx / len, db[s.b].y -= 0.25 * err * dy / len;
      residual += err;
    }
    return residual;
  }
};

struct Engine {
  std::vector<Sheet> sheets;  // sheet (cx, cy) at cy * kSheetsX + cx
  std::vector<SpringSet> sets;
  double residual = 0;
  bool converged = false;

  Engine() {
    const auto at = [](int i, int j) { return j * kSide + i; };
    for (int cy = 0; cy < kSheetsY; ++cy)
      for (int cx = 0; cx < kSheetsX; ++cx) {
        Sheet s;
        s.name = "sheet" + std::to_string(cx) + "_" + std::to_string(cy);
        for (int j = 0; j < kSide; ++j)
          for (int i = 0; i < kSide; ++i) {
            s.x.push_back({kRest * (cx * kSide + i), -kRest * (cy * kSide + j)});
            s.pinned.push_back(cy == 0 && j == 0);  // the top row hangs
          }
        s.v = s.f = s.delta = std::vector<Vec2>(s.x.size());
        sheets.push_back(std::move(s));
        const int me = cy * kSheetsX + cx;
        SpringSet own{sheets.back().name + ".springs", me, me, {}};
        for (int j = 0; j < kSide; ++j)
          for (int i = 0; i < kSide; ++i) {
            if (i + 1 < kSide) own.springs.push_back({at(i, j), at(i + 1, j)});
            if (j + 1 < kSide) own.springs.push_back({at(i, j), at(i, j + 1)});
          }
        sets.push_back(std::move(own));
      }
    for (int cy = 0; cy < kSheetsY; ++cy)  // seams: right edge to left edge, bottom to top
      for (int cx = 0; cx < kSheetsX; ++cx) {
        const int me = cy * kSheetsX + cx;
        if (cx + 1 < kSheetsX) {
          SpringSet seam{
              "seam[" + sheets[me].name + "|" + sheets[me + 1].name + "]", me, me + 1, {}};
          for (int j = 0; j < kSide; ++j) seam.springs.push_back({at(kSide - 1, j), at(0, j)});
          sets.push_back(std::move(seam));
        }
        if (cy + 1 < kSheetsY) {
          const int below = me + kSheetsX;
          SpringSet seam{"seam[" + sheets[me].name + "|" + sheets[below].name + "]", me, below, {}};
          for (int i = 0; i < kSide; ++i) seam.springs.push_back({at(i, kSide - 1), at(i, 0)});
          sets.push_back(std::move(seam));
        }
      }
  }
};

// How an executor gives a cumulative writer running on another thread its own zeroed forces
// and adds them back (tgraph::accumulate in the bodies below).
tgraph::Accumulator vec2_accumulator(std::vector<Vec2>& v) {
  tgraph::Accumulator a;
  a.target = &v;
  a.make_zero = [n = v.size()] {
    return std::shared_ptr<void>(std::make_shared<std::vector<Vec2>>(n));
  };
  a.add_and_clear = [](void* target, void* temp) {
    auto& t = *static_cast<std::vector<Vec2>*>(target);
    auto& s = *static_cast<std::vector<Vec2>*>(temp);
    for (std::size_t i = 0; i < t.size(); ++i) t[i].x += s[i].x, t[i].y += s[i].y, s[i] = {};
  };
  return a;
}

// The instrumentation: ids declared once on a recorder, one task per component-method call.
// The same code captures (Mode::kCapture), records for a live run (kDeferred) or runs the
// engine plainly (kOff).
struct Instrumented {
  Engine e;
  struct Ids {
    ObjectId obj;
    DatumId x, v, f, delta;
  };
  std::vector<Ids> ids;  // by sheet
  std::vector<ObjectId> set_obj;
  ObjectId solver = 0;
  DatumId residual = 0, converged = 0;
  KindId reset = 0, spring_force = 0, integrate = 0, clear_delta = 0, project = 0, apply_delta = 0,
         check = 0;

  void declare(Recorder& rec) {
    reset = rec.kind("resetForce");
    spring_force = rec.kind("addForce");
    integrate = rec.kind("integrateExplicitEuler");
    clear_delta = rec.kind("clearDelta");
    project = rec.kind("projectLength");
    apply_delta = rec.kind("applyDelta");
    check = rec.kind("checkResidual");
    for (Sheet& s : e.sheets) {
      const ObjectId o = rec.object(s.name);
      const std::uint64_t bytes = s.x.size() * sizeof(Vec2);
      ids.push_back({o, rec.datum(s.name + ".x", o, bytes, s.x.data()),
                     rec.datum(s.name + ".v", o, bytes, s.v.data()),
                     rec.datum(s.name + ".f", o, bytes, s.f.data()),
                     rec.datum(s.name + ".delta", o, bytes, s.delta.data())});
      rec.accumulator(ids.back().f, vec2_accumulator(s.f));
      rec.accumulator(ids.back().delta, vec2_accumulator(s.delta));
    }
    for (const SpringSet& s : e.sets) set_obj.push_back(rec.object(s.name));
    solver = rec.object("solver");
    residual = rec.datum("solver.residual", solver, sizeof(double), &e.residual);
    converged = rec.datum("solver.converged", solver, sizeof(bool), &e.converged);
    rec.accumulator(residual, tgraph::make_accumulator(e.residual));
  }

  // One step's tasks (between rec.begin_step() and the step's end).
  void issue(Recorder& rec) {
    Engine* en = &e;
    for (std::size_t i = 0; i < ids.size(); ++i)
      rec.task(reset, ids[i].obj, {{ids[i].f, AccessMode::W}},
               [en, i] { en->sheets[i].reset_force(); });
    for (std::size_t s = 0; s < e.sets.size(); ++s) {
      const Ids &a = ids[e.sets[s].sa], &b = ids[e.sets[s].sb];
      rec.task(spring_force, set_obj[s],
               {{a.x, AccessMode::R},
                {b.x, AccessMode::R},
                {a.v, AccessMode::R},
                {b.v, AccessMode::R},
                {a.f, AccessMode::CW},
                {b.f, AccessMode::CW}},
               [en, s] {
                 const SpringSet& set = en->sets[s];
                 Sheet &A = en->sheets[set.sa], &B = en->sheets[set.sb];
                 set.add_force(A, B, tgraph::accumulate(A.f), tgraph::accumulate(B.f));
               });
    }
    for (std::size_t i = 0; i < ids.size(); ++i)
      rec.task(integrate, ids[i].obj,
               {{ids[i].f, AccessMode::R}, {ids[i].v, AccessMode::RW}, {ids[i].x, AccessMode::RW}},
               [en, i] { en->sheets[i].integrate(); });
    // Dynamic loop: project spring lengths until the residual is small.
    const tgraph::LoopId loop = rec.begin_loop(converged, kMaxIterations);
    do {
      for (std::size_t i = 0; i < ids.size(); ++i)
        rec.task(clear_delta, ids[i].obj, {{ids[i].delta, AccessMode::W}},
                 [en, i] { en->sheets[i].clear_delta(); });
      for (std::size_t s = 0; s < e.sets.size(); ++s) {
        const Ids &a = ids[e.sets[s].sa], &b = ids[e.sets[s].sb];
        rec.task(project, set_obj[s],
                 {{a.x, AccessMode::R},
                  {b.x, AccessMode::R},
                  {a.delta, AccessMode::CW},
                  {b.delta, AccessMode::CW},
                  {residual, AccessMode::CW}},
                 [en, s] {
                   const SpringSet& set = en->sets[s];
                   Sheet &A = en->sheets[set.sa], &B = en->sheets[set.sb];
                   tgraph::accumulate(en->residual) +=
                       set.project(A, B, tgraph::accumulate(A.delta), tgraph::accumulate(B.delta));
                 });
      }
      for (std::size_t i = 0; i < ids.size(); ++i)
        rec.task(
            apply_delta, ids[i].obj,
            {{ids[i].delta, AccessMode::R}, {ids[i].x, AccessMode::RW}, {ids[i].v, AccessMode::RW}},
            [en, i] { en->sheets[i].apply_delta(); });
      rec.task(check, solver, {{residual, AccessMode::RW}, {converged, AccessMode::W}}, [en] {
        en->converged = en->residual < 1e-5 * kSide * kSide;
        en->residual = 0;
      });
    } while (!rec.conditional_break(loop, [en] { return en->converged; }));
    rec.end_loop(loop);
  }
};

int fail(const std::string& what) {
  std::fprintf(stderr, "springs: check failed: %s\n", what.c_str());
  return 1;
}

// Captures `steps` steps into `out`, reads the trace back and checks it.
int capture(int steps, const std::string& out, bool quiet) {
  Instrumented inst;
  Recorder rec(tgraph::capture::Mode::kCapture);
  inst.declare(rec);
  const std::string scene = "springs " + std::to_string(kSheetsX) + "x" + std::to_string(kSheetsY) +
                            " sheets of " + std::to_string(kSide) + "x" + std::to_string(kSide);
  tgraph::TraceHeader header{scene, "instrument-your-engine (explicit Euler)", "unknown",
                             TGRAPH_PACKAGE_VERSION};
  tgraph::TraceWriter writer(out, header);
  std::vector<std::uint32_t> iterations;
  for (int s = 0; s < steps; ++s) {
    rec.begin_step();
    inst.issue(rec);
    const tgraph::StepGraph g = rec.end_step();
    iterations.push_back(g.loops.at(0).iterations);
    writer.append(g);
  }
  writer.close();
  if (rec.errors() != 0) return fail("the recorder counted API misuses");
  for (const Sheet& s : inst.e.sheets)
    for (const Vec2& x : s.x)
      if (!std::isfinite(x.x) || !std::isfinite(x.y)) return fail(s.name + ": not finite");

  // Read back and check: every step has the same structure, the expected tasks and loop.
  const tgraph::Trace t = tgraph::read_trace(out);
  const std::size_t sheets = inst.e.sheets.size(), sets = inst.e.sets.size();
  const std::size_t tasks = 4 * sheets + 2 * sets + 2;  // + checkResidual + loop.break
  if (t.steps.size() != static_cast<std::size_t>(steps)) return fail("step count");
  for (std::size_t s = 0; s < t.steps.size(); ++s) {
    const tgraph::StepGraph& g = t.steps[s];
    if (g.tasks.size() != tasks) return fail("step " + std::to_string(s) + ": task count");
    if (g.loops.size() != 1 || g.loops[0].iterations != iterations[s])
      return fail("step " + std::to_string(s) + ": loop iterations");
    if (!g.same_structure(t.steps[0])) return fail("step " + std::to_string(s) + ": structure");
    // addForce writes the sheets' f (CW); integrate reads it: a RAW edge from each spring
    // set into the integrate task of each sheet it touches (one for a sheet's own springs,
    // two for a seam).
    std::size_t raw_into_integrate = 0;
    for (const tgraph::Edge& edge : g.edges)
      if (edge.kind == tgraph::EdgeKind::RAW && g.kind_name(edge.from) == "addForce" &&
          g.kind_name(edge.to) == "integrateExplicitEuler")
        ++raw_into_integrate;
    if (raw_into_integrate != sheets + 2 * (sets - sheets))
      return fail("addForce -> integrate edges");
  }
  std::fprintf(quiet ? stderr : stdout,
               "springs: %d steps, %zu tasks per step, loop iterations %u..%u -> %s\n", steps,
               tasks, *std::min_element(iterations.begin(), iterations.end()),
               *std::max_element(iterations.begin(), iterations.end()), out.c_str());
  return 0;
}

#ifdef SPRINGS_LIVE
// The live run: what connects the engine to tgraph's executor (docs/instrumenting.md,
// "Run it live").
int run_live(int steps, int threads, const std::string& method, int repeat, bool json, bool verify) {
  namespace tm = tgraph::measure;
  const tm::CallbacksFactory make = [] {
    auto inst = std::make_shared<Instrumented>();  // a fresh engine for every pass
    tm::EngineCallbacks c;
    c.declare = [inst](Recorder& rec) { inst->declare(rec); };
    c.step = [inst](Recorder& rec) { inst->issue(rec); };
    c.same_every_step = true;  // same tasks each step; the bodies reach the state by pointer
    return c;
  };
  tm::LiveOptions o;
  o.exec.threads = static_cast<std::uint32_t>(threads);
  o.steps = static_cast<std::uint32_t>(steps);
  o.repeat = static_cast<std::uint32_t>(repeat);
  o.check = true;  // the final state against a sequential run, bit for bit
  const tm::MethodChoice choice = tm::choose_method(method);
  if (verify) {  // every task between checksums of the state (docs/instrumenting.md, 9)
    const tm::VerifyResult v = tm::verify_engine_accesses(make, choice, o);
    const std::string m = tm::method_name(choice);
    std::printf("%s\n", json ? tm::verify_json(v, "springs", m).c_str()
                             : tm::verify_text(v, "springs", m).c_str());
    if (!v.findings.empty()) return fail(std::to_string(v.findings.size()) + " wrong declaration(s)");
    return 0;
  }
  const tm::LiveResult r = tm::run_engine_live(make, choice, o);
  const std::string name = tm::method_name(choice);
  std::printf("%s\n", json ? tm::to_json(r, "springs", name).c_str()
                           : tm::to_text(r, "springs", name, o.repeat).c_str());
  if (r.difference) return fail("live state differs: " + tm::to_string(*r.difference));
  return 0;
}
#endif

int usage(const char* why) {
  std::fprintf(stderr,
               "springs: %s (usage: springs STEPS OUT.tgt [--live K [--method M] [--repeat R] "
               "[--json] [--verify-accesses]])\n",
               why);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3 || std::atoi(argv[1]) < 1) return usage("STEPS (>= 1) and OUT.tgt are required");
  const int steps = std::atoi(argv[1]);
  const std::string out = argv[2];
  int threads = 0, repeat = 3;
  std::string method = "owner";
  bool json = false, verify = false;
  for (int i = 3; i < argc; ++i) {
    const std::string flag = argv[i];
    if (flag == "--json") {
      json = true;
    } else if (flag == "--verify-accesses") {
      verify = true;
    } else if ((flag == "--live" || flag == "--method" || flag == "--repeat") && i + 1 < argc) {
      const std::string value = argv[++i];
      if (flag == "--method") {
        method = value;
        continue;
      }
      const int n = std::atoi(value.c_str());
      if (n < 1) return usage((flag + " " + value + ": a positive number is required").c_str());
      (flag == "--live" ? threads : repeat) = n;
    } else {
      return usage(("unknown or incomplete flag " + flag).c_str());
    }
  }
#ifndef SPRINGS_LIVE
  if (threads > 0) return usage("--live: built without tgraph::measure (find_package component)");
#endif
  try {
    if (const int rc = capture(steps, out, json); rc != 0 || threads == 0) return rc;
#ifdef SPRINGS_LIVE
    return run_live(steps, threads, method, repeat, json, verify);
#endif
  } catch (const tgraph::UsageError& e) {
    return usage(e.what());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "springs: %s\n", e.what());
    return 1;
  }
  return 0;
}
