// SPDX-License-Identifier: MIT
// Replay timelines: the cairo Gantt chart, Chrome trace events with flow arrows.
#include "tgraph/viz/timeline.hpp"

#include <cairo.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <tuple>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/viz/palette.hpp"
#include "chart_util.hpp"

namespace tgraph::viz {
namespace {

using nlohmann::json;
using detail::decimals_for;
using detail::set_colour;
using detail::text_at;
using detail::tick_step;

// ---- cairo helpers -----------------------------------------------------------------------

// Grey diagonal hatching for waits.
cairo_pattern_t* hatch_pattern() {
  cairo_surface_t* tile = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, 6, 6);
  cairo_t* c = cairo_create(tile);
  set_colour(c, kWaitFill, 0.35);
  cairo_paint(c);
  set_colour(c, "#444444");
  cairo_set_line_width(c, 1.2);
  cairo_move_to(c, -1, 7);
  cairo_line_to(c, 7, -1);
  cairo_stroke(c);
  cairo_destroy(c);
  cairo_pattern_t* p = cairo_pattern_create_for_surface(tile);
  cairo_pattern_set_extend(p, CAIRO_EXTEND_REPEAT);
  cairo_surface_destroy(tile);
  return p;
}

// Draws the chart on `cr`; returns nothing, sizes come from ChartLayout.
struct ChartLayout {
  double width = 1200, left = 96, right = 24, top = 56, row = 22, gap = 4;
  double legend_row = 18;
  std::uint32_t threads = 1;
  std::size_t legend_items = 0;
  double plot_bottom() const { return top + threads * row; }
  double height() const {
    const double per_row = std::floor((width - left - right) / 170.0);
    const double rows = std::ceil(static_cast<double>(legend_items) / std::max(1.0, per_row));
    return plot_bottom() + 44 + rows * legend_row + 12;
  }
};

void draw(cairo_t* cr, const Timeline& t, const ChartLayout& L, const std::string& title,
          const std::vector<std::string>& ranked_kinds) {
  const std::vector<std::int64_t> offsets = t.step_offsets();
  std::int64_t end_ns = 1;
  for (const TimelineTask& e : t.tasks) end_ns = std::max(end_ns, offsets[e.step] + e.end_ns);
  for (const TimelineWait& w : t.waits) end_ns = std::max(end_ns, offsets[w.step] + w.end_ns);
  std::int64_t begin_ns = end_ns;
  for (const TimelineTask& e : t.tasks) begin_ns = std::min(begin_ns, offsets[e.step] + e.start_ns);
  for (const TimelineWait& w : t.waits) begin_ns = std::min(begin_ns, offsets[w.step] + w.start_ns);
  if (t.tasks.empty() && t.waits.empty()) begin_ns = 0;
  begin_ns = std::min<std::int64_t>(begin_ns, offsets.empty() ? 0 : offsets.front());
  const double span_ms = static_cast<double>(end_ns - begin_ns) / 1e6;
  const double plot_w = L.width - L.left - L.right;
  auto x_of = [&](std::int64_t ns) {
    return L.left + static_cast<double>(ns - begin_ns) / 1e6 / span_ms * plot_w;
  };
  auto y_of = [&](std::uint32_t thread) { return L.top + thread * L.row; };

  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  set_colour(cr, "#FFFFFF");
  cairo_paint(cr);
  set_colour(cr, "#000000");
  text_at(cr, L.left, 20, title, 14);

  // Rows.
  for (std::uint32_t th = 0; th < L.threads; ++th) {
    set_colour(cr, th % 2 ? "#F4F4F4" : "#FFFFFF");
    cairo_rectangle(cr, L.left, y_of(th), plot_w, L.row);
    cairo_fill(cr);
    set_colour(cr, "#000000");
    text_at(cr, L.left - 8, y_of(th) + L.row / 2 + 4, "thread " + std::to_string(th), 11, 1);
  }
  // Tasks.
  std::map<std::string, std::string> colour;
  for (std::size_t i = 0; i < ranked_kinds.size(); ++i)
    colour[ranked_kinds[i]] = kind_colour(static_cast<std::uint32_t>(i));
  for (const TimelineTask& e : t.tasks) {
    const double x0 = x_of(offsets[e.step] + e.start_ns), x1 = x_of(offsets[e.step] + e.end_ns);
    const auto it = colour.find(e.kind);
    set_colour(cr, it == colour.end() ? kind_colour(kKindColours) : it->second);
    cairo_rectangle(cr, x0, y_of(e.thread) + L.gap / 2, std::max(x1 - x0, 0.3), L.row - L.gap);
    cairo_fill(cr);
  }
  // Waits, hatched.
  cairo_pattern_t* hatch = hatch_pattern();
  for (const TimelineWait& w : t.waits) {
    const double x0 = x_of(offsets[w.step] + w.start_ns), x1 = x_of(offsets[w.step] + w.end_ns);
    cairo_set_source(cr, hatch);
    cairo_rectangle(cr, x0, y_of(w.thread) + L.gap / 2, std::max(x1 - x0, 0.3), L.row - L.gap);
    cairo_fill(cr);
  }
  // Loop iterations: a dotted line where each iteration's first instance starts.
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::int64_t> iteration_start;
  for (const TimelineTask& e : t.tasks) {
    if (e.iteration == 0) continue;
    auto [it, fresh] = iteration_start.try_emplace({e.step, e.iteration}, e.start_ns);
    if (!fresh) it->second = std::min(it->second, e.start_ns);
  }
  const double dashes[] = {2.0, 3.0};
  cairo_set_line_width(cr, 0.8);
  for (const auto& [key, start] : iteration_start) {
    const double x = x_of(offsets[key.first] + start);
    set_colour(cr, "#555555");
    cairo_set_dash(cr, dashes, 2, 0);
    cairo_move_to(cr, x, L.top - 6);
    cairo_line_to(cr, x, L.plot_bottom());
    cairo_stroke(cr);
  }
  cairo_set_dash(cr, nullptr, 0, 0);
  if (!iteration_start.empty()) {
    set_colour(cr, "#555555");
    text_at(cr, L.width - L.right, L.top - 10, "dotted: start of a loop iteration", 9, 1);
  }
  // Step boundaries.
  std::vector<std::uint32_t> steps;
  for (const TimelineTask& e : t.tasks)
    if (steps.empty() || steps.back() != e.step) steps.push_back(e.step);
  std::sort(steps.begin(), steps.end());
  steps.erase(std::unique(steps.begin(), steps.end()), steps.end());
  cairo_set_line_width(cr, 1.5);
  for (std::uint32_t s : steps) {
    const double x = x_of(offsets[s]);
    set_colour(cr, "#000000");
    cairo_move_to(cr, x, L.top - 16);
    cairo_line_to(cr, x, L.plot_bottom());
    cairo_stroke(cr);
    text_at(cr, x + 3, L.top - 8, "step " + std::to_string(s), 10);
  }
  // Axis.
  const double step = tick_step(span_ms, 10);
  const int decimals = decimals_for(step);
  set_colour(cr, "#000000");
  cairo_set_line_width(cr, 1);
  cairo_move_to(cr, L.left, L.plot_bottom());
  cairo_line_to(cr, L.left + plot_w, L.plot_bottom());
  cairo_stroke(cr);
  const double first_ms = static_cast<double>(begin_ns) / 1e6;
  for (double v = std::ceil(first_ms / step) * step; v <= first_ms + span_ms + step * 1e-6;
       v += step) {
    const double x = L.left + (v - first_ms) / span_ms * plot_w;
    cairo_move_to(cr, x, L.plot_bottom());
    cairo_line_to(cr, x, L.plot_bottom() + 4);
    cairo_stroke(cr);
    text_at(cr, x, L.plot_bottom() + 16, fixed(v, decimals), 10, 0.5);
  }
  text_at(cr, L.left + plot_w / 2, L.plot_bottom() + 32, "time (ms)", 11, 0.5);
  // Legend: kinds by time, then "other" and the waits.
  double lx = L.left, ly = L.plot_bottom() + 44;
  auto legend = [&](const std::string& label, cairo_pattern_t* pattern, const std::string& hex) {
    if (lx + 170 > L.width - L.right) {
      lx = L.left;
      ly += L.legend_row;
    }
    if (pattern) {
      cairo_set_source(cr, pattern);
    } else {
      set_colour(cr, hex);
    }
    cairo_rectangle(cr, lx, ly, 12, 12);
    cairo_fill(cr);
    set_colour(cr, "#000000");
    text_at(cr, lx + 16, ly + 10, label.size() > 24 ? label.substr(0, 23) + "." : label, 10);
    lx += 170;
  };
  for (std::size_t i = 0; i < ranked_kinds.size() && i < kKindColours; ++i)
    legend(ranked_kinds[i], nullptr, kind_colour(static_cast<std::uint32_t>(i)));
  if (ranked_kinds.size() > kKindColours) legend("other kinds", nullptr, kind_colour(kKindColours));
  if (!t.waits.empty()) legend("blocking wait", hatch, "");
  cairo_pattern_destroy(hatch);
}

// Kinds by total time, longest first (ties by name).
std::vector<std::string> rank_kinds(const Timeline& t) {
  std::map<std::string, std::int64_t> total;
  for (const TimelineTask& e : t.tasks) total[e.kind] += e.end_ns - e.start_ns;
  std::vector<std::pair<std::string, std::int64_t>> v(total.begin(), total.end());
  std::stable_sort(v.begin(), v.end(),
                   [](const auto& a, const auto& b) { return a.second > b.second; });
  std::vector<std::string> out;
  for (const auto& [k, ns] : v) out.push_back(k);
  return out;
}

}  // namespace

