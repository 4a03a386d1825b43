// SPDX-License-Identifier: MIT
// `tgraph info T.tgt [--json]`: size, work, span and shape of a trace.
#include <algorithm>
#include <cstdio>
#include <set>

#include "commands.hpp"
#include "tgraph/graph/metrics.hpp"

namespace tgraph::app {
namespace {

struct InfoOptions {
  std::string trace;
  bool json = false;
  bool recover = false;
};

void run_info(const InfoOptions& o) {
  const Trace trace = load_trace(o.trace, o.recover);
  nlohmann::json per_step = nlohmann::json::array();
  std::uint64_t tasks_total = 0, tasks_min = UINT64_MAX, tasks_max = 0, edges = 0, work = 0, span = 0;
  std::uint64_t loops = 0, iterations = 0, data_max = 0, contact_changes = 0;
  std::uint32_t iter_max = 0;
  std::set<std::uint64_t> shapes;
  std::uint64_t last_groups = 0;
  for (std::size_t s = 0; s < trace.steps.size(); ++s) {
    const StepGraph& g = trace.steps[s];
    const Metrics m = compute_metrics(g);
    tasks_total += m.tasks;
    tasks_min = std::min(tasks_min, m.tasks);
    tasks_max = std::max(tasks_max, m.tasks);
    edges += m.edges;
    work += m.work_ns;
    span += m.span_ns;
    loops += m.loops;
    iterations += m.loop_iterations;
    data_max = std::max<std::uint64_t>(data_max, m.data);
    for (const Loop& l : g.loops) iter_max = std::max(iter_max, l.iterations);
    shapes.insert(g.structural_hash());
    const bool changed = contacts_changed(trace, s);
    contact_changes += changed ? 1 : 0;
    std::set<std::uint32_t> groups(g.groups.begin(), g.groups.end());
    const std::uint64_t n_groups = g.groups.empty() ? (g.objects.empty() ? 0 : 1) : groups.size();
    last_groups = n_groups;
    std::vector<std::uint32_t> loop_iters;
    for (const Loop& l : g.loops) loop_iters.push_back(l.iterations);
    per_step.push_back({{"step", s},
                        {"tasks", m.tasks},
                        {"edges", m.edges},
                        {"data", m.data},
                        {"loops", m.loops},
                        {"loop_iterations", loop_iters},
                        {"work_ns", m.work_ns},
                        {"span_ns", m.span_ns},
                        {"parallelism", m.parallelism},
                        {"contacts", g.contacts.size()},
                        {"collision_groups", n_groups},
                        {"contacts_changed", changed},
                        {"structure", g.structural_hash()}});
  }
  const std::size_t n = trace.steps.size();
  if (n == 0) tasks_min = 0;
  const double parallelism = span == 0 ? 0.0 : static_cast<double>(work) / static_cast<double>(span);
  const double tasks_mean = n == 0 ? 0.0 : static_cast<double>(tasks_total) / static_cast<double>(n);
  if (o.json) {
    nlohmann::json j = {
        {"trace", o.trace},
        {"scene", trace.header.scene},
        {"engine", trace.header.engine},
        {"machine", trace.header.machine},
        {"tgraph_version", trace.header.tgraph_version},
        {"steps", n},
        {"tasks", tasks_total},
        {"tasks_per_step", {{"min", tasks_min}, {"mean", tasks_mean}, {"max", tasks_max}}},
        {"edges", edges},
        {"data", data_max},
        {"loops", loops},
        {"loop_iterations", iterations},
        {"max_loop_iterations", iter_max},
        {"work_ns", work},
        {"span_ns", span},
        {"parallelism", parallelism},
        {"distinct_structures", shapes.size()},
        {"contact_changes", contact_changes},
        {"last_step_collision_groups", last_groups},
        {"per_step", per_step},
    };
    print_json(j);
    return;
  }
  std::printf("trace          %s (scene %s, engine %s)\n", o.trace.c_str(), trace.header.scene.c_str(),
              trace.header.engine.c_str());
  std::printf("steps          %zu\n", n);
  std::printf("tasks          %llu (per step min %llu, mean %.1f, max %llu)\n",
              static_cast<unsigned long long>(tasks_total), static_cast<unsigned long long>(tasks_min),
              tasks_mean, static_cast<unsigned long long>(tasks_max));
  std::printf("data           %llu (largest step)\n", static_cast<unsigned long long>(data_max));
  std::printf("edges          %llu\n", static_cast<unsigned long long>(edges));
  std::printf("loops          %llu, %llu iterations (max %u in one loop)\n",
              static_cast<unsigned long long>(loops), static_cast<unsigned long long>(iterations), iter_max);
  std::printf("work           %.3f ms\n", static_cast<double>(work) / 1e6);
  std::printf("span           %.3f ms\n", static_cast<double>(span) / 1e6);
  std::printf("parallelism    %.2f\n", parallelism);
  std::printf("structures     %zu distinct\n", shapes.size());
  std::printf("contacts       %llu steps whose contact set changed; last step %llu collision group(s)\n",
              static_cast<unsigned long long>(contact_changes), static_cast<unsigned long long>(last_groups));
}

}  // namespace

void add_info(CLI::App& app) {
  auto o = std::make_shared<InfoOptions>();
  auto* cmd = app.add_subcommand("info", "Steps, tasks, data, edges, work, span, parallelism of a trace");
  cmd->add_option("trace", o->trace, "Trace file (.tgt)")->required();
  cmd->add_flag("--json", o->json, "Print one JSON object");
  cmd->add_flag("--recover", o->recover, "Read the complete steps of an interrupted capture");
  cmd->callback([o] { run_info(*o); });
}

}  // namespace tgraph::app
