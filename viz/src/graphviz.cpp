// SPDX-License-Identifier: MIT
// Graphviz's own libraries build, write, lay out and render the picture; no DOT text is
// assembled here.
#include "tgraph/viz/graphviz.hpp"

#include <cgraph.h>
#include <gvc.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/viz/palette.hpp"

namespace tgraph::viz {
namespace {

std::mutex& graphviz_mutex() {
  static std::mutex m;
  return m;
}

// agwrite() into a std::string through cgraph's I/O discipline.
int put_string(void* chan, const char* str) {
  static_cast<std::string*>(chan)->append(str);
  return 0;
}
int flush_nothing(void*) { return 0; }

// cgraph takes char* for names and values it does not modify.
char* cs(const char* s) { return const_cast<char*>(s); }

void set(void* obj, const char* name, const std::string& value) {
  agsafeset(obj, cs(name), cs(value.c_str()), cs(""));
}

// Graphviz interprets backslash escapes in labels (\n, \l, \N...): text from a trace is
// escaped, and lines are joined with the centred line break "\n".
std::string label_text(const std::vector<std::string>& lines, const char* brk = "\\n") {
  std::string out;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (i) out += brk;
    for (char c : lines[i]) {
      if (c == '\\') out += '\\';
      out += c;
    }
  }
  return out;
}

std::string node_fill(const ViewNode& n) {
  if (n.procs.empty()) return kNeutralFill;
  if (n.procs.size() == 1) return processor_colour(n.procs.front().proc);
  return {};
}

// Owns a cgraph graph and closes it.
struct GraphCloser {
  void operator()(Agraph_t* g) const { agclose(g); }
};
using GraphPtr = std::unique_ptr<Agraph_t, GraphCloser>;

class Builder {
 public:
  explicit Builder(const GraphView& v) : v_(v) {
    io_ = AgIoDisc;
    io_.putstr = put_string;
    io_.flush = flush_nothing;
    disc_ = {&AgMemDisc, &AgIdDisc, &io_};
  }

  GraphPtr build() {
    GraphPtr owner(agopen(cs("step"), Agdirected, &disc_));
    Agraph_t* g = owner.get();
    // Defaults first: agwrite prints them once, objects then carry only differences.
    agattr(g, AGRAPH, cs("fontname"), cs("Helvetica"));
    agattr(g, AGRAPH, cs("fontsize"), cs("12"));
    agattr(g, AGRAPH, cs("labelloc"), cs("t"));
    agattr(g, AGRAPH, cs("labeljust"), cs("l"));
    agattr(g, AGRAPH, cs("newrank"), cs("true"));
    char nodesep[32];
    std::snprintf(nodesep, sizeof nodesep, "%g", v_.nodesep);
    agattr(g, AGRAPH, cs("nodesep"), nodesep);
    agattr(g, AGRAPH, cs("ranksep"), cs("0.45"));
    agattr(g, AGNODE, cs("shape"), cs("box"));
    agattr(g, AGNODE, cs("style"), cs("rounded,filled"));
    agattr(g, AGNODE, cs("fillcolor"), cs(kNeutralFill));
    agattr(g, AGNODE, cs("fontname"), cs("Helvetica"));
    agattr(g, AGNODE, cs("fontsize"), cs("10"));
    agattr(g, AGEDGE, cs("color"), cs("#555555"));
    agattr(g, AGEDGE, cs("fontname"), cs("Helvetica"));
    agattr(g, AGEDGE, cs("fontsize"), cs("8"));
    agattr(g, AGEDGE, cs("arrowsize"), cs("0.6"));
    std::vector<std::string> title = v_.title;
    set(g, "label", label_text(title, "\\l") + "\\l");

    if (v_.legend) add_legend(g);
    std::vector<Agraph_t*> cluster_of;  // by loop id
    for (const ViewCluster& c : v_.clusters) {
      const std::string name = "cluster_loop" + std::to_string(c.loop);
      Agraph_t* sg = agsubg(g, cs(name.c_str()), 1);
      set(sg, "label", label_text({c.label}));
      set(sg, "style", "rounded,dashed");
      set(sg, "color", "#777777");
      if (cluster_of.size() <= c.loop) cluster_of.resize(c.loop + 1, nullptr);
      cluster_of[c.loop] = sg;
    }
    std::vector<Agnode_t*> nodes;
    nodes.reserve(v_.nodes.size());
    for (const ViewNode& n : v_.nodes) {
      Agraph_t* home = n.loop != kNoLoop && n.loop < cluster_of.size() && cluster_of[n.loop]
                           ? cluster_of[n.loop]
                           : g;
      Agnode_t* an = agnode(home, cs(n.id.c_str()), 1);
      style_node(an, n);
      nodes.push_back(an);
    }
    for (const ViewEdge& e : v_.edges) {
      Agedge_t* ae = agedge(g, nodes[e.from], nodes[e.to], nullptr, 1);
      style_edge(ae, e);
    }
    return owner;
  }

