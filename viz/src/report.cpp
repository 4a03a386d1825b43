// SPDX-License-Identifier: MIT
// The self-contained HTML report: tables written here, charts as Vega-Lite specifications
// rendered in the page by the inlined Vega libraries (web_assets.hpp).
#include "tgraph/viz/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>

#include "tgraph/explain/explain.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/graph/metrics.hpp"
#include "tgraph/graph/summary.hpp"
#include "tgraph/viz/critical_path.hpp"
#include "tgraph/viz/graph_view.hpp"
#include "tgraph/viz/graphviz.hpp"
#include "tgraph/viz/palette.hpp"
#include "chart_util.hpp"
#include "report_specs.hpp"
#include "web_assets.hpp"

namespace tgraph::viz {
namespace {

using nlohmann::json;
using detail::escape;
using detail::kRenderScript;
using detail::methods_spec;
using detail::page_head;
using detail::script_json;
using detail::series_spec;
using detail::speedup_spec;
using detail::lost_runs_spec;
using detail::lost_steps_spec;
using detail::timeline_spec;
using detail::with_commas;

// An unsigned integer field no larger than `max`: nlohmann's get<> would convert a float
// (or a value out of range) with undefined behaviour.
std::uint64_t get_count(const json& j, const char* key, std::uint64_t max = UINT64_MAX) {
  const json& v = j.at(key);
  if (!v.is_number_unsigned() || v.get<std::uint64_t>() > max)
    throw json::type_error::create(
        302, std::string("\"") + key + "\" must be an unsigned integer <= " + std::to_string(max),
        &v);
  return v.get<std::uint64_t>();
}

// The Graphviz SVG without its XML prolog and doctype (inline SVG in HTML).
std::string inline_svg(const std::string& svg) {
  const auto at = svg.find("<svg");
  return at == std::string::npos ? svg : svg.substr(at);
}

RunAttribution run_attribution(const std::string& label, const explain::Attribution& a) {
  RunAttribution r;
  r.label = label;
  r.lost_ns = a.lost_ns;
  for (const std::string_view n : explain::cause_names())
    r.causes.emplace_back(std::string(n), explain::cause(a.causes, n));
  return r;
}

// The explanation of a timeline that carries its step graphs (nothing otherwise).
std::optional<explain::Explanation> explained(const Timeline& t) {
  if (t.step_info.empty()) return std::nullopt;
  explain::ExplainOptions o;
  o.what_ifs = false;
  return explain::explain_timeline(t, "timeline", o);
}

std::string number_cell(const std::optional<double>& v, int decimals) {
  return v ? "<td>" + fixed(*v, decimals) + "</td>" : "<td>&ndash;</td>";
}

std::string table_html(const ReportContent& c) {
  std::string h =
      "<table><thead><tr><th>method</th><th>K</th><th>partition (ms)</th><th>imbalance "
      "(max/mean)</th>"
      "<th>cut (KiB)</th><th>migrated tasks</th><th>predicted speed-up (&times;)</th>"
      "<th>replay (ms)</th><th>sequential (ms)</th><th>speed-up (&times;)</th><th>efficiency "
      "(%)</th>"
      "<th>signals</th></tr></thead><tbody>";
  for (const MethodRow& r : c.rows) {
    h += "<tr><td>" + escape(r.method) + "</td><td>" + std::to_string(r.k) + "</td>";
    if (r.partitioned) {
      h += "<td>" + round3(r.partition_ms) + "</td><td>" + fixed(r.imbalance, 3) + "</td><td>" +
           round3(static_cast<double>(r.cut_bytes) / 1024.0) + "</td><td>" +
           with_commas(r.migrated_tasks) + "</td>";
    } else {
      h += "<td>&ndash;</td><td>&ndash;</td><td>&ndash;</td><td>&ndash;</td>";
    }
    h += number_cell(r.predicted_speedup, 2);
    if (!r.failure.empty()) {
      h += "<td colspan=\"5\" class=\"fail\">replay failed: " + escape(r.failure) + "</td></tr>";
      continue;
    }
    h += r.measured_ms ? "<td>" + round3(*r.measured_ms) + "</td>" : "<td>&ndash;</td>";
    h += r.sequential_ms ? "<td>" + round3(*r.sequential_ms) + "</td>" : "<td>&ndash;</td>";
    h += number_cell(r.speedup, 2);
    h += r.efficiency ? "<td>" + fixed(*r.efficiency * 100, 0) + "</td>" : "<td>&ndash;</td>";
    h += r.signals ? "<td>" + with_commas(*r.signals) + "</td>" : "<td>&ndash;</td>";
    h += "</tr>";
  }
  return h + "</tbody></table>";
}

const char* kStyle =
    "body{font-family:system-ui,Helvetica,Arial,sans-serif;margin:2em;max-width:1200px;color:#222}"
    "h1{font-size:1.5em}h2{font-size:1.2em;margin-top:2em;border-bottom:1px solid #ccc}"
    "table{border-collapse:collapse;font-size:0.9em}td,th{border:1px solid #bbb;padding:3px 8px;"
    "text-align:right}th{background:#eee}td:first-child{text-align:left}td.fail{color:#D55E00;"
    "text-align:left}dl{display:grid;grid-template-columns:max-content auto;gap:2px 16px}"
    "dt{font-weight:600}dd{margin:0}.charts{display:flex;flex-wrap:wrap;gap:24px}"
    ".graph{overflow:auto;max-height:900px;border:1px solid #ddd}.chart-error{color:#D55E00}"
    "figcaption{font-size:0.85em;color:#555;max-width:900px}"
    ".graphs{display:flex;flex-wrap:wrap;gap:16px;align-items:flex-start}"
    ".graphs figure{margin:0}.step-figure{flex:3 1 600px;min-width:0}"
    ".quotient-figure{flex:1 1 300px;min-width:0}"
    "#graph-step{height:700px;overflow:hidden;background:#fff}"
    "#graph-step text{text-rendering:geometricPrecision}"
    "#graph-quotient svg{max-width:100%;height:auto}"
    ".graph-tools{font-size:0.85em;color:#555;margin-bottom:4px}"
    ".graph-tools button{font-size:1em;min-width:2.2em;margin-right:4px}";

// Pan and zoom on the step graph (Panzoom, inlined). The first view shows the whole graph,
// fitted to the box and centred; the wheel zooms at the pointer, dragging pans; buttons zoom
// in and out, or go back to the whole graph. Sets data-panzoom="ready" and data-start-scale
// on #graph-step once bound (what the browser test reads).
const char* kPanZoomScript = R"js(
(function () {
  const box = document.getElementById('graph-step');
  if (!box) return;
  const svg = box.querySelector('svg');
  const w = svg.width.baseVal.value, h = svg.height.baseVal.value;  // px
  const W = box.clientWidth, H = box.clientHeight;
  const whole = Math.min(W / w, H / h);
  // Panzoom scales the <svg> about its centre (transform-origin 50% 50%): the translation
  // that puts its top-left corner at (left, top) of the box at scale s.
  function at(s, left, top) {
    return {scale: s, x: (left - (w / 2) * (1 - s)) / s, y: (top - (h / 2) * (1 - s)) / s};
  }
  const all = at(whole, (W - whole * w) / 2, (H - whole * h) / 2);
  const pz = Panzoom(svg, {canvas: true, maxScale: 8, minScale: Math.min(whole, 1) / 2, step: 0.3,
                           startScale: all.scale, startX: all.x, startY: all.y});
  box.addEventListener('wheel', function (e) { pz.zoomWithWheel(e); });
  const actions = {
    in: function () { pz.zoomIn(); },
    out: function () { pz.zoomOut(); },
    whole: function () { pz.reset(); }
  };
  for (const b of document.querySelectorAll('[data-zoom]'))
    b.addEventListener('click', actions[b.dataset.zoom]);
  box.dataset.startScale = String(all.scale);
  box.dataset.panzoom = 'ready';
})();
)js";

// The step graph of the report: step `step` collapsed by object, coloured by `assignment`,
// with `executed` (a timeline's executed critical path) or else its own critical path.
void set_step_graph(ReportContent& c, const StepGraph& g, const std::string& trace_name,
                    const Assignment* assignment, std::size_t step,
                    const std::string& assignment_name, const CriticalPath* executed) {
  ViewOptions o;
  o.collapse = Collapse::kObject;
  o.assignment = assignment;
  o.critical_path = true;
  o.path = executed;
  o.max_nodes = 0;
  o.max_edges = 0;
  o.edge_labels = false;  // on hover: drawn, they overlap on a scene of many objects
  o.title = trace_name + ", step " + std::to_string(step) +
            (assignment
                 ? ", " + assignment_name + " on " + std::to_string(assignment->k) + " processors"
                 : "");
  const GraphView view = make_graph_view(g, o);
  c.graph_step = step;
  c.graph_svg = inline_svg(render_graph(view, GraphFormat::kSvg));
  c.graph_caption =
      "Step " + std::to_string(step) +
      " collapsed by object (one node per object and loop, and per object before and "
      "after each loop; work = cost × runs), "
      "coloured by processor" +
      (assignment ? " (" + assignment_name + ")" : " (no assignment: grey)") +
      "; vermillion edges cross processors; thick black: " +
      (executed ? "the executed critical path of this step in the timeline (tgraph explain)"
                : "the critical path (the longest through the recorded costs)") +
      "; " + hidden_deps_note(view) +
      ". Hover a node or an edge for its text (edge labels: data, bytes per step, "
      "crossings). Same picture with edge labels drawn: step " + std::to_string(step) +
      " of " + trace_name + " collapsed by object, with the critical path" +
      (assignment ? " and the assignment" : "") + ", drawn on its own as SVG";
}

// The executed critical path of step `step` of the timeline, on the step graph `g` it
// replayed: each body of the path named by its task of `g` (the timeline's graph's origin;
// reducers, which `g` has not, left out), each pair of consecutive bodies joined by the edge
// of `g` between them where there is one. Nothing when the timeline has no explanation of
// that step or its graph is not `g`'s (another trace's: a kind or a task out of place).
std::optional<CriticalPath> executed_path(const StepGraph& g, const Timeline& t,
                                          const explain::Explanation& e, std::size_t step) {
  const explain::StepExplanation* se = nullptr;
  for (const explain::StepExplanation& s : e.steps)
    if (s.step == step) se = &s;
  const TimelineStep* info = t.info(static_cast<std::uint32_t>(step));
  if (!se || !info || info->graph >= t.graphs.size()) return std::nullopt;
  const TimelineGraph& x = t.graphs[info->graph];
  CriticalPath cp;
  cp.task_hits.assign(g.tasks.size(), 0);
  cp.edge_hits.assign(g.edges.size(), 0);
  cp.carried_hits.assign(g.carried_edges.size(), 0);
  // The edges into each task (the first from the previous body is the link), per list.
  const IncomingEdges into = incoming_edges(g.tasks.size(), g.edges);
  const IncomingEdges into_carried = incoming_edges(g.tasks.size(), g.carried_edges);
  std::optional<TaskInstance> prev;
  for (const explain::PathLink& l : se->critical_path) {
    cp.length_ns = static_cast<std::uint64_t>(std::max<std::int64_t>(0, l.end_ns));
    if (l.link != explain::Link::kBody || !l.task) continue;
    if (*l.task >= x.origin.size()) return std::nullopt;
    const TaskId o = x.origin[*l.task];
    if (o == kNoTask) continue;  // a reducer of the lowered graph
    if (o >= g.tasks.size() || g.kind_name(o) != l.kind) return std::nullopt;
    const TaskInstance here{o, l.iteration};
    PathLink link = PathLink::kStart;
    std::uint32_t edge = 0;
    if (prev) {
      const bool same_iteration = prev->iteration == here.iteration;
      const std::vector<Edge>& edges = same_iteration ? g.edges : g.carried_edges;
      const IncomingEdges& in = same_iteration ? into : into_carried;
      for (std::uint32_t k = in.begin[o]; k < in.begin[o + 1]; ++k)
        if (const std::uint32_t i = in.edge[k]; edges[i].from == prev->task) {
          link = same_iteration ? PathLink::kEdge : PathLink::kCarried;
          edge = i;
          (same_iteration ? cp.edge_hits : cp.carried_hits)[i]++;
          break;
        }
    }
    ++cp.task_hits[o];
    cp.instances.push_back(here);
    cp.links.push_back(link);
    cp.edge_of.push_back(edge);
    prev = here;
  }
  if (cp.instances.empty()) return std::nullopt;
  return cp;
}

}  // namespace

