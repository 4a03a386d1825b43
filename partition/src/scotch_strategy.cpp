// SPDX-License-Identifier: MIT
// `scotch`: Scotch graph partitioning of the undirected task graph.
#include "strategies.hpp"

namespace tgraph::partition::detail {

namespace {

/// Scotch static mapping onto K processors with a selectable strategy flavour.
class Scotch final : public Strategy {
 public:
  std::string_view name() const override { return "scotch"; }

 private:
  Result do_partition(const StepGraph& g, std::uint32_t k, const Previous&,
                      const Options& options) override {
    const auto n = static_cast<std::uint32_t>(g.tasks.size());
    Result r;
    r.assignment.k = k;
    if (k == 1 || n == 0) {
      r.assignment.proc.assign(n, 0);
      r.stats.edgecut = 0;
      return r;
    }
    const UndirectedGraph pg = library_graph(g);
    const LibraryWeights w = library_weights(pg);
    if (k >= n) {
      r.assignment = one_task_per_processor(g, k);
    } else {
      std::vector<std::uint32_t> part;
      scotch_part(pg, w, k, options, part);
      r.assignment.proc.assign(part.begin(), part.end());
    }
    r.stats.edgecut = edgecut(pg, r.assignment.proc);
    return r;
  }
};

}  // namespace

std::unique_ptr<Strategy> make_scotch() { return std::make_unique<Scotch>(); }

}  // namespace tgraph::partition::detail
