// SPDX-License-Identifier: MIT
// A tiled dense LU factorisation without pivoting (right-looking, as in PLASMA or StarPU's
// examples), instrumented with tgraph's capture API as docs/instrumenting.md shows. Not a
// physics engine: there are no objects, only tiles. Each step fills every tile with a fresh
// matrix (one FILL task per tile) that is diagonally dominant by rows and columns (so no
// pivoting is needed and LAPACK's partial pivoting swaps no rows), then factorises it: per
// k, GETRF on tile (k,k); TRSM on the tiles (i,k) and (k,j) below and right of it; GEMM
// updating every tile (i,j), i,j > k. It checks ||A - LU||_F / ||A||_F after each step and
// appends the step's graph to a .tgt trace; with --live it also runs its steps' kernels on K
// threads through tgraph's executor, checks the factors bit for bit against the sequential
// engine, checks their residual and prints the result (`tgraph run`'s).
//
//   tiled_lu NT B OUT.tgt [STEPS] [--live K [--method M] [--repeat R] [--json] [--verify-accesses]]
//   (NT x NT tiles of B x B doubles; exit 0: factorisation, trace and live state checked;
//    1: a check failed; 2: usage)
#include <cblas.h>
#include <lapacke.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "tgraph/capture/recorder.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/version.hpp"
#ifdef TILED_LU_LIVE
#include "tgraph/measure/adapter.hpp"
#include "tgraph/measure/verify.hpp"
#endif

namespace {

using tgraph::AccessMode;
using tgraph::capture::Recorder;

// The kernel's own data: NT x NT tiles, each B x B, column-major. It knows nothing of tgraph.
struct TiledMatrix {
  int nt = 0, b = 0;
  std::vector<std::vector<double>> tiles;  // tile (i, j) at i * nt + j
  TiledMatrix(int nt_, int b_) : nt(nt_), b(b_), tiles(static_cast<std::size_t>(nt_ * nt_)) {
    for (auto& t : tiles) t.assign(static_cast<std::size_t>(b_ * b_), 0.0);
  }
  double* tile(int i, int j) { return tiles[static_cast<std::size_t>(i * nt + j)].data(); }
  const double* tile(int i, int j) const {
    return tiles[static_cast<std::size_t>(i * nt + j)].data();
  }
};

// Tile (i, j) of matrix number `matrix`: off-diagonal entries uniform in [-1, 1] (drawn from
// the tile's own seed), diagonal n = NT * B: strictly dominant by rows and columns.
void fill_tile(TiledMatrix& a, int i, int j, std::uint64_t matrix) {
  std::mt19937_64 gen(1000 +
                      (matrix * static_cast<std::uint64_t>(a.nt) + static_cast<std::uint64_t>(i)) *
                          static_cast<std::uint64_t>(a.nt) +
                      static_cast<std::uint64_t>(j));
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double* t = a.tile(i, j);
  for (int c = 0; c < a.b; ++c)
    for (int r = 0; r < a.b; ++r)
      t[c * a.b + r] = i == j && r == c ? static_cast<double>(a.nt) * a.b : u(gen);
}

// The three tile kernels, LAPACKE and CBLAS. GETRF returns false when LAPACK pivoted (it must
// not on a column diagonally dominant matrix; the factorisation would not be A = LU).
bool getrf(double* akk, int b) {
  std::vector<lapack_int> ipiv(static_cast<std::size_t>(b));
  if (LAPACKE_dgetrf(LAPACK_COL_MAJOR, b, b, akk, b, ipiv.data()) != 0) return false;
  for (int r = 0; r < b; ++r)
    if (ipiv[static_cast<std::size_t>(r)] != r + 1) return false;
  return true;
}
void trsm_lower(const double* akk, double* aik, int b) {  // A(i,k) <- A(i,k) U(k,k)^-1
  cblas_dtrsm(CblasColMajor, CblasRight, CblasUpper, CblasNoTrans, CblasNonUnit, b, b, 1.0, akk, b,
              aik, b);
}
void trsm_upper(const double* akk, double* akj, int b) {  // A(k,j) <- L(k,k)^-1 A(k,j)
  cblas_dtrsm(CblasColMajor, CblasLeft, CblasLower, CblasNoTrans, CblasUnit, b, b, 1.0, akk, b, akj,
              b);
}
void gemm(const double* aik, const double* akj, double* aij, int b) {  // A(i,j) -= A(i,k)A(k,j)
  cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, b, b, b, -1.0, aik, b, akj, b, 1.0, aij,
              b);
}

