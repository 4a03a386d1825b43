// SPDX-License-Identifier: MIT
// Internal: small pieces the experiments share (the methods' check, lists as text, the date
// stamp, the results folder).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "tgraph/experiment/machine.hpp"
#include "tgraph/experiment/progress.hpp"
#include "tgraph/measure/live.hpp"

namespace tgraph::experiment::detail {

/// `methods` without duplicates, in their order; OptionError on `methods` for an unknown
/// name, sequential (every run's reference), partition (a strategy is named instead) or
/// starpu in a build without it.
std::vector<std::string> check_methods(const std::vector<std::string>& methods);
/// A live run's options: `threads`, `steps`, `repeat` timed passes, the observed pass or not;
/// the rest measure's defaults.
measure::LiveOptions live_options(std::uint32_t threads, std::uint32_t steps, std::uint32_t repeat,
                                  bool observe);
/// The items joined by `sep`.
std::string join(const std::vector<std::string>& v, const char* sep = ",");
/// The counts joined by commas ("1,2,4").
std::string join(const std::vector<std::uint32_t>& v);
/// Now, UTC, as 2026-11-28T10:55:00Z.
std::string utc_now();
/// Creates `dir` (and its parents) for an experiment's results; OptionError on `out` when it
/// cannot.
void make_results_folder(const std::string& dir);

/// What every planned experiment does first: probes the machine, plans `options` on its
/// cores (`plan(options, cores)`, which checks them), stamps the date, makes the plan's
/// results folder and sets the progress total to the plan's runs.
template <class Result, class Options, class Plan>
Result start_experiment(const Options& options, Plan plan, Progress& progress) {
  Result res;
  res.machine = probe_machine();
  res.plan = plan(options, res.machine.cores);
  res.date = utc_now();
  make_results_folder(res.plan.out_dir);
  progress.set_total(res.plan.runs());
  return res;
}

}  // namespace tgraph::experiment::detail
