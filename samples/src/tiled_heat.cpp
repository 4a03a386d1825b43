// SPDX-License-Identifier: MIT
#include "tgraph/samples/tiled_heat.hpp"

#include <algorithm>
#include <cmath>

#include "tgraph/graph/cumulative.hpp"
#include "tgraph/graph/error.hpp"

namespace tgraph::samples {

namespace {
constexpr AccessMode R = AccessMode::R;
constexpr AccessMode W = AccessMode::W;
constexpr AccessMode RW = AccessMode::RW;
constexpr AccessMode CW = AccessMode::CW;

double dot(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}
}  // namespace

TiledHeat::TiledHeat(TiledHeatOptions options) : o_(std::move(options)) {
  if (o_.tiles < 2 || o_.cells < 1) throw UsageError("tiled heat: at least 2x2 tiles of 1 cell");
  const auto n = static_cast<std::size_t>(o_.cells * o_.cells);
  const int side = o_.tiles * o_.cells;
  tiles_.resize(static_cast<std::size_t>(o_.tiles * o_.tiles));
  for (int ti = 0; ti < o_.tiles; ++ti)
    for (int tj = 0; tj < o_.tiles; ++tj) {
      Tile& t = tile(ti, tj);
      for (std::vector<double>* v : {&t.u, &t.x, &t.r, &t.p, &t.q}) v->assign(n, 0.0);
      for (int a = 0; a < o_.cells; ++a)
        for (int b = 0; b < o_.cells; ++b) {  // a warm bump on a tepid plate: never zero
          const double y = (ti * o_.cells + a + 0.5) / side, x = (tj * o_.cells + b + 0.5) / side;
          t.u[static_cast<std::size_t>(a * o_.cells + b)] =
              1.0 + 4.0 * std::exp(-20.0 * ((x - 0.3) * (x - 0.3) + (y - 0.6) * (y - 0.6)));
        }
    }
}

void TiledHeat::declare(capture::Recorder& rec) {
  const std::uint64_t bytes = static_cast<std::uint64_t>(o_.cells * o_.cells) * sizeof(double);
  for (int i = 0; i < o_.tiles; ++i)
    for (int j = 0; j < o_.tiles; ++j) {
      Tile& t = tile(i, j);
      const std::string name = "tile(" + std::to_string(i) + "," + std::to_string(j) + ")";
      t.obj = rec.object(name);
      t.du = rec.datum(name + ".u", t.obj, bytes, t.u.data());
      t.dx = rec.datum(name + ".x", t.obj, bytes, t.x.data());
      t.dr = rec.datum(name + ".r", t.obj, bytes, t.r.data());
      t.dp = rec.datum(name + ".p", t.obj, bytes, t.p.data());
      t.dq = rec.datum(name + ".q", t.obj, bytes, t.q.data());
    }
  solver_ = rec.object("solver");
  auto scalar = [&](const char* n, double* v) {
    return rec.datum(std::string("solver.") + n, solver_, sizeof(double), v);
  };
  d_rho = scalar("rho", &rho);
  d_rho_new = scalar("rho_new", &rho_new);
  d_den = scalar("den", &den);
  d_alpha = scalar("alpha", &alpha);
  d_beta = scalar("beta", &beta);
  d_b2 = scalar("b2", &b2);
  d_conv = rec.datum("solver.converged", solver_, sizeof(bool), &converged);
  rec.accumulator(d_rho, make_accumulator(rho));
  rec.accumulator(d_rho_new, make_accumulator(rho_new));
  rec.accumulator(d_den, make_accumulator(den));
  k_init = rec.kind("init");
  k_reset_rho = rec.kind("reset_rho");
  k_dot_rr0 = rec.kind("dot_rr0");
  k_start = rec.kind("start");
  k_reset = rec.kind("reset");
  k_matvec = rec.kind("matvec");
  k_dot_pq = rec.kind("dot_pq");
  k_alpha = rec.kind("alpha");
  k_update = rec.kind("update");
  k_dot_rr = rec.kind("dot_rr");
  k_beta = rec.kind("beta");
  k_direction = rec.kind("direction");
  k_store = rec.kind("store");
}

template <class F>
void TiledHeat::issue(capture::Recorder& rec, KindId kind, ObjectId obj, std::vector<Access> acc,
                      F body) {
  if (o_.mutation && o_.mutation->task == position_ && o_.mutation->access < acc.size()) {
    const auto it = acc.begin() + o_.mutation->access;
    if (o_.mutation->mode)
      it->mode = *o_.mutation->mode;
    else
      acc.erase(it);
  }
  ++position_;
  rec.task(kind, obj, acc, std::move(body));
}

void TiledHeat::matvec(std::size_t idx) {
  // q = (I - c L) p over the tile, the neighbours' p at its edges (zero outside the grid).
  const int n = o_.cells, ti = static_cast<int>(idx) / o_.tiles, tj = static_cast<int>(idx) % o_.tiles;
  Tile& t = tiles_[idx];
  auto at = [&](int a, int b) -> double {
    int i = ti, j = tj;
    if (a < 0) --i, a += n;
    if (a >= n) ++i, a -= n;
    if (b < 0) --j, b += n;
    if (b >= n) ++j, b -= n;
    if (i < 0 || j < 0 || i >= o_.tiles || j >= o_.tiles) return 0.0;
    return tile(i, j).p[static_cast<std::size_t>(a * n + b)];
  };
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b)
      t.q[static_cast<std::size_t>(a * n + b)] =
          (1.0 + 4.0 * o_.c) * at(a, b) -
          o_.c * (at(a - 1, b) + at(a + 1, b) + at(a, b - 1) + at(a, b + 1));
}

