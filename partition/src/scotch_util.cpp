// SPDX-License-Identifier: MIT
// Scotch calls, serialised and seeded. Scotch's own header comes after <stdint.h> and
// <stdio.h>, by its scotch/ prefix only: /usr/include/scotch also holds a metis.h that must
// never shadow METIS's.
#include <stdint.h>
#include <stdio.h>
#include <scotch/scotch.h>

#include <algorithm>
#include <cstdlib>
#include <mutex>
#include <stdexcept>

#include "strategies.hpp"

static_assert(sizeof(SCOTCH_Num) == 4, "tgraph expects Scotch built with 32-bit SCOTCH_Num");

namespace tgraph::partition::detail {

namespace {

// Strategy building is not reentrant and the random state is global: one caller at a time.
std::mutex& scotch_mutex() {
  static std::mutex m;
  return m;
}

// Debian's Scotch is multi-threaded with thread pinning; one thread keeps it reproducible
// and off the cores our own threads use. Set once, before the first call.
void init_scotch_environment() {
  static std::once_flag once;
  std::call_once(once, [] { setenv("SCOTCH_PTHREAD_NUMBER", "1", 0); });
}

// Owns a built Scotch graph and strategy (the graph keeps pointers into the arrays).
class ScotchCall {
 public:
  ScotchCall(const UndirectedGraph& pg, const LibraryWeights& w)
      : vert_(pg.xadj.begin(), pg.xadj.end()),
        edge_(pg.adjncy.begin(), pg.adjncy.end()),
        velo_(pg.vertices()),
        edlo_(w.adjwgt.begin(), w.adjwgt.end()) {
    // Scotch has no multi-constraint mode: sum the constraints.
    for (std::uint32_t v = 0; v < pg.vertices(); ++v) {
      SCOTCH_Num s = 0;
      for (std::uint32_t c = 0; c < w.ncon; ++c) s += w.vwgt[static_cast<std::size_t>(v) * w.ncon + c];
      velo_[v] = s;
    }
    if (edge_.empty()) {  // Scotch wants valid pointers even without edges
      edge_.push_back(0);
      edlo_.push_back(1);
    }
    if (SCOTCH_graphInit(&graph_) != 0) throw std::runtime_error("SCOTCH_graphInit failed");
    if (SCOTCH_stratInit(&strat_) != 0) {
      SCOTCH_graphExit(&graph_);
      throw std::runtime_error("SCOTCH_stratInit failed");
    }
  }
  /// Builds the graph from the arrays (which stay alive as members).
  void build_graph() {
    const auto n = static_cast<SCOTCH_Num>(vert_.size() - 1);
    const auto arcs = static_cast<SCOTCH_Num>(vert_.back());
    if (SCOTCH_graphBuild(&graph_, 0, n, vert_.data(), nullptr, velo_.data(), nullptr, arcs,
                          edge_.data(), edlo_.data()) != 0)
      fail("SCOTCH_graphBuild failed");
#if defined(TGRAPH_ENABLE_ASSERT)
    if (SCOTCH_graphCheck(&graph_) != 0) fail("SCOTCH_graphCheck rejected the graph");
#endif
  }
  ~ScotchCall() {
    SCOTCH_stratExit(&strat_);
    SCOTCH_graphExit(&graph_);
  }
  ScotchCall(const ScotchCall&) = delete;
  ScotchCall& operator=(const ScotchCall&) = delete;

  void build_strategy(SCOTCH_Num flags, std::uint32_t k, double imbalance) {
    if (SCOTCH_stratGraphMapBuild(&strat_, flags, static_cast<SCOTCH_Num>(k), imbalance) != 0)
      fail("SCOTCH_stratGraphMapBuild failed");
  }
  [[noreturn]] void fail(const char* what) { throw std::runtime_error(what); }

  SCOTCH_Graph graph_;
  SCOTCH_Strat strat_;

