// SPDX-License-Identifier: MIT
// `tgraph export T.tgt --step S --format {json,metis,scotch} [-o F]`: one step's graph in an
// interchange format (METIS: gpmetis input; Scotch: scotch_gpart source graph);
// `tgraph export R.json --format chrome`: a replay timeline as Chrome/Perfetto trace events,
// with signal -> wait flow arrows.
#include <iostream>

#include "commands.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/graph/step_json.hpp"
#include "tgraph/partition/export.hpp"
#include "tgraph/viz/timeline.hpp"

namespace tgraph::app {
namespace {

struct ExportOptions {
  std::string trace;
  std::string format = "json";
  std::string out;
  std::size_t step = 0;
};

void write_output(const ExportOptions& o, const std::string& text) {
  if (o.out.empty() || o.out == "-") {
    std::cout << text;
  } else {
    write_file_atomic(o.out, text);
  }
}

void run_export(const ExportOptions& o) {
  if (o.format == "chrome") {
    // The input is a replay timeline (tgraph replay --timeline R.json).
    write_output(o, viz::chrome_trace(viz::parse_timeline(read_file_text(o.trace), o.trace)));
    return;
  }
  const Trace trace = load_trace(o.trace);
  if (o.step >= trace.steps.size())
    throw UsageError("--step " + std::to_string(o.step) + ": trace " + o.trace + " has " +
                     std::to_string(trace.steps.size()) + " steps");
  const StepGraph& g = trace.steps[o.step];
  std::string text;
  if (o.format == "json") {
    text = step_graph_json(g, o.step);
  } else if (o.format == "metis") {
    text = partition::metis_graph_file(g);
  } else {
    text = partition::scotch_graph_file(g);
  }
  write_output(o, text);
}

}  // namespace

void add_export(CLI::App& app) {
  auto o = std::make_shared<ExportOptions>();
  auto* cmd = app.add_subcommand("export", "Write one step's graph in an interchange format");
  cmd->add_option("input", o->trace, "Trace file (.tgt); for chrome, a replay timeline (R.json)")->required();
  cmd->add_option("--step", o->step, "Step index (0-based)");
  cmd->add_option("--format", o->format,
                  "json, metis (gpmetis input), scotch (scotch_gpart input), chrome (timeline -> trace-event JSON)")
      ->check(CLI::IsMember({"json", "metis", "scotch", "chrome"}));
  cmd->add_option("-o,--output", o->out, "Output file (default: standard output)");
  cmd->callback([o] { run_export(*o); });
}

}  // namespace tgraph::app
