// SPDX-License-Identifier: MIT
// The HTML report of `tgraph report` and `tgraph demo`: one self-contained page (Vega-Lite,
// Vega, Vega-Embed and Panzoom inlined, no network) with the scene, the method x K table,
// speed-up charts, per-step partition time and migrations, the replay timeline, the step
// graph (pan and zoom) and the partition's quotient graph.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/viz/timeline.hpp"

namespace tgraph::viz {

/// One row of the comparison: a method at K processors, or a dynamic baseline at K threads.
struct MethodRow {
  std::string method;
  std::uint32_t k = 1;
  bool partitioned = false;  ///< a graph partition (else the partition columns are empty)
  double partition_ms = 0;   ///< over the whole trace
  double imbalance = 0;      ///< max load / mean load
  std::uint64_t cut_bytes = 0;
  std::uint64_t migrated_tasks = 0;
  std::optional<double> predicted_speedup;  ///< simulated: work / makespan
  std::optional<double> measured_ms;        ///< replay wall time
  std::optional<double> sequential_ms;      ///< sequential replay timed in the same run
  std::optional<double> speedup;            ///< measured
  std::optional<double> efficiency;         ///< speed-up / threads
  std::optional<std::uint64_t> signals;
  std::string failure;  ///< why the replay could not run (empty: it ran or was not asked for)
};

/// Per-step figures of one method at one K (partition time and migrations over the run).
struct StepSeries {
  std::string method;
  std::uint32_t k = 1;
  std::vector<double> partition_ms;
  std::vector<std::uint64_t> migrated_tasks;
};

/// The lost time of one run by cause (explain::Attribution's figures, by cause name), for
/// the report's bars per policy.
struct RunAttribution {
  std::string label;  ///< the run: its policy or method and threads, or its file
  std::int64_t lost_ns = 0;
  std::vector<std::pair<std::string, std::int64_t>> causes;  ///< explain::cause_names() order
};

/// Everything the page shows.
///
///   ReportContent c = report_content(trace, "b.tgt", &assignment.steps[1], 1);
///   c.rows.push_back(row);
///   write_file_atomic("report.html", report_html(c));
struct ReportContent {
  std::string title;
  std::vector<std::pair<std::string, std::string>> facts;  ///< scene and machine, label -> value
  double parallelism = 0;                      ///< work / span of the trace (speed-up bound)
  std::vector<std::uint32_t> contact_changes;  ///< steps whose contact set changed
  std::vector<MethodRow> rows;
  std::vector<StepSeries> series;
  std::optional<Timeline> timeline;  ///< with step graphs: explained (lost time, critical path)
  std::string timeline_caption;
  std::vector<RunAttribution> attributions;  ///< replays' and timelines' lost time by cause
  std::string graph_svg;  ///< the step graph (Graphviz SVG), empty: none
  std::string graph_caption;
  std::size_t graph_step = 0;  ///< the step it shows
  std::string quotient_svg;    ///< the assignment's quotient graph of that step, empty: none
  std::string quotient_caption;
  std::vector<std::string> notes;  ///< paragraphs under the title
};

/// Facts, parallelism, contact changes and the step graph of `trace` (collapsed by object,
/// coloured by `assignment` when given, critical path highlighted) for step `step`.
ReportContent report_content(const Trace& trace, const std::string& trace_name,
                             const Assignment* assignment, std::size_t step,
                             const std::string& assignment_name = {});

/// Draws `q`, the quotient graph of the step graph's assignment (partition::step_quotient
/// of step `c.graph_step`), beside the step graph; `method` names the assignment.
void set_quotient(ReportContent& c, const QuotientGraph& q, const std::string& method);

/// Adds the rows (and per-step series) of a comparison's JSON text (partition's
/// comparison_json); throws InputError naming `name` when the text is not such a comparison.
void add_compare_json(ReportContent& c, std::string_view json, const std::string& name);
/// Adds a replay file: a timeline (timeline_json, gzip-compressed or not; the first one is
/// drawn; one with step graphs adds its attribution) or a measurement (a replay's JSON
/// report, one measured row, and its "attribution" when it has one). Throws InputError
/// otherwise.
void add_replay_json(ReportContent& c, std::string_view json, const std::string& name);

/// Draws the step graph of `c` again with the executed critical path of its step in
/// `c.timeline` (tgraph explain's) instead of the graph's own longest path, when the timeline
/// explains that step of `trace` (its graph replayed from this trace's step); `assignment`
/// colours it as report_content's did. Returns whether it did (else the picture stays).
bool draw_executed_path(ReportContent& c, const Trace& trace, const std::string& trace_name,
                        const Assignment* assignment, const std::string& assignment_name = {});

/// A report of files: report_content of step `step` (step 0 when the trace has no such step),
/// coloured by that step of `assignment` (nullptr: none), then the comparison file
/// `compare_path` (empty: none) and each replay file (add_compare_json, add_replay_json),
/// then the first timeline's executed critical path on the step graph (draw_executed_path).
ReportContent report_from_files(const Trace& trace, const std::string& trace_name,
                                const TraceAssignment* assignment, std::size_t step,
                                const std::string& compare_path,
                                const std::vector<std::string>& replay_paths);

/// A step's quotient graph under its assignment, from a front end (partition::step_quotient,
/// whose signal counts come from the partition module's simulator, which viz does not link).
using StepQuotient = std::function<QuotientGraph(const StepGraph&, const Assignment&)>;

/// report_from_files, with `quotient` of the step graph's assignment beside the step graph
/// (set_quotient) when both are drawn, written to `output` as report_html, atomically.
void write_report(const Trace& trace, const std::string& trace_name,
                  const TraceAssignment* assignment, std::size_t step,
                  const std::string& compare_path, const std::vector<std::string>& replay_paths,
                  const StepQuotient& quotient, const std::string& output);

/// The page. Charts are Vega-Lite specifications rendered as SVG by the inlined libraries; a
/// chart that fails to render shows its error in place and on the console.
std::string report_html(const ReportContent& c);

/// Three significant digits, no exponent below 1e6 ("4.47", "0.0123", "1230").
std::string round3(double v);

}  // namespace tgraph::viz
