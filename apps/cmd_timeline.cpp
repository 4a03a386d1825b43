// SPDX-License-Identifier: MIT
// `tgraph timeline R.json [--steps a:b] -o out.{svg,png}`: a replay timeline as a Gantt chart.
#include <filesystem>

#include "commands.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/viz/timeline.hpp"

namespace tgraph::app {

void add_timeline(CLI::App& app) {
  struct Options {
    std::string input, out, steps;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("timeline", "Draw a replay timeline (tgraph replay --timeline) as a Gantt chart");
  cmd->add_option("timeline", o->input, "Timeline file (JSON from tgraph replay --timeline)")->required();
  cmd->add_option("--steps", o->steps, "Step range a:b, a: or a (default: all)");
  cmd->add_option("-o,--output", o->out, "Output file: .svg or .png")->required();
  cmd->callback([o] {
    const viz::TimelineFormat format = viz::timeline_format_of(o->out);
    viz::Timeline t = viz::parse_timeline(read_file_text(o->input), o->input);
    if (!o->steps.empty()) {
      const auto [a, b] = viz::parse_step_range(o->steps);
      t = viz::select_steps(t, a, b);
    }
    const std::string title = std::filesystem::path(o->input).filename().string() + ": " +
                              std::to_string(t.threads) + " threads, " + std::to_string(t.tasks.size()) +
                              " task instances, " + std::to_string(t.waits.size()) + " blocking waits";
    write_file_atomic(o->out, viz::render_timeline(t, format, title));
  });
}

}  // namespace tgraph::app
