// SPDX-License-Identifier: MIT
// `tgraph explain FILE [--step N] [--json]` as a call: FILE a timeline (replay/run
// --timeline), or a run's or replay's JSON, whose timeline (its "timeline" key, relative to
// the file) it explains when that exists, else whose attribution it prints per step.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace tgraph::explain {

struct ExplainCommand {
  std::string input;                  ///< the file
  std::optional<std::uint32_t> step;  ///< only this step
  bool json = false;                  ///< one JSON object, else the table
};

/// The output of the verb; InputError naming the file for input it cannot read.
std::string explain_command(const ExplainCommand& c);

}  // namespace tgraph::explain
