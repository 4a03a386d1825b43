// SPDX-License-Identifier: MIT
#include "tgraph/graph/summary.hpp"

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <set>

#include "tgraph/graph/diff.hpp"
#include "tgraph/graph/metrics.hpp"

namespace tgraph {

namespace {

// True when no task of the trace has a cost above 1 ns: no timing recorded (all 0) or unit
// costs (all 1), where the timed span says nothing.
bool without_costs(const Trace& trace) {
  for (const StepGraph& g : trace.steps)
    for (const Task& t : g.tasks)
      if (t.cost_ns > 1) return false;
  return !trace.steps.empty();
}

// A duration in the unit that shows it: ms, us below a millisecond, ns below a microsecond.
std::string duration_text(std::uint64_t ns) {
  char b[64];
  if (ns >= 1000000)
    std::snprintf(b, sizeof b, "%.3f ms", static_cast<double>(ns) / 1e6);
  else if (ns >= 1000)
    std::snprintf(b, sizeof b, "%.3f us", static_cast<double>(ns) / 1e3);
  else
    std::snprintf(b, sizeof b, "%llu ns", static_cast<unsigned long long>(ns));
  return b;
}

// Appends printf's text of `fmt` (a line of the summary, at most 1023 characters) to `out`.
void appendf(std::string& out, const char* fmt, ...) __attribute__((format(printf, 2, 3)));
void appendf(std::string& out, const char* fmt, ...) {
  char line[1024];
  va_list args;
  va_start(args, fmt);
  const int n = std::vsnprintf(line, sizeof line, fmt, args);
  va_end(args);
  out.append(line, static_cast<std::size_t>(std::clamp(n, 0, 1023)));
}

// A count as printf's %llu takes it.
unsigned long long ull(std::uint64_t v) { return v; }

}  // namespace

TraceSummary summarize_trace(const Trace& trace, const SummaryOptions& options) {
  TraceSummary s;
  s.unit_cost = options.unit_cost || without_costs(trace);
  s.header = trace.header;
  s.steps = trace.steps.size();
  s.tasks_min = trace.steps.empty() ? 0 : UINT64_MAX;
  std::set<std::uint64_t> shapes;
  const std::vector<std::vector<std::uint64_t>> robust = robust_costs(trace.steps);
  for (std::size_t i = 0; i < trace.steps.size(); ++i) {
    const StepGraph& g = trace.steps[i];
    const Metrics m = compute_metrics(g);
    StepSummary st;
    st.tasks = m.tasks;
    st.edges = m.edges;
    st.edges_carried = g.carried_edges.size();
    {
      StepGraph r = g;
      for (TaskId t = 0; t < r.tasks.size(); ++t) r.tasks[t].cost_ns = robust[i][t];
      const Metrics rm = compute_metrics(r);
      st.robust_work_ns = rm.work_ns;
      st.robust_span_ns = rm.span_ns;
      st.robust_parallelism = rm.parallelism;
    }
    st.data = m.data;
    st.loops = m.loops;
    for (const Loop& l : g.loops) st.loop_iterations.push_back(l.iterations);
    st.work_ns = m.work_ns;
    st.span_ns = m.span_ns;
    if (s.unit_cost) {
      const UnitMetrics u = compute_unit_metrics(g);
      st.work_tasks = u.work_tasks;
      st.span_tasks = u.span_tasks;
    }
    st.host_ns = g.host_ns;
    st.parallelism = m.parallelism;
    st.contacts = g.contacts.size();
    const std::set<std::uint32_t> groups(g.groups.begin(), g.groups.end());
    st.collision_groups = g.groups.empty() ? (g.objects.empty() ? 0 : 1) : groups.size();
    st.contacts_changed = contacts_changed(trace, i);
    st.structure = g.structural_hash();
    if (i > 0 && !g.same_structure(trace.steps[i - 1])) {
      st.structure_changed = true;
      st.change = step_diff_summary(diff_steps(trace.steps[i - 1], g));
    }

    s.tasks += st.tasks;
    s.tasks_min = std::min(s.tasks_min, st.tasks);
    s.tasks_max = std::max(s.tasks_max, st.tasks);
    s.edges += st.edges;
    s.edges_carried += st.edges_carried;
    s.robust_work_ns += st.robust_work_ns;
    s.robust_span_ns += st.robust_span_ns;
    s.robust_span_max_ns = std::max(s.robust_span_max_ns, st.robust_span_ns);
    s.data_max = std::max(s.data_max, st.data);
    s.loops += st.loops;
    s.loop_iterations += m.loop_iterations;
    for (std::uint32_t it : st.loop_iterations)
      s.max_loop_iterations = std::max(s.max_loop_iterations, it);
    s.work_ns += st.work_ns;
    s.span_ns += st.span_ns;
    s.span_max_ns = std::max(s.span_max_ns, st.span_ns);
    s.work_tasks += st.work_tasks;
    s.span_tasks += st.span_tasks;
    s.span_tasks_max = std::max(s.span_tasks_max, st.span_tasks);
    s.host_ns += st.host_ns;
    shapes.insert(st.structure);
    s.contact_changes += st.contacts_changed ? 1 : 0;
    s.last_step_collision_groups = st.collision_groups;
    s.per_step.push_back(std::move(st));
  }
  s.distinct_structures = shapes.size();
  s.tasks_mean = s.steps == 0 ? 0.0 : static_cast<double>(s.tasks) / static_cast<double>(s.steps);
  s.parallelism =
      s.span_ns == 0 ? 0.0 : static_cast<double>(s.work_ns) / static_cast<double>(s.span_ns);
  s.robust_parallelism = s.robust_span_ns == 0 ? 0.0
                                              : static_cast<double>(s.robust_work_ns) /
                                                    static_cast<double>(s.robust_span_ns);
  s.unit_parallelism = s.span_tasks == 0 ? 0.0
                                          : static_cast<double>(s.work_tasks) /
                                                static_cast<double>(s.span_tasks);
  return s;
}

std::string trace_summary_json(const TraceSummary& s, const std::string& trace_name) {
  using nlohmann::json;
  json per_step = json::array(), changes = json::array();
  for (std::size_t i = 0; i < s.per_step.size(); ++i) {
    const StepSummary& st = s.per_step[i];
    json one = {{"step", i},
                        {"tasks", st.tasks},
                        {"edges", st.edges},
                        {"edges_carried", st.edges_carried},
                        {"data", st.data},
                        {"loops", st.loops},
                        {"loop_iterations", st.loop_iterations},
                        {"work_ns", st.work_ns},
                        {"span_ns", st.span_ns},
                        {"host_ns", st.host_ns},
                        {"parallelism", st.parallelism},
                        {"robust_work_ns", st.robust_work_ns},
                        {"robust_span_ns", st.robust_span_ns},
                        {"robust_parallelism", st.robust_parallelism},
                        {"contacts", st.contacts},
                        {"collision_groups", st.collision_groups},
                        {"contacts_changed", st.contacts_changed},
                        {"structure", st.structure},
                        {"structure_changed", st.structure_changed}};
    if (s.unit_cost) {
      one["work_tasks"] = st.work_tasks;
      one["span_tasks"] = st.span_tasks;
    }
    per_step.push_back(std::move(one));
    if (st.structure_changed) changes.push_back({{"step", i}, {"summary", st.change}});
  }
  json j = {
      {"trace", trace_name},
      {"scene", s.header.scene},
      {"engine", s.header.engine},
      {"machine", s.header.machine},
      {"tgraph_version", s.header.tgraph_version},
      {"steps", s.steps},
      {"tasks", s.tasks},
      {"tasks_per_step", {{"min", s.tasks_min}, {"mean", s.tasks_mean}, {"max", s.tasks_max}}},
      {"edges", s.edges},
      {"edges_carried", s.edges_carried},
      {"data", s.data_max},
      {"loops", s.loops},
      {"loop_iterations", s.loop_iterations},
      {"max_loop_iterations", s.max_loop_iterations},
      {"work_ns", s.work_ns},
      {"span_ns", s.span_ns},
      {"span_max_ns", s.span_max_ns},
      {"host_ns", s.host_ns},
      {"parallelism", s.parallelism},
      {"costs", "raw: work_ns, span_ns and parallelism use the recorded costs; robust_*: each "
                "task's cost the median of its cost over the steps of its structure"},
      {"robust_work_ns", s.robust_work_ns},
      {"robust_span_ns", s.robust_span_ns},
      {"robust_span_max_ns", s.robust_span_max_ns},
      {"robust_parallelism", s.robust_parallelism},
      {"distinct_structures", s.distinct_structures},
      {"contact_changes", s.contact_changes},
      {"last_step_collision_groups", s.last_step_collision_groups},
      {"structure_changes", changes},
      {"per_step", per_step},
  };
  if (s.unit_cost) {
    j["work_tasks"] = s.work_tasks;
    j["span_tasks"] = s.span_tasks;
    j["span_tasks_max"] = s.span_tasks_max;
    j["unit_parallelism"] = s.unit_parallelism;
  }
  return j.dump();
}

std::string trace_summary_text(const TraceSummary& s, const std::string& trace_name) {
  std::string out;
  appendf(out, "trace          %s (scene %s, engine %s)\n", trace_name.c_str(),
          s.header.scene.c_str(), s.header.engine.c_str());
  appendf(out, "steps          %llu\n", ull(s.steps));
  appendf(out, "tasks          %llu (per step min %llu, mean %.1f, max %llu)\n", ull(s.tasks),
          ull(s.tasks_min), s.tasks_mean, ull(s.tasks_max));
  appendf(out, "data           %llu (largest step)\n", ull(s.data_max));
  appendf(out, "edges          %llu (%llu within a step or loop iteration, %llu loop-carried)\n",
          ull(s.edges), ull(s.edges - s.edges_carried), ull(s.edges_carried));
  appendf(out, "loops          %llu, %llu iterations (max %u in one loop)\n", ull(s.loops),
          ull(s.loop_iterations), s.max_loop_iterations);
  const bool timed = s.work_ns != 0;  // a trace without costs has only unit-cost figures
  if (timed) {
    out += "work           " + duration_text(s.work_ns) + " (sum of all task costs, all steps)\n";
    out += "span           " + duration_text(s.span_ns) +
           " (sum of the steps' critical paths; longest step " + duration_text(s.span_max_ns) +
           ")\n";
  } else {
    out += "work, span     no task costs recorded: see the unit-cost figures\n";
  }
  if (s.unit_cost) {
    appendf(out, "work (unit)    %llu tasks (task runs, all steps)\n", ull(s.work_tasks));
    appendf(out,
            "span (unit)    %llu tasks (sum of the steps' critical paths in tasks; longest step "
            "%llu)\n",
            ull(s.span_tasks), ull(s.span_tasks_max));
  }
  out += "host           " + duration_text(s.host_ns) +
         " (sum of the engine's work outside the tasks)\n";
  if (timed) {
    appendf(out, "parallelism    %.2f (work / span, raw: the recorded costs)\n", s.parallelism);
    appendf(out,
            "robust         %.2f (work %s / span %s, each task's cost the median of its cost "
            "over the steps of its structure)\n",
            s.robust_parallelism, duration_text(s.robust_work_ns).c_str(),
            duration_text(s.robust_span_ns).c_str());
  }
  if (s.unit_cost)
    appendf(out, "parallelism    %.2f (unit costs: work / span in tasks)\n", s.unit_parallelism);
  appendf(out, "structures     %llu distinct\n", ull(s.distinct_structures));
  appendf(out,
          "contacts       %llu steps whose contact set changed; last step %llu collision "
          "group(s)\n",
          ull(s.contact_changes), ull(s.last_step_collision_groups));
  std::size_t changed = 0;
  for (const StepSummary& st : s.per_step) changed += st.structure_changed ? 1 : 0;
  if (changed > 0)
    out += "changes        " + std::to_string(changed) + " steps whose structure changed:\n";
  for (std::size_t i = 0; i < s.per_step.size(); ++i)
    if (s.per_step[i].structure_changed)
      out += "  step " + std::to_string(i) + ": " + s.per_step[i].change + "\n";
  return out;
}

}  // namespace tgraph
