// SPDX-License-Identifier: MIT
// Helpers shared by viz's renderers (chart_util.cpp): HTML text and page heads, numbers as
// tick labels, and cairo drawing onto an SVG or PNG in memory.
#pragma once

#include <functional>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "tgraph/graph/fixed.hpp"
#include "tgraph/viz/timeline.hpp"

// cairo's own declaration (cairo.h), so that users of these helpers need not see cairo.
typedef struct _cairo cairo_t;

namespace tgraph::viz::detail {

/// `s` with <, >, & and " written as HTML entities.
std::string escape(std::string_view s);
/// JSON to embed in a <script>: "</" is written "<\/" so no text can close the element.
std::string script_json(const nlohmann::json& j);

/// First script of a page: records uncaught errors, rejected promises and console.error
/// calls on <html data-js-errors> (what the browser tests read; visible in the inspector).
extern const char* const kErrorHookScript;
/// Renders every Vega-Lite specification of #tgraph-specs into the element of its id; a
/// failure is shown in place and logged as a console error.
extern const char* const kRenderScript;
/// "<!doctype html>...<head>" with `title`, `style`, the error hook and the inlined `libs`,
/// up to and including "</head><body>".
std::string page_head(const std::string& title, const char* style,
                      std::initializer_list<const char*> libs);

/// A "nice" tick step (1, 2 or 5 x 10^n) giving about `target` ticks over `range`.
double tick_step(double range, int target);
/// The digits after the point that a tick step needs.
int decimals_for(double step);

/// Sets the source colour from "#RRGGBB".
void set_colour(cairo_t* cr, const std::string& hex, double alpha = 1.0);
/// Writes `s` at (x, y); `align`: 0 left, 0.5 centre, 1 right.
void text_at(cairo_t* cr, double x, double y, const std::string& s, double size, double align = 0);
/// Runs `draw` on a `width` x `height` SVG or PNG surface and returns the document; throws
/// std::runtime_error on a cairo failure.
std::string render_cairo(TimelineFormat format, double width, double height,
                         const std::function<void(cairo_t*)>& draw);

}  // namespace tgraph::viz::detail