// ||A - LU||_F / ||A||_F, A matrix number `matrix`, L (unit lower) and U read from the tiles
// of `lu`, tile by tile: (LU)(i,j) = sum over k < min(i,j) of L(i,k) U(k,j), plus the
// triangular tile's product at k = min(i,j) (about the cost of the factorisation).
double relative_residual(const TiledMatrix& lu, std::uint64_t matrix) {
  const int nt = lu.nt, b = lu.b;
  TiledMatrix a(nt, b);
  std::vector<double> t(static_cast<std::size_t>(b * b));
  double norm_a = 0, norm_r = 0;
  for (int i = 0; i < nt; ++i)
    for (int j = 0; j < nt; ++j) {
      fill_tile(a, i, j, matrix);
      double* r = a.tile(i, j);
      for (int e = 0; e < b * b; ++e) norm_a += r[e] * r[e];
      const int p = std::min(i, j);
      for (int k = 0; k < p; ++k) gemm(lu.tile(i, k), lu.tile(k, j), r, b);
      if (i <= j) {  // L(i,i) U(i,j): U(i,i) is the upper triangle of tile (i,i)
        std::copy(lu.tile(i, j), lu.tile(i, j) + b * b, t.begin());
        if (i == j)
          for (int c = 0; c < b; ++c)
            for (int rr = c + 1; rr < b; ++rr) t[static_cast<std::size_t>(c * b + rr)] = 0;
        cblas_dtrmm(CblasColMajor, CblasLeft, CblasLower, CblasNoTrans, CblasUnit, b, b, 1.0,
                    lu.tile(i, i), b, t.data(), b);
      } else {  // L(i,j) U(j,j)
        std::copy(lu.tile(i, j), lu.tile(i, j) + b * b, t.begin());
        cblas_dtrmm(CblasColMajor, CblasRight, CblasUpper, CblasNoTrans, CblasNonUnit, b, b, 1.0,
                    lu.tile(j, j), b, t.data(), b);
      }
      for (int e = 0; e < b * b; ++e) {
        const double d = r[e] - t[static_cast<std::size_t>(e)];
        norm_r += d * d;
      }
    }
  return std::sqrt(norm_r / norm_a);
}

// The instrumentation: one datum per tile (no owning object: tgraph::kNoObject) and one per
// tile's matrix number, one task per kernel call, declaring what the kernel reads (R), writes
// (W) and updates in place (RW). The same code captures (Mode::kCapture), records for a live
// run (kDeferred) or runs the factorisation plainly (kOff).
struct InstrumentedLu {
  TiledMatrix a;
  std::vector<std::uint64_t> matrix;    // by tile: the number of the matrix it holds
  std::vector<tgraph::DatumId> tile;    // datum of tile (i, j) at i * nt + j
  std::vector<tgraph::DatumId> number;  // datum of matrix[i * nt + j]
  tgraph::KindId fill_kind = 0, getrf_kind = 0, trsm_kind = 0, gemm_kind = 0;

  InstrumentedLu(int nt, int b) : a(nt, b), matrix(static_cast<std::size_t>(nt * nt), 0) {}

  void declare(Recorder& rec) {
    fill_kind = rec.kind("FILL");
    getrf_kind = rec.kind("GETRF");
    trsm_kind = rec.kind("TRSM");
    gemm_kind = rec.kind("GEMM");
    const auto bytes = static_cast<std::uint64_t>(a.b) * a.b * sizeof(double);
    for (int i = 0; i < a.nt; ++i)
      for (int j = 0; j < a.nt; ++j) {
        const std::string ij = "(" + std::to_string(i) + "," + std::to_string(j) + ")";
        tile.push_back(rec.datum("A" + ij, tgraph::kNoObject, bytes, a.tile(i, j)));
        number.push_back(rec.datum("matrix" + ij, tgraph::kNoObject, sizeof(std::uint64_t),
                                   &matrix[static_cast<std::size_t>(i * a.nt + j)]));
      }
  }
  tgraph::DatumId t(int i, int j) const { return tile[static_cast<std::size_t>(i * a.nt + j)]; }

