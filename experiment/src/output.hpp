// SPDX-License-Identifier: MIT
// Writing an experiment's results: CSV, JSON, the HTML page and the charts.
#pragma once

#include <vector>

#include "tgraph/experiment/experiment.hpp"
#include "tgraph/viz/series_chart.hpp"

namespace tgraph::experiment {

/// Speed-up against threads: measured (live) and predicted series per scene and method.
viz::SeriesChart speedup_chart(const ExperimentResult& result);
/// The per-step charts of the heterogeneous experiment (empty without per-step runs).
std::vector<std::pair<std::string, viz::SeriesChart>> step_charts(const ExperimentResult& result);
/// Writes every output file of `result` into its folder and lists them in result.files.
void write_outputs(ExperimentResult& result);

}  // namespace tgraph::experiment