void TiledHeat::step(capture::Recorder& rec) {
  TiledHeat* e = this;
  position_ = 0;
  const int nt = o_.tiles;
  for (Tile& t : tiles_) {
    Tile* tp = &t;
    issue(rec, k_init, t.obj, {{t.du, R}, {t.dx, W}, {t.dr, W}, {t.dp, W}}, [tp] {
      for (std::size_t i = 0; i < tp->u.size(); ++i) tp->x[i] = 0, tp->r[i] = tp->u[i], tp->p[i] = tp->u[i];
    });
  }
  issue(rec, k_reset_rho, solver_, {{d_rho, W}}, [e] { e->rho = 0; });
  for (Tile& t : tiles_) {
    Tile* tp = &t;
    issue(rec, k_dot_rr0, t.obj, {{t.dr, R}, {d_rho, CW}},
          [e, tp] { accumulate(e->rho) += dot(tp->r, tp->r); });
  }
  issue(rec, k_start, solver_, {{d_rho, R}, {d_b2, W}}, [e] { e->b2 = e->rho; });
  const LoopId loop = rec.begin_loop(d_conv, o_.max_iterations);
  const std::uint32_t first = position_;
  do {
    position_ = first;
    issue(rec, k_reset, solver_, {{d_den, W}, {d_rho_new, W}}, [e] { e->den = 0, e->rho_new = 0; });
    for (int i = 0; i < nt; ++i)
      for (int j = 0; j < nt; ++j) {
        const Tile& t = tile(i, j);
        std::vector<Access> acc = {{t.dp, R}};
        const bool planted = o_.plant == HeatPlant::kMissingHalo && i == 1 && j == 1;
        if (i > 0 && !planted) acc.push_back({tile(i - 1, j).dp, R});  // north
        if (i + 1 < nt) acc.push_back({tile(i + 1, j).dp, R});
        if (j > 0) acc.push_back({tile(i, j - 1).dp, R});
        if (j + 1 < nt) acc.push_back({tile(i, j + 1).dp, R});
        acc.push_back({t.dq, W});
        const std::size_t idx = static_cast<std::size_t>(i * nt + j);
        issue(rec, k_matvec, t.obj, std::move(acc), [e, idx] { e->matvec(idx); });
      }
    for (Tile& t : tiles_) {
      Tile* tp = &t;
      issue(rec, k_dot_pq, t.obj, {{t.dp, R}, {t.dq, R}, {d_den, CW}},
            [e, tp] { accumulate(e->den) += dot(tp->p, tp->q); });
    }
    issue(rec, k_alpha, solver_, {{d_rho, R}, {d_den, R}, {d_alpha, W}},
          [e] { e->alpha = e->rho / e->den; });
    for (Tile& t : tiles_) {
      Tile* tp = &t;
      issue(rec, k_update, t.obj, {{t.dp, R}, {t.dq, R}, {d_alpha, R}, {t.dx, RW}, {t.dr, RW}},
            [e, tp] {
              for (std::size_t i = 0; i < tp->x.size(); ++i)
                tp->x[i] += e->alpha * tp->p[i], tp->r[i] -= e->alpha * tp->q[i];
            });
    }
    for (Tile& t : tiles_) {
      Tile* tp = &t;
      issue(rec, k_dot_rr, t.obj, {{t.dr, R}, {d_rho_new, CW}},
            [e, tp] { accumulate(e->rho_new) += dot(tp->r, tp->r); });
    }
    issue(rec, k_beta, solver_,
          {{d_rho_new, R}, {d_b2, R}, {d_rho, RW}, {d_beta, W}, {d_conv, W}}, [e] {
            e->beta = e->rho_new / e->rho;
            e->rho = e->rho_new;
            e->converged = e->rho_new <= 1e-20 * e->b2;
          });
    for (int i = 0; i < nt; ++i)
      for (int j = 0; j < nt; ++j) {
        Tile* tp = &tile(i, j);
        const bool planted = o_.plant == HeatPlant::kWrongMode && i == 1 && j == std::min(2, nt - 1);
        issue(rec, k_direction, tp->obj, {{tp->dr, R}, {d_beta, R}, {tp->dp, planted ? R : RW}},
              [e, tp] {
                for (std::size_t k = 0; k < tp->p.size(); ++k) tp->p[k] = tp->r[k] + e->beta * tp->p[k];
              });
      }
    ++position_;  // the break
  } while (!rec.conditional_break(loop, [e] { return e->converged; }));
  rec.end_loop(loop);
  for (Tile& t : tiles_) {
    Tile* tp = &t;
    issue(rec, k_store, t.obj, {{t.dx, R}, {t.du, W}}, [tp] { std::copy(tp->x.begin(), tp->x.end(), tp->u.begin()); });
  }
}

double TiledHeat::total() const {
  double s = 0;
  for (const Tile& t : tiles_)
    for (double v : t.u) s += v;
  return s;
}

bool is_tiled_heat(std::string_view name) {
  return name == "tiled-heat" || name == "tiled-heat:wrong-mode" || name == "tiled-heat:missing-halo";
}

TiledHeatOptions tiled_heat_options(std::string_view name) {
  TiledHeatOptions o;
  if (name == "tiled-heat:wrong-mode") {
    o.plant = HeatPlant::kWrongMode;
  } else if (name == "tiled-heat:missing-halo") {
    o.plant = HeatPlant::kMissingHalo;
  } else if (name != "tiled-heat") {
    throw UsageError("unknown test engine '" + std::string(name) +
                     "' (known: tiled-heat, tiled-heat:wrong-mode, tiled-heat:missing-halo)");
  }
  return o;
}

}  // namespace tgraph::samples
