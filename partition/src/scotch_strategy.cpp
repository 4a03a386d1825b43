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
    if (auto trivial = library_trivial_case(g, k)) return *trivial;
    Result r;
    r.assignment.k = k;
    const UndirectedGraph pg = library_graph(g);
    const LibraryWeights w = library_weights(pg);
    std::vector<std::uint32_t> part;
    scotch_part(pg, w, k, options, part);
    r.assignment.proc.assign(part.begin(), part.end());
    r.stats.edgecut = edgecut(pg, r.assignment.proc);
    return r;
  }
};

}  // namespace

std::unique_ptr<Strategy> make_scotch() { return std::make_unique<Scotch>(); }

}  // namespace tgraph::partition::detail
