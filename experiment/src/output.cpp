// SPDX-License-Identifier: MIT
#include "output.hpp"

#include <algorithm>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "tgraph/graph/file_util.hpp"
#include "tgraph/graph/fixed.hpp"
#include "tgraph/graph/json_util.hpp"

namespace tgraph::experiment {
namespace {

using nlohmann::json;

std::string thread_list(const std::vector<std::uint32_t>& ks) {
  std::string s;
  for (std::uint32_t k : ks) {
    if (!s.empty()) s += ',';
    s += std::to_string(k);
  }
  return s.empty() ? "none" : s;
}

std::string variant_label(const ResultRow& r) {
  return r.subobjects ? r.scene + "-s" + std::to_string(*r.subobjects) : r.scene;
}

// The name of a scene x method line in charts: the method alone for one scene, the scene
// alone for one method, both otherwise.
std::string line_name(const ExperimentPlan& p, const ResultRow& r) {
  if (p.scenes.size() == 1) return r.method;
  if (p.methods.size() == 1) return variant_label(r);
  return variant_label(r) + " " + r.method;
}

std::string scenes_text(const ExperimentPlan& p) {
  std::string s;
  for (const SceneVariant& v : p.scenes) {
    if (!s.empty()) s += ", ";
    s += v.label();
  }
  return s;
}

json measured_json(const Measured& m) {
  return {{"live_ms_per_step", m.live_ms_per_step},
          {"engine_ms_per_step", m.engine_ms_per_step},
          {"live_speedup", m.live_speedup},
          {"integration_speedup", m.integration_speedup},
          {"step_speedup", m.step_speedup},
          {"core_bound", m.core_bound},
          {"record_ms_per_step", m.record_ms_per_step},
          {"graph_update_ms_per_step", m.graph_update_ms_per_step},
          {"partition_ms_per_step", m.partition_ms_per_step},
          {"build_ms_per_step", m.build_ms_per_step},
          {"plans_built", m.plans_built},
          {"structure_changes", m.structure_changes},
          {"signals", m.signals},
          {"replay_ms_per_step", optional_json(m.replay_ms_per_step)},
          {"replay_sequential_ms_per_step", optional_json(m.replay_sequential_ms_per_step)},
          {"replay_speedup", optional_json(m.replay_speedup)}};
}

json predicted_json(const Predicted& p) {
  return {{"speedup", p.speedup},
          {"integration_speedup", p.integration_speedup},
          {"step_speedup", p.step_speedup},
          {"ms_per_step", p.ms_per_step},
          {"work_ms_per_step", p.work_ms_per_step},
          {"imbalance", p.imbalance},
          {"migrated_tasks", p.migrated_tasks},
          {"partition_ms_per_step", p.partition_ms_per_step}};
}

std::string cell(double v, int decimals) { return fixed(v, decimals); }

viz::SeriesTable results_table(const ExperimentResult& res) {
  viz::SeriesTable t;
  t.caption =
      "Per configuration (ms are per step). Measured: live run against the uninstrumented "
      "engine timed in the same run, and synthetic replay against sequential replay. "
      "Predicted: the simulator on the captured trace. Step speed-ups count the whole step "
      "(collision detection and host work included); integration speed-ups the task graph "
      "alone (the paper's measure): measured as the trace's work over the live task execution "
      "time, predicted as work / (makespan - host).";
  t.columns = {"scene",
               "method",
               "threads",
               "kind",
               "engine ms",
               "live ms",
               "live step speed-up",
               "live integration speed-up",
               "core bound",
               "partition ms",
               "graph update ms",
               "build ms",
               "replay speed-up",
               "predicted step speed-up",
               "predicted integration speed-up",
               "predicted ms",
               "predicted imbalance",
               "failure"};
  for (const ResultRow& r : res.rows) {
    std::vector<std::string> c = {variant_label(r), r.method, std::to_string(r.threads),
                                  std::string(r.threads_kind(res.plan.cores))};
    if (r.measured) {
      const Measured& m = *r.measured;
      c.insert(c.end(),
               {cell(m.engine_ms_per_step, 2), cell(m.live_ms_per_step, 2), cell(m.step_speedup, 2),
                cell(m.integration_speedup, 2), cell(m.core_bound, 2), cell(m.partition_ms_per_step, 3),
                cell(m.graph_update_ms_per_step, 3), cell(m.build_ms_per_step, 3),
                m.replay_speedup ? cell(*m.replay_speedup, 2) : ""});
    } else {
      c.resize(c.size() + 9);
    }
    if (r.predicted)
      c.insert(c.end(), {cell(r.predicted->step_speedup, 2), cell(r.predicted->integration_speedup, 2),
                         cell(r.predicted->ms_per_step, 2),
                         cell(r.predicted->imbalance, 3)});
    else
      c.resize(c.size() + 4);
    c.push_back(r.failure);
    t.rows.push_back(std::move(c));
  }
  return t;
}

viz::SeriesTable series_table(const ExperimentResult& res) {
  viz::SeriesTable t;
  t.caption = "Repartitioning at every step on " + std::to_string(res.plan.series_threads) +
              " threads (means per step; 'changed': steps recorded afresh because contacts or "
              "collision groups changed, step 0 excluded; graph update = edge derivation + "
              "plan build; new graph = recording (collision detection included) + partition + "
              "plan build).";
  t.columns = {"method",
               "steps",
               "changed steps",
               "live step ms",
               "engine step ms",
               "partition ms",
               "plan build ms",
               "migrated tasks",
               "graph update ms (changed)",
               "new graph ms (changed)",
               "new graph / engine step"};
  for (const SeriesSummary& s : res.series)
    t.rows.push_back({s.method, std::to_string(s.steps), std::to_string(s.structure_changes),
                      cell(s.step_ms, 2), cell(s.engine_ms, 2), cell(s.partition_ms, 3),
                      cell(s.build_ms, 3), std::to_string(s.migrated_tasks),
                      cell(s.update_ms_changed, 3), cell(s.new_graph_ms_changed, 3),
                      s.engine_ms > 0 ? cell(s.new_graph_ms_changed / s.engine_ms, 2) : ""});
  return t;
}

viz::SeriesPage page_of(const ExperimentResult& res) {
  const ExperimentPlan& p = res.plan;
  const PaperFigure paper = paper_figure(p.name);
  viz::SeriesPage page;
  page.title = "tgraph experiment " + std::string(to_string(p.name)) + ": " + scenes_text(p) +
               " (paper " + paper.figure + ")";
  page.notes = {
      "Paper (" + paper.figure + "): " + paper.text,
      "Measured on this machine at " + thread_list(p.threads.measured) +
          " threads: live runs (the engine's own task bodies through the executor), timed "
          "against the uninstrumented sequential engine in the same run, medians of " +
          std::to_string(p.repeat) + " passes of " + std::to_string(p.steps) +
          " steps. Predicted (never mixed with measured values): the simulator on the captured "
          "trace with the cost model's " +
          (res.cost_model == "defaults" ? std::string("defaults (no calibration file)")
                                        : "calibration file " + res.cost_model) +
          ", at every thread count including those beyond this machine's " +
          std::to_string(p.cores) + " cores."};
  if (p.replay)
    page.notes.push_back(
        "Replay speed-ups: the captured trace replayed with synthetic bodies (tgraph replay) "
        "against sequential replay in the same run, at more than one thread, not for starpu "
        "(its replay costs 4 to 7 times the sequential run).");
  for (const std::string& n : p.notes) page.notes.push_back(n);
  page.facts = {{"machine", res.machine.summary()},
                {"operating system", res.machine.os},
                {"date (UTC)", res.date},
                {"command", p.command()},
                {"steps per run", std::to_string(p.steps)},
                {"timed passes", std::to_string(p.repeat)},
                {"measured thread counts", thread_list(p.threads.measured)},
                {"predicted thread counts", thread_list(p.threads.all())},
                {"wall time", fixed(res.seconds, 1) + " s"}};
  page.charts.push_back(speedup_chart(res));
  for (auto& [file, chart] : step_charts(res)) page.charts.push_back(chart);
  if (!res.series.empty()) page.tables.push_back(series_table(res));
  page.tables.push_back(results_table(res));
  return page;
}

}  // namespace

viz::SeriesChart speedup_chart(const ExperimentResult& res) {
  const ExperimentPlan& p = res.plan;
  viz::SeriesChart c;
  c.title = "Speed-up against threads: " + scenes_text(p);
  c.subtitle = "solid: measured (live run / uninstrumented engine, same run, " +
               std::to_string(p.cores) + "-core machine); dashed: predicted by the simulator";
  c.x_title = "threads";
  c.y_title = "speed-up over sequential (x)";
  c.log2_x = true;
  c.log2_y = true;
  std::map<std::string, std::size_t> line_of;  // line name -> index in `names`
  std::vector<std::string> names;
  // Two measures, never mixed: the whole step (host work included) and the time
  // integration alone (the task graph, the paper's measure), each its own series.
  std::map<std::string, viz::Series> measured, predicted;
  auto point = [](std::map<std::string, viz::Series>& lines, const std::string& line, viz::SeriesKind kind,
                  std::uint32_t colour, std::uint32_t k, double v) {
    if (!(v > 0)) return;
    viz::Series& s = lines[line];
    if (s.name.empty()) s = viz::Series{line, kind, colour, {}};
    s.points.push_back({static_cast<double>(k), v});
  };
  for (const ResultRow& r : res.rows) {
    if (r.method.find("(every step)") != std::string::npos) continue;
    const std::string name = line_name(p, r);
    if (line_of.emplace(name, names.size()).second) names.push_back(name);
    const auto colour = static_cast<std::uint32_t>(line_of[name]);
    if (r.measured) {
      point(measured, name + " step", viz::SeriesKind::kMeasured, colour, r.threads, r.measured->step_speedup);
      point(measured, name + " integration", viz::SeriesKind::kMeasured, colour, r.threads,
            r.measured->integration_speedup);
    }
    if (r.predicted) {
      point(predicted, name + " step (predicted)", viz::SeriesKind::kPredicted, colour, r.threads,
            r.predicted->step_speedup);
      point(predicted, name + " integration (predicted)", viz::SeriesKind::kPredicted, colour, r.threads,
            r.predicted->integration_speedup);
    }
  }
  viz::Series ideal{"ideal (= threads)", viz::SeriesKind::kReference, 0, {}};
  for (std::uint32_t k : p.threads.all())
    ideal.points.push_back({static_cast<double>(k), static_cast<double>(k)});
  c.series.push_back(std::move(ideal));
  for (const auto* lines : {&measured, &predicted})
    for (const std::string& n : names)
      for (const char* what : {" step", " integration", " step (predicted)", " integration (predicted)"})
        if (const auto it = lines->find(n + what); it != lines->end()) c.series.push_back(it->second);
  if (!p.threads.predicted.empty())
    c.marks.push_back(
        {static_cast<double>(p.cores), std::to_string(p.cores) + " cores: measured up to here"});
  return c;
}

std::vector<std::pair<std::string, viz::SeriesChart>> step_charts(const ExperimentResult& res) {
  std::vector<std::pair<std::string, viz::SeriesChart>> out;
  if (res.steps.empty()) return out;
  const ExperimentPlan& p = res.plan;
  std::vector<viz::SeriesMark> marks;
  const std::string first = res.steps.front().method;
  for (const StepRow& s : res.steps)
    if (s.method == first && s.structure_changed && s.step > 0)
      marks.push_back({static_cast<double>(s.step), ""});
  struct Figure {
    const char* file;
    const char* title;
    const char* y;
    double (*value)(const StepRow&);
  };
  const Figure figures[] = {
      {"steps-time", "Step time over the run", "ms per step",
       [](const StepRow& s) { return s.step_ms; }},
      {"steps-partition", "Partitioning time per step", "ms",
       [](const StepRow& s) { return s.partition_ms; }},
      {"steps-migrations", "Migrated tasks per step", "tasks",
       [](const StepRow& s) { return static_cast<double>(s.migrated_tasks); }},
      {"steps-update", "Graph update per step (edge derivation + plan build)", "ms",
       [](const StepRow& s) { return s.graph_update_ms + s.build_ms; }}};
  for (const Figure& f : figures) {
    viz::SeriesChart c;
    c.title = std::string(f.title) + ": " + scenes_text(p) + ", " +
              std::to_string(p.series_threads) + " threads, repartitioned every step";
    c.subtitle = "measured (live run, medians of " + std::to_string(p.repeat) +
                 " passes); dotted rules: steps whose contacts or collision groups changed";
    c.x_title = "step";
    c.y_title = f.y;
    c.markers = false;
    std::map<std::string, std::uint32_t> colour;
    for (const std::string& m : p.series_methods)
      colour.emplace(m, static_cast<std::uint32_t>(colour.size()));
    std::map<std::string, viz::Series> by_method;
    for (const StepRow& s : res.steps) {
      viz::Series& series = by_method[s.method];
      series.name = s.method;
      series.colour = colour[s.method];
      series.points.push_back({static_cast<double>(s.step), f.value(s)});
    }
    for (const std::string& m : p.series_methods)
      if (by_method.count(m)) c.series.push_back(by_method[m]);
    if (std::string(f.file) == "steps-time") {
      viz::Series engine{"engine (sequential)",
                         viz::SeriesKind::kMeasured,
                         static_cast<std::uint32_t>(colour.size()),
                         {}};
      for (const StepRow& s : res.steps)
        if (s.method == first) engine.points.push_back({static_cast<double>(s.step), s.engine_ms});
      c.series.push_back(std::move(engine));
    }
    c.marks = marks;
    out.emplace_back(f.file, std::move(c));
  }
  return out;
}

std::string experiment_json(const ExperimentResult& res, int indent) {
  const ExperimentPlan& p = res.plan;
  const PaperFigure paper = paper_figure(p.name);
  json scenes = json::array();
  for (const SceneVariant& v : p.scenes)
    scenes.push_back({{"scene", v.scene},
                      {"subobjects", optional_json(v.subobjects)},
                      {"label", v.label()}});
  json paper_ms = json::object();
  for (const auto& [scene, t] : paper.sequential_ms) paper_ms[scene] = t;
  json rows = json::array();
  for (const ResultRow& r : res.rows)
    rows.push_back({{"experiment", r.experiment},
                    {"scene", r.scene},
                    {"subobjects", optional_json(r.subobjects)},
                    {"method", r.method},
                    {"policy", r.policy},
                    {"threads", r.threads},
                    {"threads_kind", std::string(r.threads_kind(p.cores))},
                    {"measured", r.measured ? measured_json(*r.measured) : json(nullptr)},
                    {"predicted", r.predicted ? predicted_json(*r.predicted) : json(nullptr)},
                    {"failure", r.failure.empty() ? json(nullptr) : json(r.failure)}});
  json steps = json::array();
  for (const StepRow& s : res.steps)
    steps.push_back({{"method", s.method},
                     {"threads", s.threads},
                     {"step", s.step},
                     {"structure_changed", s.structure_changed},
                     {"step_ms", s.step_ms},
                     {"engine_ms", s.engine_ms},
                     {"record_ms", s.record_ms},
                     {"graph_update_ms", s.graph_update_ms},
                     {"partition_ms", s.partition_ms},
                     {"build_ms", s.build_ms},
                     {"execute_ms", s.execute_ms},
                     {"migrated_tasks", s.migrated_tasks}});
  json series = json::array();
  for (const SeriesSummary& s : res.series)
    series.push_back({{"method", s.method},
                      {"threads", s.threads},
                      {"steps", s.steps},
                      {"structure_changes", s.structure_changes},
                      {"step_ms", s.step_ms},
                      {"engine_ms", s.engine_ms},
                      {"partition_ms", s.partition_ms},
                      {"build_ms", s.build_ms},
                      {"migrated_tasks", s.migrated_tasks},
                      {"update_ms_changed", s.update_ms_changed},
                      {"new_graph_ms_changed", s.new_graph_ms_changed}});
  const json j = {
      {"experiment", std::string(to_string(p.name))},
      {"command", p.command()},
      {"date", res.date},
      {"seconds", res.seconds},
      {"cost_model", res.cost_model},
      {"machine",
       {{"summary", res.machine.summary()},
        {"model", res.machine.model},
        {"cores", res.machine.cores},
        {"hardware_threads", res.machine.pus},
        {"sockets", res.machine.packages},
        {"numa_nodes", res.machine.numa_nodes},
        {"l2_bytes", res.machine.l2_bytes},
        {"l3_bytes", res.machine.l3_bytes},
        {"os", res.machine.os}}},
      {"plan",
       {{"scenes", scenes},
        {"methods", p.methods},
        {"series_methods", p.series_methods},
        {"series_threads", p.series_threads},
        {"steps", p.steps},
        {"repeat", p.repeat},
        {"replay", p.replay},
        {"threads_measured", p.threads.measured},
        {"threads_predicted", p.threads.predicted},
        {"notes", p.notes}}},
      {"paper",
       {{"figure", paper.figure}, {"text", paper.text}, {"sequential_ms_per_step", paper_ms}}},
      {"rows", rows},
      {"steps", steps},
      {"series", series},
      {"failures", res.failures()},
      {"files", res.files}};
  return j.dump(indent);
}

std::string experiment_text(const ExperimentResult& res) {
  const ExperimentPlan& p = res.plan;
  std::string s = "\n" + std::string(to_string(p.name)) + ": " + scenes_text(p) + ", " +
                  std::to_string(p.steps) + " steps, " +
                  (p.repeat == 1 ? std::string("1 timed pass")
                                 : "medians of " + std::to_string(p.repeat) + " passes") +
                  ", " + fixed(res.seconds, 0) + " s\nmachine: " + res.machine.summary() +
                  "\nmeasured (live run / uninstrumented engine, same run) at threads " +
                  thread_list(p.threads.measured) + "; predicted (simulator) at " +
                  thread_list(p.threads.all()) + "\n";
  char line[256];
  std::string scene;
  for (const ResultRow& r : res.rows) {
    if (variant_label(r) != scene) {
      scene = variant_label(r);
      s += "\n" + scene + "\n";
      std::snprintf(line, sizeof line, "%-16s %4s %-9s %10s %10s %9s %9s %10s %10s\n", "method",
                    "K", "kind", "engine ms", "live ms", "speed-up", "replay", "predicted",
                    "pred. ms");
      s += line;
    }
    const auto num = [](bool has, double v, int d) { return has ? fixed(v, d) : std::string("-"); };
    const bool m = r.measured.has_value();
    std::snprintf(
        line, sizeof line, "%-16s %4u %-9s %10s %10s %9s %9s %10s %10s", r.method.c_str(),
        r.threads, std::string(r.threads_kind(p.cores)).c_str(),
        num(m, m ? r.measured->engine_ms_per_step : 0, 2).c_str(),
        num(m, m ? r.measured->live_ms_per_step : 0, 2).c_str(),
        num(m, m ? r.measured->live_speedup : 0, 2).c_str(),
        num(m && r.measured->replay_speedup, m ? r.measured->replay_speedup.value_or(0) : 0, 2)
            .c_str(),
        num(r.predicted.has_value(), r.predicted ? r.predicted->speedup : 0, 2).c_str(),
        num(r.predicted.has_value(), r.predicted ? r.predicted->ms_per_step : 0, 2).c_str());
    s += line;
    s += r.failure.empty() ? "\n" : "  FAILED: " + r.failure + "\n";
  }
  if (!res.series.empty()) {
    s += "\n" + scenes_text(p) + ", repartitioned every step on " +
         std::to_string(p.series_threads) + " threads (ms per step)\n";
    std::snprintf(line, sizeof line, "%-14s %8s %9s %9s %10s %9s %9s %13s %15s\n", "method",
                  "changed", "live ms", "engine", "partition", "build", "migrated", "update (chg)",
                  "new graph (chg)");
    s += line;
    for (const SeriesSummary& x : res.series) {
      std::snprintf(line, sizeof line, "%-14s %8u %9.2f %9.2f %10.3f %9.3f %9llu %13.3f %15.3f\n",
                    x.method.c_str(), x.structure_changes, x.step_ms, x.engine_ms, x.partition_ms,
                    x.build_ms, static_cast<unsigned long long>(x.migrated_tasks),
                    x.update_ms_changed, x.new_graph_ms_changed);
      s += line;
    }
  }
  s += "\nresults: " + p.out_dir + "/ (";
  for (std::size_t i = 0; i < res.files.size(); ++i) s += (i ? ", " : "") + res.files[i];
  s += ")\n";
  if (res.failures())
    s += std::to_string(res.failures()) + " run(s) failed: see the failure column\n";
  return s;
}

void write_outputs(ExperimentResult& res) {
  const std::string dir = res.plan.out_dir + "/";
  std::vector<std::pair<std::string, std::string>> files;  // name -> content
  files.emplace_back("results.csv", results_csv(res.rows, res.plan.cores));
  if (!res.steps.empty()) files.emplace_back("steps.csv", steps_csv(res.steps));
  const viz::SeriesChart speedup = speedup_chart(res);
  files.emplace_back("speedup.svg", viz::render_series_chart(speedup, viz::TimelineFormat::kSvg));
  files.emplace_back("speedup.png", viz::render_series_chart(speedup, viz::TimelineFormat::kPng));
  for (const auto& [name, chart] : step_charts(res)) {
    files.emplace_back(name + ".svg", viz::render_series_chart(chart, viz::TimelineFormat::kSvg));
    files.emplace_back(name + ".png", viz::render_series_chart(chart, viz::TimelineFormat::kPng));
  }
  files.emplace_back("report.html", viz::series_page_html(page_of(res)));
  for (const auto& f : files) res.files.push_back(f.first);
  res.files.push_back("results.json");
  for (const auto& [name, content] : files) write_file_atomic(dir + name, content);
  write_file_atomic(dir + "results.json", experiment_json(res, 1) + "\n");
}

}  // namespace tgraph::experiment