 private:
  void style_node(Agnode_t* an, const ViewNode& n) {
    set(an, "label", label_text(n.lines));
    if (!v_.edge_labels) set(an, "tooltip", label_text(n.lines));  // hover text, not the id
    const std::string fill = node_fill(n);
    switch (n.kind) {
      case NodeKind::kTask:
        break;
      case NodeKind::kGroup:
        set(an, "style", "filled");
        break;
      case NodeKind::kSignal:
        set(an, "shape", "cds");
        set(an, "style", "filled");
        set(an, "fontsize", "8");
        break;
      case NodeKind::kWait:
        set(an, "shape", "octagon");
        set(an, "style", "filled");
        set(an, "fontsize", "8");
        break;
      case NodeKind::kReducer:
        set(an, "shape", "invtrapezium");
        set(an, "style", "filled");
        set(an, "fontsize", "9");
        break;
      case NodeKind::kDatum:
        set(an, "shape", "ellipse");
        set(an, "style", "solid");
        set(an, "fontsize", "8");
        break;
    }
    if (!fill.empty()) {
      if (fill != kNeutralFill) set(an, "fillcolor", fill);
      const std::string text = text_colour_on(fill);
      if (text != "#000000") set(an, "fontcolor", text);
    } else {
      // Several processors: stripes as wide as each one's share of the work.
      std::string list;
      for (const ProcessorShare& s : n.procs) {
        const double f = n.work_ns == 0
                             ? 1.0 / static_cast<double>(n.procs.size())
                             : static_cast<double>(s.work_ns) / static_cast<double>(n.work_ns);
        char frac[16];
        std::snprintf(frac, sizeof frac, "%.3f", std::max(f, 0.001));
        if (!list.empty()) list += ':';
        list += processor_colour(s.proc);
        list += ';';
        list += frac;
      }
      set(an, "style", "striped");
      set(an, "fillcolor", list);
    }
    if (n.critical_hits > 0) {
      set(an, "penwidth", "3");
      set(an, "peripheries", "2");
    }
  }

  void style_edge(Agedge_t* ae, const ViewEdge& e) {
    if (!e.lines.empty()) {
      // Without drawn labels the text stays reachable: SVG viewers show it on hover.
      set(ae, v_.edge_labels ? "label" : "tooltip", label_text(e.lines));
    }
    switch (e.style) {
      case EdgeStyle::kData:
        break;
      case EdgeStyle::kOrder:
        set(ae, "style", "dashed");
        break;
      case EdgeStyle::kCarried:
        set(ae, "style", "dotted");
        set(ae, "constraint", "false");
        break;
      case EdgeStyle::kInternal:
        set(ae, "arrowsize", "0.4");
        break;
    }
    const bool cross = e.cross_deps > 0;
    const bool critical = e.critical_hits > 0;
    if (cross && critical) {
      set(ae, "color", std::string(kInkColour) + ":" + kCrossColour + ":" + kInkColour);
      set(ae, "penwidth", "2.5");
    } else if (cross) {
      set(ae, "color", kCrossColour);
      set(ae, "penwidth", "3");
    } else if (critical) {
      set(ae, "color", kInkColour);
      set(ae, "penwidth", "4");
    } else if (e.width > 0) {
      char width[32];
      std::snprintf(width, sizeof width, "%.2f", e.width);
      set(ae, "penwidth", width);
    }
  }