std::string round3(double v) {
  if (!std::isfinite(v)) return "&ndash;";
  if (v == 0) return "0";
  const int magnitude = static_cast<int>(std::floor(std::log10(std::fabs(v))));
  if (magnitude >= 2) return fixed(v, 0);
  return fixed(v, 2 - magnitude);
}

ReportContent report_content(const Trace& trace, const std::string& trace_name,
                             const Assignment* assignment, std::size_t step,
                             const std::string& assignment_name) {
  ReportContent c;
  const TraceSummary s = summarize_trace(trace);
  c.title = "tgraph report: " + (trace.header.scene.empty() ? trace_name : trace.header.scene);
  c.facts = {
      {"trace", trace_name},
      {"scene", trace.header.scene},
      {"engine", trace.header.engine},
      {"machine", trace.header.machine},
      {"steps", with_commas(s.steps)},
      {"tasks per step", with_commas(s.tasks_min) +
                             (s.tasks_min == s.tasks_max ? "" : " to " + with_commas(s.tasks_max))},
      {"dependencies", with_commas(s.edges) + " (all steps)"},
      {"loops", with_commas(s.loops) + ", " + with_commas(s.loop_iterations) + " iterations"},
      {"work, span", round3(static_cast<double>(s.work_ns) / 1e6) + " ms, " +
                         round3(static_cast<double>(s.span_ns) / 1e6) + " ms (all steps)"},
      {"parallelism (work/span)", round3(s.parallelism) + " (raw: the recorded costs)"},
      {"parallelism, robust costs",
       round3(s.robust_parallelism) +
           " (each task's cost the median of its cost over the steps of its structure: one "
           "interrupted task of the capture does not bend it)"},
      {"contact changes", with_commas(s.contact_changes) + " steps"}};
  c.parallelism = s.parallelism;
  for (std::size_t i = 0; i < s.per_step.size(); ++i)
    if (s.per_step[i].contacts_changed && i > 0)
      c.contact_changes.push_back(static_cast<std::uint32_t>(i));
  if (step < trace.steps.size())
    set_step_graph(c, trace.steps[step], trace_name, assignment, step, assignment_name, nullptr);
  return c;
}

