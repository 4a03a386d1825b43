// SPDX-License-Identifier: MIT
// The verbs that read a trace: `tgraph info` (summarize_trace), `tgraph export` (a step's graph:
// partition::graph_file; a timeline's trace events: viz::chrome_trace), `tgraph diff`
// (diff_trace_steps).
#include <iostream>

#include "commands.hpp"
#include "tgraph/graph/diff.hpp"
#include "tgraph/graph/summary.hpp"
#include "tgraph/partition/assignment_io.hpp"
#include "tgraph/partition/export.hpp"
#include "tgraph/viz/timeline.hpp"

namespace tgraph::app {

void add_info(CLI::App& app) {
  auto o = std::make_shared<Args>();
  auto* cmd =
      app.add_subcommand("info", "Steps, tasks, data, edges, work, span, parallelism of a trace");
  cmd->add_option("trace", o->input, "Trace file (.tgt)")->required();
  cmd->add_flag("--json", o->json, "Print one JSON object");
  cmd->add_flag("--recover", o->recover, "Read the complete steps of an interrupted capture");
  auto summary = std::make_shared<SummaryOptions>();
  cmd->add_flag("--unit-cost", summary->unit_cost,
                "Also the work and span in tasks (every task costs 1; loops unrolled)");
  cmd->callback([o, summary] {
    const TraceSummary s =
        summarize_trace(read_trace(o->input, {.recover = o->recover}), *summary);
    std::cout << (o->json ? trace_summary_json(s, o->input) + "\n"
                          : trace_summary_text(s, o->input));
  });
}

void add_export(CLI::App& app) {
  auto a = std::make_shared<Args>();
  a->format = "json";
  auto* cmd = app.add_subcommand("export", "Write one step's graph in an interchange format");
  cmd->add_option("input", a->input, "Trace file (.tgt); for chrome, a replay timeline (R.json)")
      ->required();
  cmd->add_option("--step", a->step, "Step index (0-based)");
  cmd->add_option("--format", a->format,
                  "json, metis (gpmetis input), scotch (scotch_gpart input), chrome (timeline -> "
                  "trace-event JSON)")
      ->check(CLI::IsMember({"json", "metis", "scotch", "chrome"}));
  cmd->add_option("-o,--output", a->output, "Output file (default: standard output)");
  cmd->callback([a] {
    write_output(a->output,
                 a->format == "chrome"
                     ? viz::chrome_trace(read_timeline(a->input))
                     : partition::graph_file(read_trace(a->input), a->step, a->input,
                                             partition::parse_graph_file_format(a->format)));
  });
}

void add_diff(CLI::App& app) {
  auto o = std::make_shared<Args>();
  auto steps = std::make_shared<std::vector<std::size_t>>();
  auto* cmd = app.add_subcommand("diff", "Structural difference of two steps by stable task key");
  cmd->add_option("trace", o->input, "Trace file (.tgt)")->required();
  cmd->add_option("--steps", *steps, "The two steps A B (0-based)")->required()->expected(2);
  cmd->add_option("--assignment,-a", o->assignment,
                  "Assignment file (.tga): also list tasks whose processor changed");
  cmd->add_flag("--json", o->json, "Print one JSON object");
  cmd->callback([o, steps] {
    const Trace trace = read_trace(o->input);
    const std::size_t a = (*steps)[0], b = (*steps)[1];  // expected(2): exactly two
    const auto as = partition::load_assignment_if(o->assignment, trace, o->input);
    const StepDiff d = diff_trace_steps(trace, o->input, a, b, as ? &*as : nullptr);
    std::cout << (o->json ? step_diff_json(d, a, b) + "\n" : step_diff_text(d, a, b));
  });
}

}  // namespace tgraph::app
