// SPDX-License-Identifier: MIT
// Generic line charts of numeric series (speed-up against threads, a figure over the steps
// of a run): as a Vega-Lite specification for HTML pages, as a static SVG or PNG (cairo) for
// documents, and a self-contained HTML page of tables and such charts.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "tgraph/viz/timeline.hpp"

namespace tgraph::viz {

/// What a series shows; measured and predicted values are drawn differently and never in
/// one series.
enum class SeriesKind : std::uint8_t {
  kMeasured = 0,   ///< solid line, filled markers
  kPredicted = 1,  ///< dashed line, open markers; its legend entry says "predicted"
  kReference = 2,  ///< thin black dotted line (the ideal speed-up, a bound)
};

/// "measured", "predicted" or "reference".
std::string_view to_string(SeriesKind kind);

/// One point of a series.
struct SeriesPoint {
  double x = 0;
  double y = 0;
};

/// One line of a chart.
struct Series {
  std::string name;  ///< legend label
  SeriesKind kind = SeriesKind::kMeasured;
  /// Colour index in the chart's line palette; series of one method (measured and
  /// predicted) share it. Ignored for references (black).
  std::uint32_t colour = 0;
  std::vector<SeriesPoint> points;
};

/// A vertical rule across the plot (a core count, a step whose contacts changed).
struct SeriesMark {
  double x = 0;
  std::string label;  ///< drawn at the top of the rule (may be empty)
};

/// A chart of several series over one x axis.
///
///   SeriesChart c{"Speed-up", "bars64", "threads", "speed-up (x)", true};
///   c.series.push_back({"owner", SeriesKind::kMeasured, 0, {{1, 0.98}, {2, 1.9}}});
///   write_file_atomic("speedup.svg", render_series_chart(c, TimelineFormat::kSvg));
struct SeriesChart {
  std::string title;
  std::string subtitle;
  std::string x_title;
  std::string y_title;
  bool log2_x = false;  ///< x on a base-2 log scale (thread counts), ticks at powers of 2
  bool log2_y = false;  ///< y on a base-2 log scale (speed-ups), ticks at powers of 2
  bool markers = true;  ///< a marker at every point (off for long series such as steps)
  std::vector<Series> series;
  std::vector<SeriesMark> marks;
};

/// Colour of index `i` of the line palette (Okabe-Ito without yellow, then Paul Tol's
/// "muted" scheme), "#RRGGBB".
std::string series_colour(std::uint32_t i);

/// The chart as a Vega-Lite v5 specification (JSON text) drawing the same as
/// render_series_chart.
std::string series_chart_spec(const SeriesChart& chart);

/// The chart drawn with cairo as SVG or PNG bytes (tgraph::write_file_atomic them).
std::string render_series_chart(const SeriesChart& chart, TimelineFormat format);

/// A table of preformatted cells; an empty cell is shown as a dash.
struct SeriesTable {
  std::string caption;
  std::vector<std::string> columns;
  std::vector<std::vector<std::string>> rows;
};

/// An HTML page of facts, notes, tables and charts.
struct SeriesPage {
  std::string title;
  std::vector<std::string> notes;                          ///< paragraphs under the title
  std::vector<std::pair<std::string, std::string>> facts;  ///< label -> value
  std::vector<SeriesTable> tables;
  std::vector<SeriesChart> charts;
};

/// One self-contained page (Vega, Vega-Lite and Vega-Embed inlined, no network); a chart
/// that fails to render shows its error in place and on the console, as report_html does.
std::string series_page_html(const SeriesPage& page);

}  // namespace tgraph::viz
