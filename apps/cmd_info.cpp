// SPDX-License-Identifier: MIT
// `tgraph info T.tgt [--json]`: size, work, span and shape of a trace (summarize_trace).
#include <iostream>

#include "commands.hpp"
#include "tgraph/graph/summary.hpp"

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

}  // namespace tgraph::app
