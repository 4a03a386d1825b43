// SPDX-License-Identifier: MIT
#include "worksteal_task.hpp"

namespace tgraph::replay::detail {

void SpawnedInstance::operator()() const { fn(context, task, iteration); }

}  // namespace tgraph::replay::detail