 private:
  std::vector<SCOTCH_Num> vert_, edge_, velo_, edlo_;
};

void copy_parts(const std::vector<SCOTCH_Num>& in, std::uint32_t k, std::vector<std::uint32_t>& part) {
  part.resize(in.size());
  for (std::size_t v = 0; v < in.size(); ++v) {
    if (in[v] < 0 || static_cast<std::uint32_t>(in[v]) >= k)
      throw std::runtime_error("Scotch returned part " + std::to_string(in[v]) + " for vertex " +
                               std::to_string(v));
    part[v] = static_cast<std::uint32_t>(in[v]);
  }
}

}  // namespace

void scotch_part(const UndirectedGraph& pg, const LibraryWeights& w, std::uint32_t k,
                 const Options& options, std::vector<std::uint32_t>& part) {
  init_scotch_environment();
  std::vector<SCOTCH_Num> out(pg.vertices(), 0);
  {
    std::lock_guard<std::mutex> lock(scotch_mutex());
    ScotchCall call(pg, w);
    call.build_graph();
    call.build_strategy(scotch_strategy_flags(options.scotch), k, options.imbalance - 1.0);
    SCOTCH_randomSeed(static_cast<SCOTCH_Num>(options.seed % 0x7fffffff));
    SCOTCH_randomReset();
    if (SCOTCH_graphPart(&call.graph_, static_cast<SCOTCH_Num>(k), &call.strat_, out.data()) != 0)
      call.fail("SCOTCH_graphPart failed");
  }
  copy_parts(out, k, part);
}

void scotch_repart(const UndirectedGraph& pg, const LibraryWeights& w, std::uint32_t k,
                   const Options& options, const std::vector<std::int32_t>& old,
                   const std::vector<std::int32_t>& migration_cost, std::vector<std::uint32_t>& part) {
  init_scotch_environment();
  std::vector<SCOTCH_Num> parotab(old.begin(), old.end());
  std::vector<SCOTCH_Num> vmlotab(migration_cost.begin(), migration_cost.end());
  std::vector<SCOTCH_Num> out(pg.vertices(), 0);
  // Scotch quantises the migration cost ratio to 0.01 (below 0.005 it is silently off).
  const double emraval = std::max(0.01, options.migration_cost);
  {
    std::lock_guard<std::mutex> lock(scotch_mutex());
    ScotchCall call(pg, w);
    call.build_graph();
    call.build_strategy(scotch_strategy_flags(options.scotch) | SCOTCH_STRATREMAP, k,
                        options.imbalance - 1.0);
    SCOTCH_randomSeed(static_cast<SCOTCH_Num>(options.seed % 0x7fffffff));
    SCOTCH_randomReset();
    if (SCOTCH_graphRepart(&call.graph_, static_cast<SCOTCH_Num>(k), parotab.data(), emraval,
                           vmlotab.data(), &call.strat_, out.data()) != 0)
      call.fail("SCOTCH_graphRepart failed");
  }
  copy_parts(out, k, part);
}

}  // namespace tgraph::partition::detail

namespace tgraph::partition {

std::int32_t scotch_strategy_flags(ScotchFlavour f) {
  switch (f) {
    case ScotchFlavour::kDefault:
      return SCOTCH_STRATDEFAULT;
    case ScotchFlavour::kQuality:
      return SCOTCH_STRATQUALITY;
    case ScotchFlavour::kSpeed:
      return SCOTCH_STRATSPEED;
    case ScotchFlavour::kBalance:
      return SCOTCH_STRATBALANCE;
  }
  return SCOTCH_STRATDEFAULT;
}

std::vector<std::uint32_t> scotch_partition(const UndirectedGraph& pg, const LibraryWeights& w,
                                            std::uint32_t k, const Options& options) {
  const std::uint32_t n = pg.vertices();
  std::vector<std::uint32_t> part(n, 0);
  if (k <= 1) return part;
  if (k >= n) {
    for (std::uint32_t v = 0; v < n; ++v) part[v] = v;
    return part;
  }
  detail::scotch_part(pg, w, k, options, part);
  return part;
}

}  // namespace tgraph::partition
