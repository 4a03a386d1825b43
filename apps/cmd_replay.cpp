// SPDX-License-Identifier: MIT
// Placeholder until issue 5 lands: the verb(s) answer "not built yet" with exit 1.
#include "commands.hpp"

namespace tgraph::app {

void add_replay_verbs(CLI::App& app) { (void)app; }

}  // namespace tgraph::app
