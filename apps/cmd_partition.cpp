// SPDX-License-Identifier: MIT
// Placeholder until issue 4 lands: the verb(s) answer "not built yet" with exit 1.
#include "commands.hpp"

namespace tgraph::app {

void add_partition_verbs(CLI::App& app) { (void)app; }

}  // namespace tgraph::app
