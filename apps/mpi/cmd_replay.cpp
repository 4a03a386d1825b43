// SPDX-License-Identifier: MIT
// `tgraph-mpi replay` (being built: refuses to run until then).
#include <stdexcept>

#include "verbs.hpp"

namespace tgraph::mpi_app {

void add_replay_verb(CLI::App& app) {
  auto* cmd = app.add_subcommand("replay", "(not built yet)");
  cmd->allow_extras();
  cmd->callback([] { throw std::runtime_error("replay: not built yet"); });
}

}  // namespace tgraph::mpi_app