std::string timeline_title(const Timeline& t, const std::string& path) {
  return std::filesystem::path(path).filename().string() + ": " + std::to_string(t.threads) +
         " threads, " + std::to_string(t.tasks.size()) + " task instances, " +
         std::to_string(t.waits.size()) + " blocking waits";
}

std::optional<std::pair<std::uint32_t, std::uint32_t>> parse_step_range(std::string_view text) {
  const auto number = [](std::string_view s, std::uint32_t& v) {  // empty: v stays
    const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    return s.empty() || (ec == std::errc() && p == s.data() + s.size());
  };
  const std::size_t colon = std::min(text.find(':'), text.size());
  std::uint32_t a = 0, b = 0xffffffffu;
  if (text.empty() || !number(text.substr(0, colon), a) ||
      !number(colon == text.size() ? text : text.substr(colon + 1), b) || a > b)
    return std::nullopt;
  return std::pair{a, b};
}

Timeline select_steps(const Timeline& t, std::uint32_t first, std::uint32_t last) {
  Timeline out;
  out.threads = t.threads;
  out.steps = t.steps;
  for (const TimelineTask& e : t.tasks)
    if (e.step >= first && e.step <= last) out.tasks.push_back(e);
  for (const TimelineWait& w : t.waits)
    if (w.step >= first && w.step <= last) out.waits.push_back(w);
  if (out.tasks.empty()) {
    std::uint32_t hi = 0;
    for (const TimelineTask& e : t.tasks) hi = std::max(hi, e.step);
    throw OptionError("steps", "no task in steps " + std::to_string(first) + " to " +
                                   std::to_string(last) + " (the timeline has steps 0 to " +
                                   std::to_string(hi) + ")");
  }
  return out;
}