void set_quotient(ReportContent& c, const QuotientGraph& q, const std::string& method) {
  const std::string title = "quotient graph, step " + std::to_string(c.graph_step) + ", " + method +
                            " on " + std::to_string(q.load_ns.size()) + " processors";
  c.quotient_svg = inline_svg(render_graph(quotient_view(q, title), GraphFormat::kSvg));
  c.quotient_caption =
      "The partition seen from the processors: a node per processor with its work (cost × "
      "runs) and share of the step's work; an arrow p → q for the dependencies from p's tasks "
      "to q's, their datum bytes (the cut, as in tgraph evaluate) and the signals p sends q in "
      "one execution of the step (datum versions and loop decisions; summed over the arrows: "
      "tgraph evaluate's waits). Arrows are wider the more bytes they carry.";
}

void add_compare_json(ReportContent& c, std::string_view text, const std::string& name) {
  const json j = json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("rows") || !j["rows"].is_array())
    throw InputError(name, std::nullopt,
                     "not a comparison (expected a comparison's JSON with \"rows\")");
  std::size_t i = 0;
  try {
    for (const json& r : j["rows"]) {
      MethodRow row;
      row.method = r.contains("label") ? r.at("label").get<std::string>()
                                       : r.at("method").get<std::string>();
      row.k = static_cast<std::uint32_t>(get_count(r, "k", UINT32_MAX));
      row.partitioned = true;
      row.partition_ms = r.at("partition_ms").get<double>();
      row.imbalance = r.at("imbalance").get<double>();
      row.cut_bytes = get_count(r, "cut_bytes");
      row.migrated_tasks = get_count(r, "migrated_tasks");
      row.predicted_speedup = r.at("predicted_speedup").get<double>();
      c.rows.push_back(row);
      ++i;
    }
  } catch (const json::exception& e) {
    std::string why = e.what();
    if (const auto p = why.find("] "); p != std::string::npos) why = why.substr(p + 2);
    throw InputError(name, std::nullopt, "rows[" + std::to_string(i) + "]: " + why);
  }
}

