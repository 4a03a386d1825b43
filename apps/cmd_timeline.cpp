// SPDX-License-Identifier: MIT
// `tgraph timeline R.json [--steps a:b] -o out.{svg,png}`: a replay timeline as a Gantt chart.
#include "commands.hpp"
#include "tgraph/viz/timeline.hpp"

namespace tgraph::app {

void add_timeline(CLI::App& app) {
  auto a = std::make_shared<Args>();
  auto* cmd = app.add_subcommand(
      "timeline", "Draw a replay timeline (tgraph replay --timeline) as a Gantt chart");
  cmd->add_option("timeline", a->input, "Timeline file (JSON from tgraph replay --timeline)")
      ->required();
  cmd->add_option("--steps", a->range, "Step range a:b, a: or a (default: all)");
  cmd->add_option("-o,--output", a->output, "Output file: .svg or .png")->required();
  cmd->callback([a] {
    const viz::TimelineFormat format = viz::timeline_format_of(a->output);
    Timeline t = read_timeline(a->input);
    if (!a->range.empty()) {
      const auto [first, last] = viz::parse_step_range(a->range);
      t = viz::select_steps(t, first, last);
    }
    write_file_atomic(a->output, viz::render_timeline(t, format, viz::timeline_title(t, a->input)));
  });
}

}  // namespace tgraph::app