std::string_view to_string(TimelineFormat f) {
  switch (f) {
    case TimelineFormat::kSvg:
      return "svg";
    case TimelineFormat::kPng:
      return "png";
  }
  return "?";
}

TimelineFormat timeline_format_of(const std::string& path) {
  const auto dot = path.rfind('.');
  std::string ext = dot == std::string::npos ? std::string() : path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (TimelineFormat f : {TimelineFormat::kSvg, TimelineFormat::kPng})
    if (to_string(f) == ext) return f;
  throw UsageError("", "{output} " + path + ": expected a .svg or .png file name", kNamesFields);
}

void draw_timeline(const std::string& input, const std::string& steps,
                   const std::string& output) {
  const TimelineFormat format = timeline_format_of(output);
  Timeline t = read_timeline(input);
  if (!steps.empty()) {
    const auto r = parse_step_range(steps);
    if (!r)
      throw UsageError("", "{steps} " + steps + ": expected a:b, a: or a (steps, a <= b)",
                       kNamesFields);
    t = select_steps(t, r->first, r->second);
  }
  write_file_atomic(output, render_timeline(t, format, timeline_title(t, input)));
}

std::string render_timeline(const Timeline& t, TimelineFormat format, const std::string& title) {
  const std::vector<std::string> kinds = rank_kinds(t);
  ChartLayout L;
  L.threads = std::max<std::uint32_t>(t.threads, 1);
  L.legend_items =
      std::min<std::size_t>(kinds.size(), kKindColours + 1) + (t.waits.empty() ? 0 : 1);
  const double h = L.height();
  return detail::render_cairo(format, L.width, h,
                              [&](cairo_t* cr) { draw(cr, t, L, title, kinds); });
}