  // A cluster of sample nodes and edges explaining colours, shapes and strokes, left to
  // right in the order added (p0, p1, ... first): dot orders the nodes of one rank freely
  // unless flat edges join them, so consecutive samples are chained by invisible edges.
  void add_legend(Agraph_t* g) {
    Agraph_t* lg = agsubg(g, cs("cluster_legend"), 1);
    set(lg, "label", "legend");
    set(lg, "style", "rounded");
    set(lg, "color", "#AAAAAA");
    Agraph_t* row = agsubg(lg, cs("legend_row"), 1);
    set(row, "rank", "same");
    int count = 0;
    Agnode_t* last = nullptr;
    auto sample = [&](const std::string& label, const std::string& fill, const char* shape,
                      bool chain = true) {
      const std::string name = "legend" + std::to_string(count++);
      Agnode_t* n = agnode(row, cs(name.c_str()), 1);
      if (last && chain) set(agedge(row, last, n, nullptr, 1), "style", "invis");
      last = n;
      set(n, "label", label_text({label}));
      set(n, "fontsize", "9");
      if (shape) set(n, "shape", shape);
      if (fill.empty()) {
        set(n, "style", "rounded");
      } else {
        if (fill != kNeutralFill) set(n, "fillcolor", fill);
        const std::string text = text_colour_on(fill);
        if (text != "#000000") set(n, "fontcolor", text);
      }
      return n;
    };
    constexpr std::uint32_t kShown = 16;
    for (std::uint32_t p = 0; p < v_.processors && p < kShown; ++p)
      sample(std::string("p").append(std::to_string(p)), processor_colour(p), nullptr);
    if (v_.processors > kShown)
      sample(std::string("+").append(std::to_string(v_.processors - kShown)).append(" processors"),
             kNeutralFill, nullptr);
    if (v_.processors == 0) sample("no assignment", kNeutralFill, nullptr);
    auto has = [&](NodeKind k) {
      return std::any_of(v_.nodes.begin(), v_.nodes.end(),
                         [k](const ViewNode& n) { return n.kind == k; });
    };
    if (has(NodeKind::kSignal)) set(sample("signal", kNeutralFill, "cds"), "style", "filled");
    if (has(NodeKind::kWait)) set(sample("wait", kNeutralFill, "octagon"), "style", "filled");
    if (has(NodeKind::kReducer))
      set(sample("reducer", kNeutralFill, "invtrapezium"), "style", "filled");
    if (has(NodeKind::kDatum)) set(sample("shared datum", "", "ellipse"), "style", "solid");
    if (v_.critical_path) {
      Agnode_t* n = sample("on the critical path", "", nullptr);
      set(n, "penwidth", "3");
      set(n, "peripheries", "2");
    }
    auto has_edge = [&](auto pred) { return std::any_of(v_.edges.begin(), v_.edges.end(), pred); };
    auto edge_sample = [&](const std::string& label) {
      Agnode_t* a = sample("", "", "point");
      Agnode_t* b = sample("", "", "point", false);  // joined by the sample edge itself
      set(a, "width", "0.05");
      set(b, "width", "0.05");
      Agedge_t* e = agedge(row, a, b, nullptr, 1);
      set(e, "label", label_text({label}));
      return e;
    };
    if (has_edge([](const ViewEdge& e) { return e.cross_deps > 0; })) {
      Agedge_t* e = edge_sample("crosses processors");
      set(e, "color", kCrossColour);
      set(e, "penwidth", "3");
    }
    if (v_.critical_path) {
      Agedge_t* e = edge_sample("critical path");
      set(e, "color", kInkColour);
      set(e, "penwidth", "4");
    }
    if (has_edge([](const ViewEdge& e) { return e.style == EdgeStyle::kOrder; }))
      set(edge_sample("order only (WAR/WAW)"), "style", "dashed");
    if (has_edge([](const ViewEdge& e) { return e.style == EdgeStyle::kCarried; }))
      set(edge_sample("loop-carried"), "style", "dotted");
  }

  const GraphView& v_;
  Agiodisc_t io_;
  Agdisc_t disc_;
};

}  // namespace

std::string_view to_string(GraphFormat f) {
  switch (f) {
    case GraphFormat::kDot:
      return "dot";
    case GraphFormat::kSvg:
      return "svg";
    case GraphFormat::kPng:
      return "png";
    case GraphFormat::kPdf:
      return "pdf";
  }
  return "?";
}

GraphFormat graph_format_of(const std::string& path) {
  const auto dot = path.rfind('.');
  std::string ext = dot == std::string::npos ? std::string() : path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (GraphFormat f : {GraphFormat::kDot, GraphFormat::kSvg, GraphFormat::kPng, GraphFormat::kPdf})
    if (to_string(f) == ext) return f;
  throw UsageError("", "{output} " + path + ": expected a .dot, .svg, .png or .pdf file name",
                   kNamesFields);
}

