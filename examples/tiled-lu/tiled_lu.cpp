// SPDX-License-Identifier: MIT
// A tiled dense LU factorisation without pivoting (right-looking, as in PLASMA or StarPU's
// examples), instrumented with tgraph's capture API as docs/instrumenting.md shows. Not a
// physics engine: there are no objects, only tiles. Each step factorises a fresh matrix that
// is diagonally dominant by rows and columns (so no pivoting is needed and LAPACK's partial
// pivoting swaps no rows), checks ||A - LU||_F / ||A||_F and appends the step's graph to a
// .tgt trace. Per k: GETRF on tile (k,k); TRSM on the tiles (i,k) and (k,j) below and right
// of it; GEMM updating every tile (i,j), i,j > k.
//
//   tiled_lu NT B OUT.tgt [STEPS]   (NT x NT tiles of B x B doubles; exit 0: factorisation
//                                    and trace checked; 1: check failed; 2: usage)
#include <cblas.h>
#include <lapacke.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <random>
#include <string>
#include <vector>

#include "tgraph/capture/recorder.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/version.hpp"

namespace {

using tgraph::AccessMode;

// The kernel's own data: NT x NT tiles, each B x B, column-major. It knows nothing of tgraph.
struct TiledMatrix {
  int nt = 0, b = 0;
  std::vector<std::vector<double>> tiles;  // tile (i, j) at i * nt + j
  TiledMatrix(int nt_, int b_) : nt(nt_), b(b_), tiles(static_cast<std::size_t>(nt_ * nt_)) {
    for (auto& t : tiles) t.assign(static_cast<std::size_t>(b_ * b_), 0.0);
  }
  double* tile(int i, int j) { return tiles[static_cast<std::size_t>(i * nt + j)].data(); }
  double& at(int r, int c) {  // element (r, c) of the whole matrix
    return tile(r / b, c / b)[(c % b) * b + r % b];
  }
};

// Off-diagonal entries uniform in [-1, 1], diagonal n: strictly dominant by rows and columns.
void fill(TiledMatrix& a, std::uint64_t seed) {
  std::mt19937_64 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int n = a.nt * a.b;
  for (int c = 0; c < n; ++c)
    for (int r = 0; r < n; ++r) a.at(r, c) = r == c ? static_cast<double>(n) : u(gen);
}

// The three tile kernels, LAPACKE and CBLAS. Returns false when LAPACK pivoted (it must not
// on a column diagonally dominant matrix; the factorisation would not be A = LU).
bool getrf(double* akk, int b) {
  std::vector<lapack_int> ipiv(static_cast<std::size_t>(b));
  if (LAPACKE_dgetrf(LAPACK_COL_MAJOR, b, b, akk, b, ipiv.data()) != 0) return false;
  for (int r = 0; r < b; ++r)
    if (ipiv[static_cast<std::size_t>(r)] != r + 1) return false;
  return true;
}
void trsm_lower(const double* akk, double* aik, int b) {  // A(i,k) <- A(i,k) U(k,k)^-1
  cblas_dtrsm(CblasColMajor, CblasRight, CblasUpper, CblasNoTrans, CblasNonUnit, b, b, 1.0, akk,
              b, aik, b);
}
void trsm_upper(const double* akk, double* akj, int b) {  // A(k,j) <- L(k,k)^-1 A(k,j)
  cblas_dtrsm(CblasColMajor, CblasLeft, CblasLower, CblasNoTrans, CblasUnit, b, b, 1.0, akk, b,
              akj, b);
}
void gemm(const double* aik, const double* akj, double* aij, int b) {  // A(i,j) -= A(i,k)A(k,j)
  cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, b, b, b, -1.0, aik, b, akj, b, 1.0, aij,
              b);
}

// ||A - LU||_F / ||A||_F with L (unit lower) and U read from the factorised tiles.
double relative_residual(TiledMatrix& original, TiledMatrix& factors) {
  const int n = original.nt * original.b;
  std::vector<double> l(static_cast<std::size_t>(n) * n, 0.0), u(l.size(), 0.0), a(l.size());
  for (int c = 0; c < n; ++c)
    for (int r = 0; r < n; ++r) {
      const std::size_t e = static_cast<std::size_t>(c) * n + r;
      a[e] = original.at(r, c);
      if (r > c) l[e] = factors.at(r, c);
      if (r == c) l[e] = 1.0;
      if (r <= c) u[e] = factors.at(r, c);
    }
  double norm_a = 0;
  for (double x : a) norm_a += x * x;
  cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, n, n, n, -1.0, l.data(), n, u.data(), n,
              1.0, a.data(), n);  // a <- A - LU
  double norm_r = 0;
  for (double x : a) norm_r += x * x;
  return std::sqrt(norm_r / norm_a);
}

