// SPDX-License-Identifier: MIT
// Line charts of numeric series: Vega-Lite specifications, cairo SVG/PNG, an HTML page.
#include "tgraph/viz/series_chart.hpp"

#include <cairo.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "chart_util.hpp"
#include "web_assets.hpp"

namespace tgraph::viz {
namespace {

using nlohmann::json;
using detail::decimals_for;
using detail::escape;
using detail::kRenderScript;
using detail::page_head;
using detail::script_json;
using detail::set_colour;
using detail::text_at;
using detail::tick_step;

// Okabe & Ito without yellow (too pale for lines on white), then Paul Tol's "muted".
constexpr std::array<const char*, 15> kLines = {
    "#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#332288", "#117733",
    "#882255", "#44AA99", "#999933", "#AA4499", "#CC6677", "#DDCC77", "#88CCEE"};
constexpr const char* kReferenceColour = "#000000";

bool usable(const SeriesChart& c, const SeriesPoint& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && (!c.log2_x || p.x > 0) &&
         (!c.log2_y || p.y > 0);
}

// A power of two as a tick label: "64", "0.5", "0.125".
std::string power_label(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string colour_of(const Series& s) {
  return s.kind == SeriesKind::kReference ? kReferenceColour : series_colour(s.colour);
}

// The axes' extents and ticks, shared by both renderings.
struct Axes {
  double x0 = 0, x1 = 1, y0 = 0, y1 = 1;  // in data units (log2 of them on a log axis)
  std::vector<double> x_ticks, y_ticks;   // the values themselves
  int x_decimals = 0, y_decimals = 0;
  std::string x_label(const SeriesChart& c, double v) const {
    return c.log2_x ? power_label(v) : fixed(v, x_decimals);
  }
  std::string y_label(const SeriesChart& c, double v) const {
    return c.log2_y ? power_label(v) : fixed(v, y_decimals);
  }
};

Axes axes_of(const SeriesChart& c) {
  double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin, ymax = 0;
  double ymin = std::numeric_limits<double>::infinity();
  for (const Series& s : c.series)
    for (const SeriesPoint& p : s.points)
      if (usable(c, p)) {
        xmin = std::min(xmin, p.x);
        xmax = std::max(xmax, p.x);
        ymin = std::min(ymin, p.y);
        ymax = std::max(ymax, p.y);
      }
  for (const SeriesMark& m : c.marks)
    if (std::isfinite(m.x) && (!c.log2_x || m.x > 0)) {
      xmin = std::min(xmin, m.x);
      xmax = std::max(xmax, m.x);
    }
  if (!std::isfinite(xmin)) xmin = xmax = c.log2_x ? 1 : 0;
  Axes a;
  if (c.log2_x) {
    const double lo = std::floor(std::log2(xmin)), hi = std::ceil(std::log2(xmax));
    a.x0 = lo;
    a.x1 = std::max(hi, lo + 1);
    for (double e = a.x0; e <= a.x1 + 1e-9; ++e) a.x_ticks.push_back(std::exp2(e));
  } else {
    if (xmax <= xmin) xmax = xmin + 1;
    const double step = tick_step(xmax - xmin, 8);
    a.x0 = std::floor(xmin / step) * step;
    a.x1 = std::ceil(xmax / step) * step;
    for (double v = a.x0; v <= a.x1 + step * 1e-6; v += step) a.x_ticks.push_back(v);
    a.x_decimals = decimals_for(step);
  }
  if (c.log2_y) {
    if (!std::isfinite(ymin)) ymin = ymax = 1;
    const double lo = std::floor(std::log2(ymin)), hi = std::ceil(std::log2(ymax));
    a.y0 = lo;
    a.y1 = std::max(hi, lo + 1);
    for (double e = a.y0; e <= a.y1 + 1e-9; ++e) a.y_ticks.push_back(std::exp2(e));
    return a;
  }
  if (ymax <= 0) ymax = 1;
  const double step = tick_step(ymax * 1.05, 6);
  a.y1 = std::ceil(ymax * 1.05 / step) * step;
  for (double v = 0; v <= a.y1 + step * 1e-6; v += step) a.y_ticks.push_back(v);
  a.y_decimals = decimals_for(step);
  return a;
}

// ---- cairo --------------------------------------------------------------------------------

struct Layout {
  double width = 860, left = 64, right = 230, top = 64, plot_h = 330, bottom = 48;
  double legend_row = 17;
  double height(std::size_t legend_items) const {
    return std::max(top + plot_h + bottom,
                    top + static_cast<double>(legend_items) * legend_row + 16);
  }
};

void set_dash(cairo_t* cr, SeriesKind kind) {
  static const double predicted[] = {7.0, 4.0};
  static const double reference[] = {2.0, 3.0};
  switch (kind) {
    case SeriesKind::kMeasured:
      cairo_set_dash(cr, nullptr, 0, 0);
      break;
    case SeriesKind::kPredicted:
      cairo_set_dash(cr, predicted, 2, 0);
      break;
    case SeriesKind::kReference:
      cairo_set_dash(cr, reference, 2, 0);
      break;
  }
}

void marker(cairo_t* cr, double x, double y, const Series& s) {
  if (s.kind == SeriesKind::kReference) return;
  cairo_set_dash(cr, nullptr, 0, 0);
  cairo_new_sub_path(cr);
  cairo_arc(cr, x, y, 3.6, 0, 2 * M_PI);
  if (s.kind == SeriesKind::kMeasured) {
    set_colour(cr, colour_of(s));
    cairo_fill(cr);
  } else {
    set_colour(cr, "#FFFFFF");
    cairo_fill_preserve(cr);
    set_colour(cr, colour_of(s));
    cairo_set_line_width(cr, 1.5);
    cairo_stroke(cr);
  }
}

void draw(cairo_t* cr, const SeriesChart& c, const Layout& L, double height) {
  const Axes a = axes_of(c);
  const double plot_w = L.width - L.left - L.right;
  const double bottom = L.top + L.plot_h;
  auto x_of = [&](double x) {
    const double v = c.log2_x ? std::log2(x) : x;
    return L.left + (v - a.x0) / (a.x1 - a.x0) * plot_w;
  };
  auto y_of = [&](double y) {
    const double v = c.log2_y ? std::log2(y) : y;
    return bottom - (v - a.y0) / (a.y1 - a.y0) * L.plot_h;
  };

  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  set_colour(cr, "#FFFFFF");
  cairo_rectangle(cr, 0, 0, L.width, height);
  cairo_fill(cr);
  set_colour(cr, "#000000");
  text_at(cr, L.left, 22, c.title, 15);
  set_colour(cr, "#555555");
  text_at(cr, L.left, 40, c.subtitle, 10.5);

  // Grid and y axis.
  cairo_set_line_width(cr, 1);
  for (double v : a.y_ticks) {
    set_colour(cr, "#E4E4E4");
    cairo_move_to(cr, L.left, y_of(v));
    cairo_line_to(cr, L.left + plot_w, y_of(v));
    cairo_stroke(cr);
    set_colour(cr, "#000000");
    text_at(cr, L.left - 6, y_of(v) + 3.5, a.y_label(c, v), 10, 1);
  }
  for (double v : a.x_ticks) {
    const double x = x_of(v);
    set_colour(cr, "#F0F0F0");
    cairo_move_to(cr, x, L.top);
    cairo_line_to(cr, x, bottom);
    cairo_stroke(cr);
    set_colour(cr, "#000000");
    cairo_move_to(cr, x, bottom);
    cairo_line_to(cr, x, bottom + 4);
    cairo_stroke(cr);
    text_at(cr, x, bottom + 16, a.x_label(c, v), 10, 0.5);
  }
  set_colour(cr, "#000000");
  cairo_move_to(cr, L.left, L.top);
  cairo_line_to(cr, L.left, bottom);
  cairo_line_to(cr, L.left + plot_w, bottom);
  cairo_stroke(cr);
  text_at(cr, L.left + plot_w / 2, bottom + 36, c.x_title, 11, 0.5);
  cairo_save(cr);
  cairo_move_to(cr, 16, L.top + L.plot_h / 2);
  cairo_rotate(cr, -M_PI / 2);
  cairo_set_font_size(cr, 11);
  cairo_text_extents_t ext;
  cairo_text_extents(cr, c.y_title.c_str(), &ext);
  cairo_rel_move_to(cr, -ext.x_advance / 2, 0);
  cairo_show_text(cr, c.y_title.c_str());
  cairo_restore(cr);

  // Marks.
  static const double dotted[] = {1.5, 3.0};
  for (const SeriesMark& m : c.marks) {
    if (!std::isfinite(m.x) || (c.log2_x && m.x <= 0)) continue;
    const double x = x_of(m.x);
    set_colour(cr, "#7F7F7F");
    cairo_set_line_width(cr, 1);
    cairo_set_dash(cr, dotted, 2, 0);
    cairo_move_to(cr, x, L.top - 4);
    cairo_line_to(cr, x, bottom);
    cairo_stroke(cr);
    cairo_set_dash(cr, nullptr, 0, 0);
    if (!m.label.empty()) text_at(cr, x + 3, L.top + 8, m.label, 9);
  }

  // Series: references under predictions under measurements.
  cairo_save(cr);
  cairo_rectangle(cr, L.left - 5, L.top - 5, plot_w + 10, L.plot_h + 10);
  cairo_clip(cr);
  for (SeriesKind kind : {SeriesKind::kReference, SeriesKind::kPredicted, SeriesKind::kMeasured})
    for (const Series& s : c.series) {
      if (s.kind != kind) continue;
      set_colour(cr, colour_of(s));
      cairo_set_line_width(cr, kind == SeriesKind::kReference ? 1.2 : 2.0);
      set_dash(cr, kind);
      bool first = true;
      for (const SeriesPoint& p : s.points) {
        if (!usable(c, p)) continue;
        if (first)
          cairo_move_to(cr, x_of(p.x), y_of(p.y));
        else
          cairo_line_to(cr, x_of(p.x), y_of(p.y));
        first = false;
      }
      cairo_stroke(cr);
      if (c.markers)
        for (const SeriesPoint& p : s.points)
          if (usable(c, p)) marker(cr, x_of(p.x), y_of(p.y), s);
    }
  cairo_restore(cr);

  // Legend.
  double ly = L.top;
  const double lx = L.left + plot_w + 18;
  for (const Series& s : c.series) {
    set_colour(cr, colour_of(s));
    cairo_set_line_width(cr, s.kind == SeriesKind::kReference ? 1.2 : 2.0);
    set_dash(cr, s.kind);
    cairo_move_to(cr, lx, ly + 5);
    cairo_line_to(cr, lx + 26, ly + 5);
    cairo_stroke(cr);
    if (c.markers) marker(cr, lx + 13, ly + 5, s);
    set_colour(cr, "#000000");
    const std::string label = s.name.size() > 34 ? s.name.substr(0, 33) + "." : s.name;
    text_at(cr, lx + 32, ly + 9, label, 10);
    ly += L.legend_row;
  }
}

}  // namespace

std::string_view to_string(SeriesKind kind) {
  switch (kind) {
    case SeriesKind::kMeasured:
      return "measured";
    case SeriesKind::kPredicted:
      return "predicted";
    case SeriesKind::kReference:
      return "reference";
  }
  return "?";
}

std::string series_colour(std::uint32_t i) { return kLines[i % kLines.size()]; }

std::string series_chart_spec(const SeriesChart& c) {
  const Axes a = axes_of(c);
  json values = json::array(), names = json::array(), colours = json::array();
  for (const Series& s : c.series) {
    names.push_back(s.name);
    colours.push_back(colour_of(s));
    for (const SeriesPoint& p : s.points)
      if (usable(c, p))
        values.push_back(
            {{"series", s.name}, {"kind", std::string(to_string(s.kind))}, {"x", p.x}, {"y", p.y}});
  }
  json x = {{"field", "x"}, {"type", "quantitative"}, {"title", c.x_title}};
  if (c.log2_x) {
    x["scale"] = {{"type", "log"},
                  {"base", 2},
                  {"domain", {std::exp2(a.x0), std::exp2(a.x1)}},
                  {"nice", false}};
    x["axis"] = {{"values", a.x_ticks}, {"format", "d"}};
  } else {
    x["scale"] = {{"domain", {a.x0, a.x1}}, {"nice", false}};
  }
  json y = {{"field", "y"}, {"type", "quantitative"}, {"title", c.y_title}};
  if (c.log2_y) {
    y["scale"] = {{"type", "log"},
                  {"base", 2},
                  {"domain", {std::exp2(a.y0), std::exp2(a.y1)}},
                  {"nice", false}};
    y["axis"] = {{"values", a.y_ticks}, {"format", "~g"}};
  } else {
    y["scale"] = {{"domain", {a.y0, a.y1}}, {"nice", false}};
  }
  const json colour = {{"field", "series"},
                       {"type", "nominal"},
                       {"title", nullptr},
                       {"sort", nullptr},
                       {"scale", {{"domain", names}, {"range", colours}}}};
  const json tooltip = {{{"field", "series"}},
                        {{"field", "kind"}},
                        {{"field", "x"}},
                        {{"field", "y"}, {"format", ".3~f"}}};
  json layers = json::array();
  layers.push_back({{"mark", {{"type", "line"}, {"clip", true}}},
                    {"encoding",
                     {{"x", x},
                      {"y", y},
                      {"color", colour},
                      {"detail", {{"field", "series"}}},
                      {"strokeDash",
                       {{"field", "kind"},
                        {"type", "nominal"},
                        {"title", nullptr},
                        {"scale",
                         {{"domain", {"measured", "predicted", "reference"}},
                          {"range", {{1, 0}, {7, 4}, {2, 3}}}}}}}}}});
  for (SeriesKind kind : {SeriesKind::kPredicted, SeriesKind::kMeasured}) {
    if (!c.markers) break;
    const std::string k(to_string(kind));
    layers.push_back({{"transform", {{{"filter", "datum.kind === '" + k + "'"}}}},
                      {"mark",
                       {{"type", "point"},
                        {"filled", kind == SeriesKind::kMeasured},
                        {"size", 45},
                        {"opacity", 1},
                        {"clip", true}}},
                      {"encoding", {{"x", x}, {"y", y}, {"color", colour}, {"tooltip", tooltip}}}});
  }
  json marks = json::array();
  for (const SeriesMark& m : c.marks)
    if (std::isfinite(m.x) && (!c.log2_x || m.x > 0))
      marks.push_back({{"x", m.x}, {"label", m.label}});
  if (!marks.empty()) {
    layers.push_back({{"data", {{"values", marks}}},
                      {"mark", {{"type", "rule"}, {"color", "#7F7F7F"}, {"strokeDash", {2, 3}}}},
                      {"encoding", {{"x", x}}}});
    layers.push_back(
        {{"data", {{"values", marks}}},
         {"mark", {{"type", "text"}, {"align", "left"}, {"dx", 3}, {"dy", 8}, {"fontSize", 9}}},
         {"encoding", {{"x", x}, {"y", {{"value", 0}}}, {"text", {{"field", "label"}}}}}});
  }
  const json spec = {{"$schema", "https://vega.github.io/schema/vega-lite/v5.json"},
                     {"width", 560},
                     {"height", 320},
                     {"title", {{"text", c.title}, {"subtitle", c.subtitle}}},
                     {"data", {{"values", values}}},
                     {"layer", layers}};
  return spec.dump();
}

std::string render_series_chart(const SeriesChart& c, TimelineFormat format) {
  const Layout L;
  const double h = L.height(c.series.size());
  return detail::render_cairo(format, L.width, h, [&](cairo_t* cr) { draw(cr, c, L, h); });
}

std::string series_page_html(const SeriesPage& p) {
  static const char* kStyle =
      "body{font-family:system-ui,Helvetica,Arial,sans-serif;margin:2em;max-width:1300px;"
      "color:#222}h1{font-size:1.5em}h2{font-size:1.2em;margin-top:2em;border-bottom:1px solid "
      "#ccc}table{border-collapse:collapse;font-size:0.85em;margin:0.5em 0 1.5em}td,th{border:"
      "1px solid #bbb;padding:3px 7px;text-align:right}th{background:#eee}td:first-child{"
      "text-align:left}caption{text-align:left;font-weight:600;padding:4px 0}dl{display:grid;"
      "grid-template-columns:max-content auto;gap:2px 16px}dt{font-weight:600}dd{margin:0}"
      ".charts{display:flex;flex-wrap:wrap;gap:24px}.chart-error{color:#D55E00}";
  std::string body = "<h1>" + escape(p.title) + "</h1>";
  for (const std::string& n : p.notes) body += "<p>" + escape(n) + "</p>";
  if (!p.facts.empty()) {
    body += "<dl>";
    for (const auto& [k, v] : p.facts)
      body += "<dt>" + escape(k) + "</dt><dd>" + escape(v) + "</dd>";
    body += "</dl>";
  }
  json specs = json::object();
  if (!p.charts.empty()) {
    body += "<h2>Charts</h2><div class=\"charts\">";
    for (std::size_t i = 0; i < p.charts.size(); ++i) {
      const std::string id = "chart-" + std::to_string(i);
      specs[id] = json::parse(series_chart_spec(p.charts[i]));
      body += "<div class=\"chart\" id=\"" + id + "\"></div>";
    }
    body += "</div>";
  }
  for (const SeriesTable& t : p.tables) {
    body += "<table>";
    if (!t.caption.empty()) body += "<caption>" + escape(t.caption) + "</caption>";
    body += "<thead><tr>";
    for (const std::string& c : t.columns) body += "<th>" + escape(c) + "</th>";
    body += "</tr></thead><tbody>";
    for (const std::vector<std::string>& row : t.rows) {
      body += "<tr>";
      for (const std::string& cell : row)
        body += cell.empty() ? "<td>&ndash;</td>" : "<td>" + escape(cell) + "</td>";
      body += "</tr>";
    }
    body += "</tbody></table>";
  }
  body += "<p><small>Charts: " + escape(std::string(detail::web_asset_versions())) +
          " (BSD-3-Clause), inlined; the page uses no network.</small></p>";
  std::string h = page_head(p.title, kStyle, {"vega", "vega-lite", "vega-embed"}) + body;
  h += "<script type=\"application/json\" id=\"tgraph-specs\">" + script_json(specs) + "</script>";
  h += "<script>" + std::string(kRenderScript) + "</script></body></html>\n";
  return h;
}

}  // namespace tgraph::viz