namespace {

std::string draw_view(const Trace& trace, const std::string& trace_name, std::size_t step,
                      const TraceAssignment* assignment, const ViewOptions& options,
                      const std::string& output) {
  const GraphFormat format = graph_format_of(output);
  const GraphView v = trace_step_view(trace, trace_name, step, assignment, options);
  if (format != GraphFormat::kDot && v.edges.size() > kLayoutEdges) {
    // The aggregate with the fewest edges, its size named; .dot needs no layout.
    std::string best;
    std::size_t best_nodes = 0, best_edges = 0;
    for (const Collapse c : {Collapse::kLoop, Collapse::kObject, Collapse::kKind,
                             Collapse::kProcessor}) {
      if (c == options.collapse || (c == Collapse::kProcessor && assignment == nullptr)) continue;
      ViewOptions o = options;
      o.collapse = c;
      o.max_nodes = 0;
      o.max_edges = 0;
      const GraphView a = trace_step_view(trace, trace_name, step, assignment, o);
      if (best.empty() || a.edges.size() < best_edges) {
        best = std::string(to_string(c));
        best_nodes = a.nodes.size();
        best_edges = a.edges.size();
      }
    }
    std::string msg = "the picture would have " + std::to_string(v.edges.size()) +
                      " edges, more than dot lays out in about 15 s (" +
                      std::to_string(kLayoutEdges) + "): ";
    if (!best.empty())
      msg += "aggregate with {collapse} " + best + " (" + std::to_string(best_nodes) +
             " nodes, " + std::to_string(best_edges) + " edges), or ";
    msg += "write a .dot file (no layout)";
    throw OptionError("max_edges", msg);
  }
  write_file_atomic(output, render_graph(v, format));
  return v.collapse != Collapse::kNone && v.hidden_deps > 0 ? hidden_deps_note(v) : "";
}

}  // namespace

std::string draw_step(const Trace& trace, const std::string& trace_name, std::size_t step,
                      const TraceAssignment* assignment, const ViewOptions& options,
                      const std::string& output) {
  if (!options.kinds_when_too_many || options.collapse != Collapse::kNone)
    return draw_view(trace, trace_name, step, assignment, options, output);
  try {
    return draw_view(trace, trace_name, step, assignment, options, output);
  } catch (const OptionError& e) {
    if (e.option() != "max_nodes") throw;  // too many edges stays a refusal
    ViewOptions by_kind = options;
    by_kind.collapse = Collapse::kKind;
    const std::string note = draw_view(trace, trace_name, step, assignment, by_kind, output);
    return trace_name + " step " + std::to_string(step) + ": " +
           std::to_string(step_at(trace, step, trace_name).tasks.size()) +
           " tasks, too many to draw one by one: drawn collapsed by kind ({collapse} none "
           "{max_nodes} 0 {max_edges} 0 draws every task)" +
           (note.empty() ? "" : "; " + note);
  }
}

std::string to_dot(const GraphView& view) {
  std::lock_guard<std::mutex> lock(graphviz_mutex());
  agseterr(AGMAX);  // errors come back as return codes, not on stderr
  Builder b(view);
  GraphPtr g = b.build();
  std::string out;
  if (agwrite(g.get(), &out) != 0) throw std::runtime_error("Graphviz could not write the graph");
  return out;
}

std::string render_graph(const GraphView& view, GraphFormat format) {
  if (format == GraphFormat::kDot) return to_dot(view);
  std::lock_guard<std::mutex> lock(graphviz_mutex());
  agseterr(AGMAX);
  // One context for the whole process, never freed: Graphviz 2.42's pango plugin keeps a
  // pointer to the last font name it measured, and that name lives in the context's font
  // table. Freeing the context and rendering again with a new one reads the freed name
  // (a heap-use-after-free that AddressSanitizer reports inside libgvplugin_pango).
  static GVC_t* const gvc = gvContext();
  if (!gvc) throw std::runtime_error("Graphviz: no context (libgvc)");
  Builder b(view);
  GraphPtr g = b.build();
  if (view.edges.size() > kQuickLayoutEdges) {
    set(g.get(), "mclimit", "0.1");
    set(g.get(), "remincross", "false");
    set(g.get(), "nslimit", "1");
    set(g.get(), "nslimit1", "1");
    set(g.get(), "splines", "line");
  }
  if (format == GraphFormat::kPng) {
    // cairo's bitmaps stop at 32,767 pixels a side: at most 300 inches at 96 dpi (dot
    // scales a larger drawing down to fit; "!" is not given, so a small one keeps its size).
    set(g.get(), "size", "300,300");
  }
  if (gvLayout(gvc, g.get(), "dot") != 0) {
    const char* why = aglasterr();
    throw std::runtime_error(std::string("Graphviz dot layout failed") +
                             (why ? ": " + std::string(why) : ""));
  }
  char* data = nullptr;
  unsigned int length = 0;
  const std::string name(to_string(format));
  const int rc = gvRenderData(gvc, g.get(), name.c_str(), &data, &length);
  std::string out;
  if (rc == 0 && data) out.assign(data, length);
  if (data) gvFreeRenderData(data);
  gvFreeLayout(gvc, g.get());
  if (rc != 0)
    throw std::runtime_error("Graphviz cannot render " + name +
                             " (is graphviz's cairo plugin, libgvplugin_pango, installed?)");
  return out;
}

}  // namespace tgraph::viz
