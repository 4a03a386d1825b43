// SPDX-License-Identifier: MIT
// The charting and pan/zoom libraries inlined into the HTML report, compiled in at build time from
// the npm packages pinned by viz/web/package-lock.json (the page needs no network).
#pragma once

#include <string_view>

namespace tgraph::viz::detail {

/// The minified bundle of "vega", "vega-lite", "vega-embed" or "panzoom"; empty for another name.
std::string_view web_asset(std::string_view name);
/// "vega 5.30.0 (BSD-3-Clause), ..., @panzoom/panzoom 4.6.2 (MIT)" (from the installed packages).
std::string_view web_asset_versions();

}  // namespace tgraph::viz::detail