std::vector<TimelineFlow> timeline_flows(const Timeline& t) {
  // Task instances of each step by end time.
  std::map<std::uint32_t, std::vector<std::size_t>> by_step;
  for (std::size_t i = 0; i < t.tasks.size(); ++i) by_step[t.tasks[i].step].push_back(i);
  for (auto& [s, v] : by_step)
    std::sort(v.begin(), v.end(),
              [&](std::size_t a, std::size_t b) { return t.tasks[a].end_ns < t.tasks[b].end_ns; });
  std::vector<TimelineFlow> flows;
  for (std::size_t w = 0; w < t.waits.size(); ++w) {
    const TimelineWait& wait = t.waits[w];
    const auto it = by_step.find(wait.step);
    if (it == by_step.end()) continue;
    const std::vector<std::size_t>& v = it->second;
    // Last instance ending at or before the wait's end.
    auto pos =
        std::upper_bound(v.begin(), v.end(), wait.end_ns,
                         [&](std::int64_t ns, std::size_t i) { return ns < t.tasks[i].end_ns; });
    while (pos != v.begin()) {
      --pos;
      const TimelineTask& e = t.tasks[*pos];
      if (e.thread != wait.thread) {
        flows.push_back({*pos, w});
        break;
      }
    }
  }
  return flows;
}

std::string chrome_trace(const Timeline& t) {
  const std::vector<std::int64_t> offsets = t.step_offsets();
  auto us = [&](std::uint32_t step, std::int64_t ns) {
    return static_cast<double>(offsets[step] + ns) / 1000.0;
  };
  json ev = json::array();
  for (const TimelineTask& e : t.tasks)
    ev.push_back({{"name", e.kind},
                  {"cat", e.origin ? "task" : "reducer"},
                  {"ph", "X"},
                  {"pid", 0},
                  {"tid", e.thread},
                  {"ts", us(e.step, e.start_ns)},
                  {"dur", static_cast<double>(e.end_ns - e.start_ns) / 1000.0},
                  {"args", {{"step", e.step}, {"task", e.task}, {"iteration", e.iteration}}}});
  for (const TimelineWait& w : t.waits)
    ev.push_back({{"name", w.parked ? "wait (parked)" : "wait"},
                  {"cat", "wait"},
                  {"ph", "X"},
                  {"pid", 0},
                  {"tid", w.thread},
                  {"ts", us(w.step, w.start_ns)},
                  {"dur", static_cast<double>(w.end_ns - w.start_ns) / 1000.0},
                  {"args", {{"step", w.step}, {"task", w.task ? json(*w.task) : json(nullptr)}}}});
  // Flow arrows: the start binds to the signalling task's slice (just before its end), the
  // finish to the wait's slice at its end ("bp": "e": the enclosing slice).
  std::uint64_t id = 0;
  for (const TimelineFlow& f : timeline_flows(t)) {
    const TimelineTask& from = t.tasks[f.from_task];
    const TimelineWait& to = t.waits[f.to_wait];
    const double from_ts =
        std::max(us(from.step, from.start_ns), us(from.step, from.end_ns) - 0.001);
    const double to_ts = std::max(us(to.step, to.start_ns), us(to.step, to.end_ns) - 0.001);
    ev.push_back({{"name", "signal"},
                  {"cat", "dependency"},
                  {"ph", "s"},
                  {"id", id},
                  {"pid", 0},
                  {"tid", from.thread},
                  {"ts", from_ts}});
    ev.push_back({{"name", "signal"},
                  {"cat", "dependency"},
                  {"ph", "f"},
                  {"bp", "e"},
                  {"id", id},
                  {"pid", 0},
                  {"tid", to.thread},
                  {"ts", to_ts}});
    ++id;
  }
  for (std::uint32_t th = 0; th < t.threads; ++th)
    ev.push_back({{"name", "thread_name"},
                  {"ph", "M"},
                  {"pid", 0},
                  {"tid", th},
                  {"args", {{"name", "thread " + std::to_string(th)}}}});
  return json{{"traceEvents", ev}, {"displayTimeUnit", "ns"}}.dump();
}

}  // namespace tgraph::viz
