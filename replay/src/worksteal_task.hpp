// SPDX-License-Identifier: MIT
// Internal: the functor oneTBB runs for one task instance. Its call operator lives in its
// own file, not instrumented by ThreadSanitizer: reading the functor's fields, which TBB hands
// from the spawning thread through its uninstrumented deques, is not a race.
#pragma once

#include <cstdint>

#include "tgraph/graph/step_graph.hpp"

namespace tgraph::replay::detail {

/// Runs instance (task, iteration) through `fn(context, task, iteration)`.
struct SpawnedInstance {
  void (*fn)(void*, TaskId, std::uint32_t);
  void* context;
  TaskId task;
  std::uint32_t iteration;
  void operator()() const;
};

}  // namespace tgraph::replay::detail
