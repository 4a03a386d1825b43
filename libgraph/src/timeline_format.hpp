// SPDX-License-Identifier: MIT
// Internal: what the two timeline formats share: the format of one object per event and the
// reader of both (timeline.cpp), and the columnar format of compact_timeline_json
// (timeline_columns.cpp). docs/replay.md describes both.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>

#include "tgraph/graph/timeline.hpp"

namespace tgraph::timeline_format {

using nlohmann::json;

/// Threads a timeline may have (rows of the picture).
constexpr std::uint32_t kMaxThreads = 4096;

/// e[key] as an unsigned 32-bit integer; throws json::type_error naming the key otherwise.
std::uint32_t get_u32(const json& e, const char* key);
/// e[key] as a signed 64-bit integer; throws json::type_error naming the key otherwise.
std::int64_t get_i64(const json& e, const char* key);

/// Reads "graphs" and "step_info" (both formats) into t; `events` bounds the step numbers.
void read_graphs(const json& j, Timeline& t, std::int64_t events);
/// The executed graphs and step information as both formats write them.
json graphs_json(const Timeline& t);
json step_info_json(const Timeline& t);
/// The columnar format (version 2); throws json::exception on a malformed column.
Timeline parse_columns(const json& j);

}  // namespace tgraph::timeline_format
