// SPDX-License-Identifier: MIT
// The report's charts: Vega-Lite specifications written from the report's content and the
// replay timeline (report.cpp lays out the page around them).
#include "report_specs.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <set>
#include <string>

#include "tgraph/viz/palette.hpp"

namespace tgraph::viz::detail {
namespace {

using nlohmann::json;

// Timeline events embedded in the page at most (the first steps up to this many).
constexpr std::size_t kMaxTimelineEvents = 6000;

json colour_range(std::size_t n) {
  json r = json::array();
  for (std::size_t i = 0; i < n; ++i) r.push_back(processor_colour(static_cast<std::uint32_t>(i)));
  return r;
}

// Speed-up against threads: measured points, predicted lines, the ideal and the bound.
}  // namespace

json speedup_spec(const ReportContent& c) {
  json values = json::array();
  std::set<std::uint32_t> ks;
  std::set<std::string> methods;
  for (const MethodRow& r : c.rows) {
    if (r.predicted_speedup)
      values.push_back({{"method", r.method},
                        {"threads", r.k},
                        {"speedup", *r.predicted_speedup},
                        {"series", "predicted (simulated)"}});
    if (r.speedup)
      values.push_back({{"method", r.method},
                        {"threads", r.k},
                        {"speedup", *r.speedup},
                        {"series", "measured (replay)"}});
    if (r.predicted_speedup || r.speedup) {
      ks.insert(r.k);
      methods.insert(r.method);
    }
  }
  ks.insert(1);
  json refs = json::array();
  const std::uint32_t kmax = *ks.rbegin();
  for (std::uint32_t k = 1;; k = std::min(kmax, k * 2)) {
    refs.push_back(
        {{"threads", k}, {"speedup", static_cast<double>(k)}, {"line", "ideal (= threads)"}});
    if (c.parallelism > 0)
      refs.push_back({{"threads", k},
                      {"speedup", std::min(static_cast<double>(k), c.parallelism)},
                      {"line", "bound min(threads, work/span)"}});
    if (k == kmax) break;
  }
  const json x = {{"field", "threads"},
                  {"type", "quantitative"},
                  {"title", "threads / processors (K)"},
                  {"scale", {{"type", "log"}, {"base", 2}}},
                  {"axis", {{"values", ks}, {"format", "d"}}}};
  const json y = {
      {"field", "speedup"}, {"type", "quantitative"}, {"title", "speed-up over sequential (×)"}};
  const json colour = {
      {"field", "method"},
      {"type", "nominal"},
      {"title", "method"},
      {"scale", {{"range", colour_range(std::max<std::size_t>(methods.size(), 1))}}}};
  json layers = json::array();
  layers.push_back({{"data", {{"values", refs}}},
                    {"mark", {{"type", "line"}, {"color", "#000000"}, {"strokeWidth", 1}}},
                    {"encoding",
                     {{"x", x},
                      {"y", y},
                      {"strokeDash",
                       {{"field", "line"},
                        {"type", "nominal"},
                        {"title", "reference"},
                        {"scale", {{"range", {{2, 2}, {6, 3}}}}}}}}}});
  // The points of one series ("predicted (simulated)" or "measured (replay)") drawn as `mark`.
  auto series_layer = [&](const char* series, json mark) {
    return json{{"transform", {{{"filter", std::string("datum.series === '") + series + "'"}}}},
                {"mark", std::move(mark)},
                {"encoding",
                 {{"x", x},
                  {"y", y},
                  {"color", colour},
                  {"tooltip",
                   {{{"field", "method"}},
                    {{"field", "threads"}},
                    {{"field", "speedup"}, {"format", ".2f"}},
                    {{"field", "series"}}}}}}};
  };
  layers.push_back(series_layer(
      "predicted (simulated)",
      {{"type", "line"}, {"point", {{"filled", false}, {"size", 60}}}, {"strokeDash", {4, 2}}}));
  layers.push_back(series_layer(
      "measured (replay)",
      {{"type", "point"}, {"filled", true}, {"size", 110}, {"shape", "diamond"}}));
  return {{"$schema", "https://vega.github.io/schema/vega-lite/v5.json"},
          {"width", 520},
          {"height", 320},
          {"title",
           {{"text", "Speed-up against threads"},
            {"subtitle",
             "diamonds: measured; open circles, dashed: predicted; black: ideal and bound"}}},
          {"data", {{"values", values}}},
          {"layer", layers}};
}

// Bars of measured and predicted speed-up per method at the largest K measured.
json methods_spec(const ReportContent& c) {
  json values = json::array();
  for (const MethodRow& r : c.rows) {
    const std::string label = r.method + " (K=" + std::to_string(r.k) + ")";
    if (r.speedup)
      values.push_back({{"row", label}, {"speedup", *r.speedup}, {"series", "measured"}});
    if (r.predicted_speedup)
      values.push_back(
          {{"row", label}, {"speedup", *r.predicted_speedup}, {"series", "predicted"}});
  }
  return {{"$schema", "https://vega.github.io/schema/vega-lite/v5.json"},
          {"width", 420},
          {"title", "Speed-up per method (×)"},
          {"data", {{"values", values}}},
          {"mark", {{"type", "bar"}, {"tooltip", true}}},
          {"encoding",
           {{"y", {{"field", "row"}, {"type", "nominal"}, {"title", nullptr}, {"sort", nullptr}}},
            {"yOffset", {{"field", "series"}}},
            {"x",
             {{"field", "speedup"},
              {"type", "quantitative"},
              {"title", "speed-up over sequential (×)"}}},
            {"color",
             {{"field", "series"},
              {"type", "nominal"},
              {"title", nullptr},
              {"scale",
               {{"domain", {"measured", "predicted"}}, {"range", {"#0072B2", "#E69F00"}}}}}}}}};
}

// Per-step partition time or migrations, one line per method, contact changes as rules.
json series_spec(const ReportContent& c, bool migrations) {
  json values = json::array();
  for (const StepSeries& s : c.series) {
    const std::string label = s.method + " (K=" + std::to_string(s.k) + ")";
    const std::size_t n = migrations ? s.migrated_tasks.size() : s.partition_ms.size();
    for (std::size_t i = 0; i < n; ++i)
      values.push_back(
          {{"method", label},
           {"step", i},
           {"value", migrations ? static_cast<double>(s.migrated_tasks[i]) : s.partition_ms[i]}});
  }
  json rules = json::array();
  for (std::uint32_t s : c.contact_changes) rules.push_back({{"step", s}});
  const char* title = migrations ? "migrated tasks" : "partition time (ms)";
  json layers = json::array();
  layers.push_back(
      {{"mark", {{"type", "line"}, {"point", true}}},
       {"encoding",
        {{"x",
          {{"field", "step"},
           {"type", "quantitative"},
           {"title", "step"},
           {"axis", {{"format", "d"}}}}},
         {"y", {{"field", "value"}, {"type", "quantitative"}, {"title", title}}},
         {"color",
          {{"field", "method"},
           {"type", "nominal"},
           {"title", "method"},
           {"scale", {{"range", colour_range(std::max<std::size_t>(c.series.size(), 1))}}}}},
         {"tooltip",
          {{{"field", "method"}},
           {{"field", "step"}},
           {{"field", "value"}, {"format", ".3~f"}}}}}}});
  if (!rules.empty())
    layers.push_back({{"data", {{"values", rules}}},
                      {"mark", {{"type", "rule"}, {"color", "#D55E00"}, {"strokeDash", {3, 3}}}},
                      {"encoding", {{"x", {{"field", "step"}, {"type", "quantitative"}}}}}});
  return {{"$schema", "https://vega.github.io/schema/vega-lite/v5.json"},
          {"width", 420},
          {"height", 220},
          {"title",
           {{"text", migrations ? "Migrations per step" : "Partition time per step"},
            {"subtitle", rules.empty() ? "" : "vermillion rules: steps whose contacts changed"}}},
          {"data", {{"values", values}}},
          {"layer", layers}};
}

// The replay timeline as a Gantt chart (first steps, at most kMaxTimelineEvents tasks).
json timeline_spec(const Timeline& t, std::string* caption, const explain::Explanation* path) {
  const std::vector<std::int64_t> offsets = t.step_offsets();
  json tasks = json::array(), waits = json::array();
  std::uint32_t last_step = 0;
  std::size_t shown = 0;
  for (const TimelineTask& e : t.tasks) {
    if (shown >= kMaxTimelineEvents && e.step != last_step) break;
    last_step = e.step;
    ++shown;
    tasks.push_back({{"thread", "thread " + std::to_string(e.thread)},
                     {"start", static_cast<double>(offsets[e.step] + e.start_ns) / 1e6},
                     {"end", static_cast<double>(offsets[e.step] + e.end_ns) / 1e6},
                     {"kind", e.kind},
                     {"step", e.step},
                     {"iteration", e.iteration}});
  }
  for (const TimelineWait& w : t.waits)
    if (w.step <= last_step)
      waits.push_back({{"thread", "thread " + std::to_string(w.thread)},
                       {"start", static_cast<double>(offsets[w.step] + w.start_ns) / 1e6},
                       {"end", static_cast<double>(offsets[w.step] + w.end_ns) / 1e6},
                       {"kind", "blocking wait"}});
  json steps = json::array();
  for (std::uint32_t s = 0; s <= last_step && s < offsets.size(); ++s)
    steps.push_back(
        {{"start", static_cast<double>(offsets[s]) / 1e6}, {"label", "step " + std::to_string(s)}});
  if (shown < t.tasks.size())
    *caption += " Steps 0 to " + std::to_string(last_step) + " shown (" + with_commas(shown) +
                " of " + with_commas(t.tasks.size()) +
                " task instances); the timeline drawn on its own shows any range of steps.";
  json kind_range = json::array();
  for (std::uint32_t i = 0; i < kKindColours; ++i) kind_range.push_back(kind_colour(i));
  const json x = {{"field", "start"}, {"type", "quantitative"}, {"title", "time (ms)"}};
  const json y = {{"field", "thread"},
                  {"type", "nominal"},
                  {"title", nullptr},
                  {"sort", {{"field", "thread"}}}};
  json layers = json::array();
  layers.push_back({{"data", {{"values", tasks}}},
                    {"mark", {{"type", "bar"}, {"height", {{"band", 0.8}}}}},
                    {"encoding",
                     {{"x", x},
                      {"x2", {{"field", "end"}}},
                      {"y", y},
                      {"color",
                       {{"field", "kind"},
                        {"type", "nominal"},
                        {"title", "task kind"},
                        {"scale", {{"range", kind_range}}}}},
                      {"tooltip",
                       {{{"field", "kind"}},
                        {{"field", "thread"}},
                        {{"field", "step"}},
                        {{"field", "iteration"}},
                        {{"field", "start"}, {"format", ".3f"}},
                        {{"field", "end"}, {"format", ".3f"}}}}}}});
  if (!waits.empty())
    layers.push_back(
        {{"data", {{"values", waits}}},
         {"mark",
          {{"type", "bar"}, {"height", {{"band", 0.35}}}, {"color", "#444444"}, {"opacity", 0.7}}},
         {"encoding",
          {{"x", x},
           {"x2", {{"field", "end"}}},
           {"y", y},
           {"tooltip",
            {{{"field", "kind"}},
             {{"field", "start"}, {"format", ".3f"}},
             {{"field", "end"}, {"format", ".3f"}}}}}}});
  // The executed critical path of the steps shown: its bodies outlined, its hand-offs as
  // slanted links from the writer's end to the reader's start.
  json path_bodies = json::array(), path_links = json::array();
  if (path)
    for (const explain::StepExplanation& s : path->steps) {
      if (s.step > last_step || s.step >= offsets.size()) continue;
      const double at = static_cast<double>(offsets[s.step] - s.serial_ns);
      for (std::size_t k = 0; k < s.critical_path.size(); ++k) {
        const explain::PathLink& l = s.critical_path[k];
        if (l.link == explain::Link::kBody) {
          path_bodies.push_back({{"thread", "thread " + std::to_string(l.thread)},
                                 {"start", (at + static_cast<double>(l.start_ns)) / 1e6},
                                 {"end", (at + static_cast<double>(l.end_ns)) / 1e6},
                                 {"kind", l.kind},
                                 {"link", "critical path: body"}});
        } else if (l.link == explain::Link::kHandoff && k > 0) {
          const explain::PathLink& from = s.critical_path[k - 1];
          path_links.push_back({{"thread", "thread " + std::to_string(from.thread)},
                                {"thread2", "thread " + std::to_string(l.thread)},
                                {"start", (at + static_cast<double>(l.start_ns)) / 1e6},
                                {"end", (at + static_cast<double>(l.end_ns)) / 1e6},
                                {"link", "critical path: hand-off"}});
        }
      }
    }
  if (!path_bodies.empty())
    layers.push_back({{"name", "critical-path"},
                      {"data", {{"values", path_bodies}}},
                      {"mark",
                       {{"type", "bar"},
                        {"height", {{"band", 0.95}}},
                        {"fillOpacity", 0},
                        {"stroke", "#000000"},
                        {"strokeWidth", 2}}},
                      {"encoding",
                       {{"x", x},
                        {"x2", {{"field", "end"}}},
                        {"y", y},
                        {"tooltip",
                         {{{"field", "link"}},
                          {{"field", "kind"}},
                          {{"field", "start"}, {"format", ".3f"}},
                          {{"field", "end"}, {"format", ".3f"}}}}}}});
  if (!path_links.empty())
    layers.push_back({{"data", {{"values", path_links}}},
                      {"mark", {{"type", "rule"}, {"color", "#000000"}, {"strokeWidth", 2}}},
                      {"encoding",
                       {{"x", x},
                        {"x2", {{"field", "end"}}},
                        {"y", y},
                        {"y2", {{"field", "thread2"}}},
                        {"tooltip", {{{"field", "link"}}}}}}});
  layers.push_back({{"data", {{"values", steps}}},
                    {"mark", {{"type", "rule"}, {"color", "#000000"}, {"strokeWidth", 1.5}}},
                    {"encoding", {{"x", {{"field", "start"}, {"type", "quantitative"}}}}}});
  return {{"$schema", "https://vega.github.io/schema/vega-lite/v5.json"},
          {"width", 900},
          {"height", {{"step", 34}}},
          {"title",
           {{"text", "Replay timeline"},
            {"subtitle", path_bodies.empty()
                             ? "one row per thread; dark thin bars: blocking waits; black "
                               "rules: step starts"
                             : "one row per thread; dark thin bars: blocking waits; black "
                               "rules: step starts; outlined: the executed critical path"}}},
          {"layer", layers}};
}

namespace {

// Stacked bars of lost time (ms) by cause; `rows` holds {bar, cause, ms} records.
json lost_spec(const json& rows, const std::string& x_field, const std::string& x_title,
               const std::string& title, const std::string& subtitle) {
  json order = json::array();
  for (const std::string_view n : explain::cause_names()) order.push_back(std::string(n));
  json range = json::array();
  for (std::uint32_t i = 0; i < order.size(); ++i) range.push_back(kind_colour(i));
  return {{"$schema", "https://vega.github.io/schema/vega-lite/v5.json"},
          {"width", 420},
          {"height", 260},
          {"title", {{"text", title}, {"subtitle", subtitle}}},
          {"data", {{"values", rows}}},
          {"mark", "bar"},
          {"encoding",
           {{"x", {{"field", x_field}, {"type", "ordinal"}, {"title", x_title}}},
            {"y",
             {{"field", "ms"},
              {"type", "quantitative"},
              {"stack", "zero"},
              {"title", "lost processor time (ms)"}}},
            {"color",
             {{"field", "cause"},
              {"type", "nominal"},
              {"sort", order},
              {"scale", {{"domain", order}, {"range", range}}}}},
            {"order", {{"field", "rank"}}},
            {"tooltip",
             {{{"field", x_field}},
              {{"field", "cause"}},
              {{"field", "ms"}, {"format", ".3f"}}}}}}};
}

}  // namespace

json lost_steps_spec(const explain::Explanation& e) {
  json rows = json::array();
  for (const explain::StepExplanation& s : e.steps) {
    int rank = 0;
    for (const std::string_view n : explain::cause_names())
      rows.push_back({{"step", s.step},
                      {"cause", std::string(n)},
                      {"rank", rank++},
                      {"ms", static_cast<double>(explain::cause(s.attribution.causes, n)) / 1e6}});
  }
  return lost_spec(rows, "step", "step", "Where the time went, step by step",
                   "threads x makespan - sequential work, by cause (tgraph explain)");
}

json lost_runs_spec(const std::vector<RunAttribution>& runs) {
  json rows = json::array();
  for (const RunAttribution& r : runs) {
    int rank = 0;
    for (const auto& [cause, ns] : r.causes)
      rows.push_back({{"run", r.label},
                      {"cause", cause},
                      {"rank", rank++},
                      {"ms", static_cast<double>(ns) / 1e6}});
  }
  return lost_spec(rows, "run", "run", "Where the time went, by run",
                   "the runs' lost processor time summed over their steps, by cause");
}

std::string with_commas(std::uint64_t v) {
  std::string s = std::to_string(v), out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (i && (s.size() - i) % 3 == 0) out += ',';
    out += s[i];
  }
  return out;
}

}  // namespace tgraph::viz::detail
