// SPDX-License-Identifier: MIT
// `tgraph-mpi partition` (being built: refuses to run until then).
#include <stdexcept>

#include "verbs.hpp"

namespace tgraph::mpi_app {

void add_partition_verb(CLI::App& app) {
  auto* cmd = app.add_subcommand("partition", "(not built yet)");
  cmd->allow_extras();
  cmd->callback([] { throw std::runtime_error("partition: not built yet"); });
}

}  // namespace tgraph::mpi_app
