// SPDX-License-Identifier: MIT
// The median of repeated measurements (replays, live runs, validations, benchmarks).
#pragma once

#include <algorithm>
#include <vector>

namespace tgraph {

/// Median of `v`: the middle value, or the mean of the two middle values (in T's arithmetic)
/// for an even count; T{} for none.
template <class T>
T median(std::vector<T> v) {
  if (v.empty()) return T{};
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : (v[v.size() / 2 - 1] + v[v.size() / 2]) / 2;
}

}  // namespace tgraph
