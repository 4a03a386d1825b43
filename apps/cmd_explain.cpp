// SPDX-License-Identifier: MIT
// `tgraph explain FILE [--step N] [--json]`: where each step's time went (tgraph::explain):
// FILE is a timeline (replay --timeline, run --timeline) or a run's or replay's JSON, whose
// attribution it prints, or whose timeline (its "timeline" key) it explains.
#include <iostream>

#include "commands.hpp"
#include "tgraph/explain/command.hpp"

namespace tgraph::app {

void add_explain(CLI::App& app) {
  auto a = std::make_shared<explain::ExplainCommand>();
  auto* cmd = app.add_subcommand(
      "explain",
      "Where each step's time went: the lost processor time by cause, the critical path, "
      "what-ifs (docs/explain.md)");
  cmd->add_option("file", a->input,
                  "A timeline (replay/run --timeline) or a replay/run --json result")
      ->required();
  cmd->add_option("--step", a->step, "Only this step (its number in the file)");
  cmd->add_flag("--json", a->json, "Print one JSON object");
  cmd->callback([a] { std::cout << explain::explain_command(*a); });
}

}  // namespace tgraph::app