void add_replay_json(ReportContent& c, std::string_view text, const std::string& name) {
  const bool gzip = text.size() >= 2 && static_cast<unsigned char>(text[0]) == 0x1f &&
                    static_cast<unsigned char>(text[1]) == 0x8b;
  const json j = gzip ? json(json::object({{"tasks", json::array()}}))
                      : json::parse(text, nullptr, false);
  if (!j.is_discarded() && j.is_object() && j.contains("tasks")) {
    Timeline t = parse_timeline(text, name);
    if (const auto e = explained(t)) c.attributions.push_back(run_attribution(name, e->attribution));
    if (!c.timeline) {
      c.timeline = std::move(t);
      c.timeline_caption = "From " + name + ".";
    }
    return;
  }
  if (j.is_discarded() || !j.is_object() || !j.contains("policy") || !j.contains("speedup"))
    throw InputError(name, std::nullopt,
                     "expected a replay timeline or a replay's measurement (its JSON report)");
  try {
    MethodRow row;
    const std::string policy = j.at("policy").get<std::string>();
    const std::string assignment = j.value("assignment", std::string());
    row.method = policy == "partition" && !assignment.empty() ? assignment : policy;
    row.k = static_cast<std::uint32_t>(get_count(j, "threads", UINT32_MAX));
    row.measured_ms = j.at("wall_ns").get<double>() / 1e6;
    row.sequential_ms = j.at("sequential_wall_ns").get<double>() / 1e6;
    row.speedup = j.at("speedup").get<double>();
    row.efficiency = j.at("efficiency").get<double>();
    row.signals = get_count(j, "signals");
    if (j.contains("attribution") && j["attribution"].is_object()) {
      explain::Attribution a;
      a.lost_ns = j["attribution"].at("lost_ns").get<std::int64_t>();
      for (const std::string_view n : explain::cause_names())
        explain::cause(a.causes, n) =
            j["attribution"].at("causes").at(std::string(n)).get<std::int64_t>();
      c.attributions.push_back(
          run_attribution(row.method + " at " + std::to_string(row.k), a));
    }
    c.rows.push_back(row);
  } catch (const json::exception& e) {
    std::string why = e.what();
    if (const auto p = why.find("] "); p != std::string::npos) why = why.substr(p + 2);
    throw InputError(name, std::nullopt, why);
  }
}

