// SPDX-License-Identifier: MIT
// `tgraph experiment NAME`: one of the paper's experiments (the runs: experiment/experiment.hpp).
#include <cstdio>
#include <iostream>

#include "commands.hpp"
#include "tgraph/experiment/experiment.hpp"
#include "tgraph/experiment/metg.hpp"
#include "tgraph/experiment/scaling.hpp"

namespace tgraph::app {

void add_experiment(CLI::App& app) {
  auto o = std::make_shared<experiment::ExperimentOptions>();
  auto a = std::make_shared<Args>();
  auto* cmd = app.add_subcommand(
      "experiment", "Run one of the paper's experiments: live speed-ups, replays, predictions");
  std::vector<std::string> names = experiment::experiment_names();
  names.emplace_back("metg");
  names.emplace_back("scaling");
  cmd->add_option("name", a->method,
                  "independent, heterogeneous, domain or medical (the paper's), metg (Task "
                  "Bench's minimum effective task granularity for every policy) or scaling "
                  "(live runs of four scenes for every method and thread count, with where "
                  "the time goes)")
      ->required()
      ->check(CLI::IsMember(names));
  cmd->add_option("--threads", o->threads,
                  "Thread counts, e.g. 1-4,8,16 (default: 1 to the cores, then powers of 2 to "
                  "64; scaling: powers of 2 up to the cores); counts above the cores are "
                  "predicted only (scaling: run oversubscribed)");
  cmd->add_option("--out", o->out_dir, "Results folder (default tgraph-experiment-NAME)");
  cmd->add_flag("--quick", o->quick, "Few steps, one pass (a smoke run)");
  cmd->add_option("--steps", o->steps, "Steps per run (default: the experiment's)");
  cmd->add_option("--repeat", o->repeat, "Timed passes per run, medians (default 3; scaling: 1)");
  cmd->add_option("--methods", o->methods,
                  "Comma list of strategies and baselines (default: the experiment's)");
  cmd->add_option("--subobjects", o->subobjects,
                  "domain: comma list of sub-object counts (perfect squares; default 16,64)");
  cmd->add_flag_callback(
      "--replay", [o] { o->replay = true; },
      "Also replay the captured trace with synthetic bodies (default, except for domain)");
  cmd->add_flag_callback(
      "--no-replay", [o] { o->replay = false; }, "Skip the synthetic replays");
  cmd->add_flag("--json", a->json, "Print results.json on stdout");
  cmd->callback([o, a] {
    if (a->method == "metg") {
      // The sweep takes --quick, --threads, --out, --json and --methods (policies).
      const experiment::MetgOptions mo{o->quick, o->out_dir, o->threads, o->methods};
      experiment::Progress progress(stderr, experiment::Progress::is_terminal(stderr));
      const experiment::MetgResult r = experiment::run_metg(mo, progress);
      std::cout << (a->json ? experiment::metg_json(r) + "\n" : experiment::metg_text(r))
                << std::flush;
      return;
    }
    if (a->method == "scaling") {
      // Live runs only: --quick, --threads, --out, --json, --methods, --steps, --repeat.
      if (!o->subobjects.empty())
        throw UsageError("--subobjects applies to the domain experiment only");
      if (o->replay)
        throw UsageError(std::string(*o->replay ? "--replay" : "--no-replay") +
                         ": the scaling experiment makes live runs only");
      const experiment::ScalingOptions so{o->quick,   o->out_dir, o->threads,
                                          o->methods, o->steps,   o->repeat};
      experiment::Progress progress(stderr, experiment::Progress::is_terminal(stderr));
      const experiment::ScalingResult r = experiment::run_scaling(so, progress);
      std::cout << (a->json ? experiment::scaling_json(r) + "\n" : experiment::scaling_text(r))
                << std::flush;
      if (!r.failed.empty())
        throw Failure(std::to_string(r.failed.size()) + " scaling run(s) failed");
      return;
    }
    o->name = *experiment::parse_experiment_name(a->method);
    experiment::Progress progress(stderr, experiment::Progress::is_terminal(stderr));
    const experiment::ExperimentResult r = experiment::run_experiment(*o, progress);
    std::cout << (a->json ? experiment::experiment_json(r) + "\n" : experiment::experiment_text(r))
              << std::flush;
    if (r.failures() != 0)
      throw Failure(std::to_string(r.failures()) + " experiment run(s) failed");
  });
}

}  // namespace tgraph::app
