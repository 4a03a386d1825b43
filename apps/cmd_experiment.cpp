// SPDX-License-Identifier: MIT
// `tgraph experiment NAME`: the paper's experiments, metg or scaling (experiment::run_named).
#include <cstdio>
#include <iostream>

#include "commands.hpp"
#include "option_words.hpp"
#include "tgraph/experiment/experiment.hpp"

namespace tgraph::app {

void add_experiment(CLI::App& app) {
  auto o = std::make_shared<experiment::ExperimentOptions>();
  auto a = std::make_shared<Args>();
  auto* cmd = app.add_subcommand(
      "experiment", "Run one of the paper's experiments: live speed-ups, replays, predictions");
  cmd->add_option("name", a->method,
                  "independent, heterogeneous, domain or medical (the paper's), metg (Task Bench's "
                  "METG per policy) or scaling (live runs per method and thread count)")
      ->required()
      ->check(CLI::IsMember(experiment::all_experiment_names()));
  cmd->add_option_function<std::string>(
      "--threads", [o](const std::string& t) { o->threads = experiment::parse_thread_list(t); },
      "Thread counts, e.g. 1-4,8,16 (default: the experiment's); above the cores: predicted "
      "only (scaling: run oversubscribed)");
  cmd->add_option("--out", o->out, "Results folder (default tgraph-experiment-NAME)");
  cmd->add_flag("--quick", o->quick, "Few steps, one pass (a smoke run)");
  cmd->add_option("--steps", o->steps, "Steps per run (default: the experiment's)");
  cmd->add_option("--repeat", o->repeat, "Timed passes per run, medians (default 3; scaling: 1)");
  cmd->add_option("--methods", o->methods,
                  "Strategies and baselines, e.g. owner,worksteal (metg: policies)")
      ->delimiter(',');
  cmd->add_option(
         "--scenes,--scene", o->scenes,
         "scaling: comma list of scenes (bars64, falling64, torso, cloth256-s64, and "
         "ode-piles, ode-heap, ode-chains when built with ODE; default: the four built-in)")
      ->delimiter(',');
  cmd->add_option("--subobjects", o->subobjects,
                  "domain: comma list of sub-object counts (perfect squares; default 16,64)")
      ->delimiter(',');
  cmd->add_flag_function(
      "--replay,!--no-replay", [o](std::int64_t n) { o->replay = n > 0; },
      "Also replay the captured trace with synthetic bodies (default, except for domain), or not");
  cmd->add_option("--calibration", o->calibration,
                  "Calibration file of the predictions (tgraph calibrate --out; default: the "
                  "default calibration file when there is one)");
  cmd->add_flag("--json", a->json, "Print results.json on stdout");
  o->words = experiment::words_with("tgraph experiment", flag_of);  // the command to rerun it
  cmd->callback([o, a] {
    experiment::Progress progress(stderr, experiment::Progress::is_terminal(stderr));
    const experiment::NamedRun r = experiment::run_named(a->method, *o, progress);
    std::cout << (a->json ? r.json + "\n" : r.text) << std::flush;
    if (r.failures != 0)
      throw Failure(std::to_string(r.failures) + " run(s) of experiment " + a->method + " failed");
  });
}

}  // namespace tgraph::app
