// SPDX-License-Identifier: MIT
// The graph files of gpmetis and scotch_gpart, and `tgraph export`'s choice of format.
#include <sstream>

#include "tgraph/graph/enum_names.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/step_json.hpp"
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

std::string_view to_string(GraphFileFormat f) {
  switch (f) {
    case GraphFileFormat::kJson:
      return "json";
    case GraphFileFormat::kMetis:
      return "metis";
    case GraphFileFormat::kScotch:
      return "scotch";
  }
  return "?";
}

GraphFileFormat parse_graph_file_format(std::string_view name) {
  return parse_enum(name, {GraphFileFormat::kJson, GraphFileFormat::kMetis, GraphFileFormat::kScotch},
                    "format");
}

std::string graph_file(const Trace& trace, std::size_t step, const std::string& trace_name,
                       GraphFileFormat format) {
  const StepGraph& g = step_at(trace, step, trace_name);
  switch (format) {
    case GraphFileFormat::kJson:
      return step_graph_json(g, step);
    case GraphFileFormat::kMetis:
      return metis_graph_file(g);
    case GraphFileFormat::kScotch:
      return scotch_graph_file(g);
  }
  return {};
}

}  // namespace tgraph::partition
