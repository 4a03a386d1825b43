// SPDX-License-Identifier: MIT
// Internal: small pieces the experiments share (comma lists, the date stamp, the results
// folder).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace tgraph::experiment::detail {

/// "a,b,c" -> {"a", "b", "c"} (empty items kept, so that the caller can refuse them).
std::vector<std::string> split_list(std::string_view text);
/// The items joined by `sep`.
std::string join(const std::vector<std::string>& v, const char* sep = ",");
/// Now, UTC, as 2026-11-28T10:55:00Z.
std::string utc_now();
/// Creates `dir` (and its parents) for an experiment's results; UsageError naming --out when
/// it cannot.
void make_results_folder(const std::string& dir);

}  // namespace tgraph::experiment::detail
