// SPDX-License-Identifier: MIT
// Replay timelines (tgraph::Timeline, which replay's TimelineObserver records): drawing them as
// a Gantt chart with cairo (SVG, PNG), and converting them to Chrome / Perfetto trace events.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "tgraph/graph/timeline.hpp"

namespace tgraph::viz {

/// Steps [first, last] (inclusive) of `t`; OptionError on `steps` when none is in range.
Timeline select_steps(const Timeline& t, std::uint32_t first, std::uint32_t last);
/// Parses a step range "a:b", "a:" (to the last), ":b" (from 0) or "a" (one step); nullopt
/// for anything else, and when a > b.
std::optional<std::pair<std::uint32_t, std::uint32_t>> parse_step_range(std::string_view text);

/// Output formats of a timeline picture.
enum class TimelineFormat : std::uint8_t { kSvg = 0, kPng = 1 };
/// "svg" or "png".
std::string_view to_string(TimelineFormat f);
/// Format from a file name's extension; throws UsageError naming the file (the field
/// `output`) otherwise.
TimelineFormat timeline_format_of(const std::string& path);

/// The Gantt chart: one row per thread, tasks coloured by kind (legend of the kinds ranked
/// by time), waits hatched grey, step boundaries as solid lines, the start of each loop
/// iteration as dotted lines, axis in ms. `title` is drawn above the chart.
std::string render_timeline(const Timeline& t, TimelineFormat format, const std::string& title);
/// The chart's title for `t` read from `path`: "<file name>: T threads, N task instances, W
/// blocking waits".
std::string timeline_title(const Timeline& t, const std::string& path);
/// The timeline file `input` (read_timeline), its steps `steps` ("a:b", "a:", ":b" or "a";
/// empty: all), drawn with its timeline_title into `output` in the format of its extension,
/// atomically. UsageError naming the field `steps` for a malformed range; select_steps'
/// OptionError for a range without tasks.
void draw_timeline(const std::string& input, const std::string& steps, const std::string& output);

/// A cross-thread dependency in a timeline: `to` (a wait) was released when `from` (a task
/// instance on another thread) ended.
struct TimelineFlow {
  std::size_t from_task = 0;  ///< index in Timeline::tasks
  std::size_t to_wait = 0;    ///< index in Timeline::waits
};
/// For each wait, the task instance that released it: in the same step, on another thread,
/// the one whose end is the latest at or before the wait's end (the timeline does not record
/// which datum was awaited; waits with no such task get no flow).
std::vector<TimelineFlow> timeline_flows(const Timeline& t);

/// Chrome / Perfetto trace-event JSON: one complete event per task instance and per wait
/// (microseconds, steps end to end), thread names, and a flow arrow ("s" -> "f") for each
/// timeline_flows() entry, which Perfetto and chrome://tracing draw as signal -> wait arrows.
std::string chrome_trace(const Timeline& t);

}  // namespace tgraph::viz