  // One step's tasks: fill the next matrix, factorise it in place.
  void issue(Recorder& rec) {
    const int nt = a.nt, b = a.b;
    TiledMatrix* m = &a;
    std::uint64_t* mat = matrix.data();
    constexpr tgraph::ObjectId kNone = tgraph::kNoObject;
    for (int i = 0; i < nt; ++i)
      for (int j = 0; j < nt; ++j) {
        const auto e = static_cast<std::size_t>(i * nt + j);
        rec.task(fill_kind, kNone, {{number[e], AccessMode::RW}, {t(i, j), AccessMode::W}},
                 [m, mat, e, i, j] { fill_tile(*m, i, j, ++mat[e]); });
      }
    for (int k = 0; k < nt; ++k) {
      rec.task(getrf_kind, kNone, {{t(k, k), AccessMode::RW}}, [m, k, b] {
        if (!getrf(m->tile(k, k), b))  // pivoted: poison the tile, the residual check fails
          std::fill(m->tile(k, k), m->tile(k, k) + b * b, std::numeric_limits<double>::quiet_NaN());
      });
      for (int i = k + 1; i < nt; ++i)
        rec.task(trsm_kind, kNone, {{t(k, k), AccessMode::R}, {t(i, k), AccessMode::RW}},
                 [m, i, k, b] { trsm_lower(m->tile(k, k), m->tile(i, k), b); });
      for (int j = k + 1; j < nt; ++j)
        rec.task(trsm_kind, kNone, {{t(k, k), AccessMode::R}, {t(k, j), AccessMode::RW}},
                 [m, j, k, b] { trsm_upper(m->tile(k, k), m->tile(k, j), b); });
      for (int i = k + 1; i < nt; ++i)
        for (int j = k + 1; j < nt; ++j)
          rec.task(gemm_kind, kNone,
                   {{t(i, k), AccessMode::R}, {t(k, j), AccessMode::R}, {t(i, j), AccessMode::RW}},
                   [m, i, j, k, b] { gemm(m->tile(i, k), m->tile(k, j), m->tile(i, j), b); });
    }
  }
  // The residual of the factors now in the tiles (of the matrix they came from).
  double residual() const { return relative_residual(a, matrix[0]); }
};

int fail(const std::string& what) {
  std::fprintf(stderr, "tiled_lu: check failed: %s\n", what.c_str());
  return 1;
}

// Double precision, n = NT * B up to a few thousand: a backward-stable factorisation leaves a
// residual of a few n * 1e-16 (false for NaN: a pivoting GETRF).
bool small(double residual, int nt, int b) { return residual < 1e-14 * nt * b; }

// Captures `steps` factorisations into `out`, checking each one's residual, then reads the
// trace back.
int capture(int nt, int b, int steps, const std::string& out, bool quiet) {
  InstrumentedLu lu(nt, b);
  Recorder rec(tgraph::capture::Mode::kCapture);
  lu.declare(rec);
  // Writing the trace: a header saying where it comes from, then one frame per step.
  const tgraph::TraceHeader header{"tiled LU " + std::to_string(nt) + "x" + std::to_string(nt) +
                                       " tiles of " + std::to_string(b),
                                   "tiled-lu (LAPACKE/CBLAS, no pivoting)",
                                   tgraph::machine_description(),
                                   std::string(tgraph::kVersionString)};
  tgraph::TraceWriter writer(out, header);
  double worst = 0;
  for (int s = 0; s < steps; ++s) {
    rec.begin_step();
    lu.issue(rec);
    writer.append(rec.end_step());  // the step's graph; its edges are derived on reading
    const double r = lu.residual();
    if (!small(r, nt, b))
      return fail("step " + std::to_string(s) + ": ||A - LU|| / ||A|| = " + std::to_string(r));
    worst = std::max(worst, r);
  }
  writer.close();  // end frame, sync, rename into place
  if (rec.errors() != 0) return fail("the recorder counted API misuses");

  const tgraph::Trace t = tgraph::read_trace(out);
  if (t.steps.size() != static_cast<std::size_t>(steps)) return fail("steps in the trace");
  std::fprintf(quiet ? stderr : stdout,
               "tiled_lu: %d steps, %dx%d tiles of %d, %zu tasks and %zu edges per step, "
               "max ||A - LU||_F / ||A||_F = %.2e -> %s\n",
               steps, nt, nt, b, t.steps[0].tasks.size(), t.steps[0].edges.size(), worst,
               out.c_str());
  return 0;
}

