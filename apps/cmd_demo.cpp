// SPDX-License-Identifier: MIT
// `tgraph demo` (and `tgraph` alone): the pipeline of experiment/demo.hpp, from a capture to
// the HTML report.
#include <cstdio>
#include <iostream>

#include "commands.hpp"
#include "tgraph/experiment/demo.hpp"

namespace tgraph::app {

void add_demo(CLI::App& app) {
  auto o = std::make_shared<experiment::DemoOptions>();
  auto json = std::make_shared<bool>(false);
  o->threads = default_threads();
  auto* cmd = app.add_subcommand(
      "demo", "Default job: capture, partition with every strategy, replay, compare");
  cmd->add_option("--scene", o->scene, "Built-in scene or scene file");
  cmd->add_option("--steps", o->steps, "Steps to capture");
  cmd->add_option("--threads", o->threads, "Replay threads (default: all hardware threads)");
  cmd->add_option("--repeat", o->repeat, "Timed passes per replay (medians)");
  cmd->add_option("--out", o->out, "Folder for the trace and report.html");
  cmd->add_flag("--json", *json, "Print one JSON object");
  cmd->callback([o, json] {
    const auto say = [](const std::string& s) { std::fprintf(stderr, "%s\n", s.c_str()); };
    const experiment::DemoResult r =
        experiment::run_demo(*o, *json ? std::function<void(const std::string&)>() : say);
    std::cout << (*json ? experiment::demo_json(r) + "\n" : experiment::demo_text(r)) << std::flush;
  });
}

}  // namespace tgraph::app
