// SPDX-License-Identifier: MIT
// `tgraph info T.tgt [--json]`: size, work, span and shape of a trace.
#include <cstdio>
#include <iostream>

#include "commands.hpp"
#include "tgraph/graph/summary.hpp"

namespace tgraph::app {
namespace {

struct InfoOptions {
  std::string trace;
  bool json = false;
  bool recover = false;
};

void run_info(const InfoOptions& o) {
  const TraceSummary s = summarize_trace(load_trace(o.trace, o.recover));
  if (o.json)
    std::cout << trace_summary_json(s, o.trace) << std::endl;
  else
    std::fputs(trace_summary_text(s, o.trace).c_str(), stdout);
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