ReportContent report_from_files(const Trace& trace, const std::string& trace_name,
                                const TraceAssignment* assignment, std::size_t step,
                                const std::string& compare_path,
                                const std::vector<std::string>& replay_paths) {
  if (step >= trace.steps.size()) step = 0;
  const bool coloured = assignment && step < assignment->steps.size();
  ReportContent c = report_content(trace, trace_name, coloured ? &assignment->steps[step] : nullptr,
                                   step, assignment ? assignment->method : std::string());
  if (!compare_path.empty()) add_compare_json(c, read_file_text(compare_path), compare_path);
  for (const std::string& r : replay_paths) add_replay_json(c, read_file_text(r), r);
  draw_executed_path(c, trace, trace_name, coloured ? &assignment->steps[step] : nullptr,
                     assignment ? assignment->method : std::string());
  return c;
}

bool draw_executed_path(ReportContent& c, const Trace& trace, const std::string& trace_name,
                        const Assignment* assignment, const std::string& assignment_name) {
  if (!c.timeline || c.graph_svg.empty() || c.graph_step >= trace.steps.size()) return false;
  std::optional<explain::Explanation> e;
  try {
    e = explained(*c.timeline);
  } catch (const Error&) {
    return false;  // not explained: the graph's own critical path stays
  }
  if (!e) return false;
  const StepGraph& g = trace.steps[c.graph_step];
  const std::optional<CriticalPath> path = executed_path(g, *c.timeline, *e, c.graph_step);
  if (!path) return false;
  set_step_graph(c, g, trace_name, assignment, c.graph_step, assignment_name, &*path);
  return true;
}

void write_report(const Trace& trace, const std::string& trace_name,
                  const TraceAssignment* assignment, std::size_t step,
                  const std::string& compare_path, const std::vector<std::string>& replay_paths,
                  const StepQuotient& quotient, const std::string& output) {
  ReportContent c =
      report_from_files(trace, trace_name, assignment, step, compare_path, replay_paths);
  if (assignment && !c.graph_svg.empty())
    set_quotient(c, quotient(trace.steps[c.graph_step], assignment->steps[c.graph_step]),
                 assignment->method);
  write_file_atomic(output, report_html(c));
}