#ifdef TILED_LU_LIVE
// The live run: what connects the factorisation to tgraph's executor (docs/instrumenting.md,
// "Run it live"). The residual is that of the factors of the first engine the run stepped
// through the executor: its first timed pass, whose state the check compares.
int run_live(int nt, int b, int steps, int threads, const std::string& method, int repeat,
             bool json, bool verify) {
  namespace tm = tgraph::measure;
  std::shared_ptr<InstrumentedLu> live;  // the first engine stepped live
  const tm::CallbacksFactory make = [&live, nt, b] {
    auto lu = std::make_shared<InstrumentedLu>(nt, b);  // a fresh engine for every pass
    tm::EngineCallbacks c;
    c.declare = [&live, lu](Recorder& rec) {
      lu->declare(rec);
      if (!live && rec.mode() == tgraph::capture::Mode::kDeferred) live = lu;
    };
    c.step = [lu](Recorder& rec) { lu->issue(rec); };
    c.same_every_step = true;  // same tasks each step; the bodies reach the tiles by pointer
    return c;
  };
  tm::LiveOptions o;
  o.exec.threads = static_cast<std::uint32_t>(threads);
  o.steps = static_cast<std::uint32_t>(steps);
  o.repeat = static_cast<std::uint32_t>(repeat);
  o.check = true;  // the final factors against a sequential run, bit for bit
  const tm::MethodChoice choice = tm::choose_method(method);
  if (verify) {  // every task between checksums of the state (docs/instrumenting.md, 9)
    const tm::VerifyResult v = tm::verify_engine_accesses(make, choice, o);
    const std::string m = tm::method_name(choice);
    std::printf("%s\n", json ? tm::verify_json(v, "tiled LU", m).c_str()
                             : tm::verify_text(v, "tiled LU", m).c_str());
    if (!v.findings.empty()) return fail(std::to_string(v.findings.size()) + " wrong declaration(s)");
    return 0;
  }
  const tm::LiveResult r = tm::run_engine_live(make, choice, o);
  const double residual = live->residual();
  const std::string name = tm::method_name(choice), engine = "tiled LU";
  std::printf("%s\n", json ? tm::to_json(r, engine, name, {{"residual", residual}}).c_str()
                           : tm::to_text(r, engine, name, o.repeat).c_str());
  if (r.difference) return fail("live factors differ: " + tm::to_string(*r.difference));
  if (!small(residual, nt, b)) return fail("live ||A - LU|| / ||A|| = " + std::to_string(residual));
  return 0;
}
#endif

int usage(const std::string& why) {
  std::fprintf(stderr,
               "tiled_lu: %s (usage: tiled_lu NT B OUT.tgt [STEPS] [--live K [--method M] "
               "[--repeat R] [--json] [--verify-accesses]], 1 <= NT <= 64, 1 <= B <= 1024)\n",
               why.c_str());
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) return usage("NT, B and OUT.tgt are required");
  const int nt = std::atoi(argv[1]), b = std::atoi(argv[2]);
  const std::string out = argv[3];
  int steps = 3, threads = 0, repeat = 3;
  std::string method = "list";  // no objects: critical-path list scheduling
  bool json = false, verify = false;
  for (int i = 4; i < argc; ++i) {
    const std::string flag = argv[i];
    if (i == 4 && flag.rfind("--", 0) != 0) {
      steps = std::atoi(flag.c_str());
    } else if (flag == "--json") {
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
      if (n < 1) return usage(flag + " " + value + ": a positive number is required");
      (flag == "--live" ? threads : repeat) = n;
    } else {
      return usage("unknown or incomplete flag " + flag);
    }
  }
  if (nt < 1 || nt > 64 || b < 1 || b > 1024 || steps < 1)
    return usage("NT, B or STEPS out of range");
#ifndef TILED_LU_LIVE
  if (threads > 0) return usage("--live: built without tgraph::measure (find_package component)");
#endif
  try {
    if (const int rc = capture(nt, b, steps, out, json); rc != 0 || threads == 0) return rc;
#ifdef TILED_LU_LIVE
    return run_live(nt, b, steps, threads, method, repeat, json, verify);
#endif
  } catch (const tgraph::UsageError& e) {
    return usage(e.what());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tiled_lu: %s\n", e.what());
    return 1;
  }
  return 0;
}