// The instrumentation: one datum per tile (no owning object: tgraph::kNoObject), one task per
// kernel call, declaring what the kernel reads (R) and updates in place (RW).
struct InstrumentedLu {
  tgraph::capture::Recorder rec{tgraph::capture::Mode::kCapture};
  TiledMatrix& a;
  std::vector<tgraph::DatumId> tile;  // datum of tile (i, j) at i * nt + j
  tgraph::KindId getrf_kind, trsm_kind, gemm_kind;
  bool pivoted = false;

  explicit InstrumentedLu(TiledMatrix& matrix) : a(matrix) {
    getrf_kind = rec.kind("GETRF");
    trsm_kind = rec.kind("TRSM");
    gemm_kind = rec.kind("GEMM");
    const auto bytes = static_cast<std::uint64_t>(a.b) * a.b * sizeof(double);
    for (int i = 0; i < a.nt; ++i)
      for (int j = 0; j < a.nt; ++j)
        tile.push_back(rec.datum("A(" + std::to_string(i) + "," + std::to_string(j) + ")",
                                 tgraph::kNoObject, bytes, a.tile(i, j)));
  }
  tgraph::DatumId t(int i, int j) const { return tile[static_cast<std::size_t>(i * a.nt + j)]; }

  tgraph::StepGraph factorise() {
    const int nt = a.nt, b = a.b;
    TiledMatrix* m = &a;
    bool* piv = &pivoted;
    constexpr tgraph::ObjectId kNone = tgraph::kNoObject;
    rec.begin_step();
    for (int k = 0; k < nt; ++k) {
      rec.task(getrf_kind, kNone, {{t(k, k), AccessMode::RW}},
               [m, piv, k, b] { *piv = !getrf(m->tile(k, k), b) || *piv; });
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
    return rec.end_step();
  }
};

int fail(const std::string& what) {
  std::fprintf(stderr, "tiled_lu: check failed: %s\n", what.c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  const int nt = argc >= 4 ? std::atoi(argv[1]) : 0, b = argc >= 4 ? std::atoi(argv[2]) : 0;
  const int steps = argc == 5 ? std::atoi(argv[4]) : 3;
  if ((argc != 4 && argc != 5) || nt < 1 || nt > 64 || b < 1 || b > 1024 || steps < 1) {
    std::fprintf(stderr, "usage: tiled_lu NT B OUT.tgt [STEPS]  (1 <= NT <= 64, 1 <= B <= 1024)\n");
    return 2;
  }
  const std::string out = argv[3];
  try {
    TiledMatrix a(nt, b), original(nt, b);
    InstrumentedLu lu(a);
    // Writing the trace: a header saying where it comes from, then one frame per step.
    const tgraph::TraceHeader header{
        "tiled LU " + std::to_string(nt) + "x" + std::to_string(nt) + " tiles of " +
            std::to_string(b),
        "tiled-lu (LAPACKE/CBLAS, no pivoting)", tgraph::machine_description(),
        std::string(tgraph::kVersionString)};
    tgraph::TraceWriter writer(out, header);
    double worst = 0;
    for (int s = 0; s < steps; ++s) {
      fill(a, 1000 + static_cast<std::uint64_t>(s));
      original.tiles = a.tiles;
      writer.append(lu.factorise());  // the step's graph; its edges are derived on reading
      if (lu.pivoted) return fail("step " + std::to_string(s) + ": LAPACK pivoted");
      worst = std::max(worst, relative_residual(original, a));
    }
    writer.close();  // end frame, sync, rename into place
    if (lu.rec.errors() != 0) return fail("the recorder counted API misuses");
    // Double precision, n = NT * B up to a few thousand: a backward-stable factorisation
    // leaves a residual of a few n * 1e-16.
    const double n = static_cast<double>(nt) * b;
    if (!(worst < 1e-14 * n)) return fail("||A - LU|| / ||A|| = " + std::to_string(worst));

    const tgraph::Trace t = tgraph::read_trace(out);
    if (t.steps.size() != static_cast<std::size_t>(steps)) return fail("steps in the trace");
    std::printf("tiled_lu: %d steps, %dx%d tiles of %d, %zu tasks and %zu edges per step, "
                "max ||A - LU||_F / ||A||_F = %.2e -> %s\n",
                steps, nt, nt, b, t.steps[0].tasks.size(), t.steps[0].edges.size(), worst,
                out.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tiled_lu: %s\n", e.what());
    return 1;
  }
  return 0;
}