std::string report_html(const ReportContent& c) {
  json specs = json::object();
  std::string body;
  body += "<h1>" + escape(c.title) + "</h1>";
  for (const std::string& n : c.notes) body += "<p>" + escape(n) + "</p>";
  body += "<h2>Scene and machine</h2><dl>";
  for (const auto& [k, v] : c.facts)
    if (!v.empty()) body += "<dt>" + escape(k) + "</dt><dd>" + escape(v) + "</dd>";
  body += "</dl>";
  if (!c.rows.empty()) {
    body += "<h2>Methods</h2>" + table_html(c);
    body +=
        "<div class=\"charts\"><div class=\"chart\" id=\"chart-speedup\"></div>"
        "<div class=\"chart\" id=\"chart-methods\"></div></div>";
    specs["chart-speedup"] = speedup_spec(c);
    specs["chart-methods"] = methods_spec(c);
  }
  if (!c.series.empty()) {
    body +=
        "<h2>Over the run</h2><div class=\"charts\"><div class=\"chart\" "
        "id=\"chart-partition-time\"></div>"
        "<div class=\"chart\" id=\"chart-migrations\"></div></div>";
    specs["chart-partition-time"] = series_spec(c, false);
    specs["chart-migrations"] = series_spec(c, true);
  }
  std::optional<explain::Explanation> e;
  if (c.timeline) {
    try {
      e = explained(*c.timeline);
    } catch (const Error&) {
      // A timeline whose steps cannot be explained is still drawn.
    }
  }
  std::vector<RunAttribution> runs = c.attributions;
  if (runs.empty() && e) runs.push_back(run_attribution("the timeline", e->attribution));
  if (e || !runs.empty()) {
    body += "<h2>Where the time went</h2><div class=\"charts\">";
    if (e) {
      body += "<div class=\"chart\" id=\"chart-lost-steps\"></div>";
      specs["chart-lost-steps"] = lost_steps_spec(*e);
    }
    body += "<div class=\"chart\" id=\"chart-lost-runs\"></div></div>";
    specs["chart-lost-runs"] = lost_runs_spec(runs);
    body +=
        "<p><small>Lost time = threads &times; makespan &minus; sequential work, split into "
        "causes that add up to it (serial phases, imbalance, dependency waits, hand-offs, "
        "interruptions, inflation, the runtime's own time, starvation, residual; "
        "docs/explain.md). <code>tgraph explain</code> on the timeline gives the table, the "
        "critical path and the what-ifs.</small></p>";
  }
  if (c.timeline) {
    std::string caption = c.timeline_caption;
    if (e) caption += " Outlined in black: each step's executed critical path (tgraph explain).";
    specs["chart-timeline"] = timeline_spec(*c.timeline, &caption, e ? &*e : nullptr);
    body +=
        "<h2>Replay timeline</h2><figure><div class=\"chart\" "
        "id=\"chart-timeline\"></div><figcaption>" +
        escape(caption) + "</figcaption></figure>";
  }
  if (!c.graph_svg.empty()) {
    body += std::string("<h2>Step graph") + (c.quotient_svg.empty() ? "" : " and quotient graph") +
            "</h2><div class=\"graphs\"><figure class=\"step-figure\"><div "
            "class=\"graph-tools\"><button data-zoom=\"in\" title=\"zoom in\">+</button>"
            "<button data-zoom=\"out\" title=\"zoom out\">&minus;</button><button "
            "data-zoom=\"whole\" title=\"the whole graph in the box\">whole graph</button> "
            "wheel: zoom &middot; drag: pan &middot; hover a node or an edge: its text</div><div "
            "class=\"graph\" "
            "id=\"graph-step\">" +
            c.graph_svg + "</div><figcaption>" + escape(c.graph_caption) + "</figcaption></figure>";
    if (!c.quotient_svg.empty())
      body += "<figure class=\"quotient-figure\"><div class=\"graph\" id=\"graph-quotient\">" +
              c.quotient_svg + "</div><figcaption>" + escape(c.quotient_caption) +
              "</figcaption></figure>";
    body += "</div>";
  }
  body += "<p><small>Charts and pan/zoom: " + escape(std::string(detail::web_asset_versions())) +
          ", inlined; the page uses no network.</small></p>";

  std::string h = page_head(c.title, kStyle, {"vega", "vega-lite", "vega-embed", "panzoom"}) + body;
  h += "<script type=\"application/json\" id=\"tgraph-specs\">" + script_json(specs) + "</script>";
  h += "<script>" + std::string(kRenderScript) + "</script>";
  if (!c.graph_svg.empty()) h += "<script>" + std::string(kPanZoomScript) + "</script>";
  h += "</body></html>\n";
  return h;
}

}  // namespace tgraph::viz
