// SPDX-License-Identifier: MIT
// Standard Task Graph Set (Kasahara lab) files as one-step traces.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "tgraph/graph/trace.hpp"

namespace tgraph {

/// An STG file read into a trace.
struct StgGraph {
  Trace trace;                          ///< one step; edges derived
  std::optional<std::uint64_t> cp_length;  ///< "CP Length" stated in the trailer (STG units)
};

/// Parses STG text: the first line holds n, then n + 2 task lines "id cost npred preds...";
/// task 0 and n + 1 are the dummy entry and exit (cost 0). Each STG time unit becomes
/// `unit_ns` ns; each precedence edge becomes a datum of `edge_bytes` bytes written by the
/// predecessor and read by the successor. Throws InputError naming `name` and the offset.
StgGraph parse_stg(std::string_view text, const std::string& name, std::uint64_t unit_ns = 1000,
                   std::uint64_t edge_bytes = 8);
/// Reads and parses an STG file.
StgGraph read_stg(const std::string& path, std::uint64_t unit_ns = 1000,
                  std::uint64_t edge_bytes = 8);

/// The report on `g` read from `input` and written to `output`: one JSON object (input,
/// output, tasks, edges, unit_ns, cp_length) or a text line and "wrote ...".
std::string stg_import_report(const StgGraph& g, const std::string& input,
                              const std::string& output, std::uint64_t unit_ns, bool json);
/// The STG file `input` (read_stg) written as the trace `output`: its stg_import_report.
std::string import_stg(const std::string& input, const std::string& output,
                       std::uint64_t unit_ns, std::uint64_t edge_bytes, bool json);

}  // namespace tgraph
