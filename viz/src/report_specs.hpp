// SPDX-License-Identifier: MIT
// The report's Vega-Lite chart specifications (report_specs.cpp), used by report.cpp.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>

#include "tgraph/explain/explain.hpp"
#include <string>

#include "tgraph/viz/report.hpp"
#include "tgraph/viz/timeline.hpp"

namespace tgraph::viz::detail {

/// Speed-up against threads: measured points, predicted lines, the ideal and the bound.
nlohmann::json speedup_spec(const ReportContent& c);
/// Bars of measured and predicted speed-up per method at the largest K measured.
nlohmann::json methods_spec(const ReportContent& c);
/// Per-step partition time (or migrations), one line per method, contact changes as rules.
nlohmann::json series_spec(const ReportContent& c, bool migrations);
/// The replay timeline as a Gantt chart (the first steps); `caption` says what is shown.
nlohmann::json timeline_spec(const Timeline& t, std::string* caption,
                             const explain::Explanation* path = nullptr);
/// Stacked bars of the lost time by cause: one bar per step of `e`.
nlohmann::json lost_steps_spec(const explain::Explanation& e);
/// Stacked bars of the lost time by cause: one bar per run (policy).
nlohmann::json lost_runs_spec(const std::vector<RunAttribution>& runs);
/// 1234567 -> "1,234,567".
std::string with_commas(std::uint64_t v);

}  // namespace tgraph::viz::detail
