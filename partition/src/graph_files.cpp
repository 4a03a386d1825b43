// SPDX-License-Identifier: MIT
#include <sstream>

#include "tgraph/partition/export.hpp"
#include "tgraph/partition/partition_graph.hpp"

namespace tgraph::partition {

std::string metis_graph_file(const UndirectedGraph& u) {
  std::ostringstream s;
  s << u.vertices() << ' ' << u.edges() << " 011\n";
  for (std::uint32_t v = 0; v < u.vertices(); ++v) {
    s << u.vwgt[v];
    for (auto i = u.xadj[v]; i < u.xadj[v + 1]; ++i)
      s << ' ' << u.adjncy[i] + 1 << ' ' << u.adjwgt[i];
    s << '\n';
  }
  return s.str();
}

std::string scotch_graph_file(const UndirectedGraph& u) {
  std::ostringstream s;
  s << "0\n" << u.vertices() << ' ' << u.adjncy.size() << "\n0 011\n";
  for (std::uint32_t v = 0; v < u.vertices(); ++v) {
    s << u.vwgt[v] << ' ' << (u.xadj[v + 1] - u.xadj[v]);
    for (auto i = u.xadj[v]; i < u.xadj[v + 1]; ++i) s << ' ' << u.adjwgt[i] << ' ' << u.adjncy[i];
    s << '\n';
  }
  return s.str();
}

std::string metis_graph_file(const StepGraph& g) { return metis_graph_file(library_graph(g)); }
std::string scotch_graph_file(const StepGraph& g) { return scotch_graph_file(library_graph(g)); }

}  // namespace tgraph::partition
