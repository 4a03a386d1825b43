// SPDX-License-Identifier: MIT
// `tgraph export T.tgt --step S --format {json,metis,scotch} [-o F]`: one step's graph in an
// interchange format (partition::graph_file); `tgraph export R.json --format chrome`: a
// replay timeline as Chrome/Perfetto trace events with signal -> wait flow arrows
// (viz::chrome_trace).
#include "commands.hpp"
#include "tgraph/partition/export.hpp"
#include "tgraph/viz/timeline.hpp"

namespace tgraph::app {

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
    const std::string text =
        a->format == "chrome"
            ? viz::chrome_trace(read_timeline(a->input))
            : partition::graph_file(read_trace(a->input), a->step, a->input,
                                    partition::parse_graph_file_format(a->format));
    if (a->output.empty() || a->output == "-") {
      std::cout << text;
    } else {
      write_file_atomic(a->output, text);
    }
  });
}

}  // namespace tgraph::app
