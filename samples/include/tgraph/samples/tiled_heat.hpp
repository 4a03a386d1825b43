// SPDX-License-Identifier: MIT
// A small test engine that is not the physics engine: an implicit heat solver on a grid of
// tiles, CG with a dynamic loop and halo reads, with planted wrong declarations (the test
// engine of --verify-accesses, docs/instrumenting.md "Finding a wrong declaration").
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tgraph/capture/recorder.hpp"

namespace tgraph::samples {

/// A wrong declaration planted in TiledHeat.
enum class HeatPlant : std::uint8_t {
  kNone = 0,
  kWrongMode = 1,    ///< `direction` of tile(1,2) writes its p, declared R
  kMissingHalo = 2,  ///< `matvec` of tile(1,1) reads its north neighbour tile(0,1).p undeclared
};

/// One access of one task changed (the seeded variants of the tests): access `access` of the
/// task at position `task` of the step's graph is dropped (`mode` nullopt) or given `mode`.
struct AccessMutation {
  std::uint32_t task = 0;
  std::uint32_t access = 0;
  std::optional<AccessMode> mode;
};

/// TiledHeat's settings.
struct TiledHeatOptions {
  int tiles = 3;             ///< tiles x tiles tiles (at least 2)
  int cells = 8;             ///< cells x cells cells per tile
  double c = 0.5;            ///< dt kappa / h^2: the system is (I - c L) u' = u
  std::uint32_t max_iterations = 60;
  HeatPlant plant = HeatPlant::kNone;
  std::optional<AccessMutation> mutation;
};

/// An implicit heat step per time step: (I - c L) u' = u solved by conjugate gradients from
/// zero, L the 5-point Laplacian over the whole grid (zero outside). One object per tile
/// ("tile(i,j)", data u, x, r, p, q) and one for the solver's scalars ("solver": rho,
/// rho_new, den, alpha, beta, b2, converged). Per step: init and dot_rr0 per tile, then a
/// loop of reset, matvec (reads p of the tile and its 4 neighbours: the halo), dot_pq,
/// alpha, update, dot_rr, beta, direction, and store. Every body is a function of the data
/// it declares (unless planted).
///
///   samples::TiledHeat heat;
///   heat.declare(rec);
///   rec.begin_step(); heat.step(rec); rec.end_step();
class TiledHeat {
 public:
  explicit TiledHeat(TiledHeatOptions options = {});
  /// Declares objects, data (with storage) and kinds on `rec` (once).
  void declare(capture::Recorder& rec);
  /// Issues one step's tasks (the caller begins and ends the step).
  void step(capture::Recorder& rec);
  /// Total heat, sum of u.
  double total() const;
  const TiledHeatOptions& options() const { return o_; }

 private:
  struct Tile {
    std::vector<double> u, x, r, p, q;
    ObjectId obj = 0;
    DatumId du = 0, dx = 0, dr = 0, dp = 0, dq = 0;
  };
  // Issues one task, applying the mutation at its graph position.
  template <class F>
  void issue(capture::Recorder& rec, KindId kind, ObjectId obj, std::vector<Access> acc, F body);
  void matvec(std::size_t t);
  Tile& tile(int i, int j) { return tiles_[static_cast<std::size_t>(i * o_.tiles + j)]; }

  TiledHeatOptions o_;
  std::vector<Tile> tiles_;
  double rho = 0, rho_new = 0, den = 0, alpha = 0, beta = 0, b2 = 0;
  bool converged = false;
  ObjectId solver_ = 0;
  DatumId d_rho = 0, d_rho_new = 0, d_den = 0, d_alpha = 0, d_beta = 0, d_b2 = 0, d_conv = 0;
  KindId k_init = 0, k_reset_rho = 0, k_dot_rr0 = 0, k_start = 0, k_reset = 0, k_matvec = 0,
         k_dot_pq = 0, k_alpha = 0, k_update = 0, k_dot_rr = 0, k_beta = 0, k_direction = 0,
         k_store = 0;
  std::uint32_t position_ = 0;  // graph position of the next task issued
};

/// Whether `name` names a TiledHeat engine: "tiled-heat", "tiled-heat:wrong-mode",
/// "tiled-heat:missing-halo".
bool is_tiled_heat(std::string_view name);
/// The options of a TiledHeat name (UsageError for another).
TiledHeatOptions tiled_heat_options(std::string_view name);

}  // namespace tgraph::samples
