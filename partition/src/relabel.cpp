// SPDX-License-Identifier: MIT
// Renaming the parts of a fresh partition after the previous step's (optimal assignment).
#include <limits>

#include "strategies.hpp"

namespace tgraph::partition {

namespace detail {

std::vector<std::uint32_t> max_weight_assignment(const std::vector<std::int64_t>& weight,
                                                 std::uint32_t k) {
  // Hungarian algorithm with row and column potentials on the cost -weight, O(k^3):
  // rows are added one at a time and each is routed along a shortest augmenting path.
  // Index 0 is a sentinel column; rows and columns are numbered from 1.
  const std::size_t n = k;
  constexpr std::int64_t kInf = std::numeric_limits<std::int64_t>::max() / 4;
  std::vector<std::int64_t> row_pot(n + 1, 0), col_pot(n + 1, 0), min_slack(n + 1);
  std::vector<std::size_t> row_of_col(n + 1, 0), prev_col(n + 1, 0);
  std::vector<char> visited(n + 1);
  for (std::size_t row = 1; row <= n; ++row) {
    row_of_col[0] = row;
    std::size_t col = 0;
    std::fill(min_slack.begin(), min_slack.end(), kInf);
    std::fill(visited.begin(), visited.end(), 0);
    do {
      visited[col] = 1;
      const std::size_t r = row_of_col[col];
      std::int64_t delta = kInf;
      std::size_t next = 0;
      for (std::size_t c = 1; c <= n; ++c) {
        if (visited[c]) continue;
        const std::int64_t slack = -weight[(r - 1) * n + (c - 1)] - row_pot[r] - col_pot[c];
        if (slack < min_slack[c]) {
          min_slack[c] = slack;
          prev_col[c] = col;
        }
        if (min_slack[c] < delta) {
          delta = min_slack[c];
          next = c;
        }
      }
      for (std::size_t c = 0; c <= n; ++c) {
        if (visited[c]) {
          row_pot[row_of_col[c]] += delta;
          col_pot[c] -= delta;
        } else {
          min_slack[c] -= delta;
        }
      }
      col = next;
    } while (row_of_col[col] != 0);
    do {  // flip the augmenting path
      const std::size_t before = prev_col[col];
      row_of_col[col] = row_of_col[before];
      col = before;
    } while (col != 0);
  }
  std::vector<std::uint32_t> to(n);
  for (std::size_t c = 1; c <= n; ++c) to[row_of_col[c] - 1] = static_cast<std::uint32_t>(c - 1);
  return to;
}

}  // namespace detail

std::uint64_t relabel_to_previous(const StepGraph& g, const Previous& prev, Assignment& a) {
  if (prev.graph == nullptr || prev.assignment == nullptr || prev.assignment->k != a.k || a.k < 2)
    return 0;
  const std::uint32_t k = a.k;
  const std::vector<TaskId> match = match_by_key(g, *prev.graph);
  // overlap[new part * k + old part] = matched tasks in both.
  std::vector<std::int64_t> overlap(static_cast<std::size_t>(k) * k, 0);
  for (TaskId t = 0; t < a.proc.size() && t < match.size(); ++t) {
    if (match[t] == kNoTask) continue;
    const ProcId old = prev.assignment->proc[match[t]];
    if (old < k && a.proc[t] < k) ++overlap[static_cast<std::size_t>(a.proc[t]) * k + old];
  }
  const std::vector<std::uint32_t> rename = detail::max_weight_assignment(overlap, k);
  std::uint64_t kept = 0;
  for (std::uint32_t p = 0; p < k; ++p)
    kept += static_cast<std::uint64_t>(overlap[static_cast<std::size_t>(p) * k + rename[p]]);
  for (ProcId& p : a.proc)
    if (p < k) p = rename[p];
  if (!a.order.empty()) {
    std::vector<std::vector<TaskId>> order(k);
    for (std::uint32_t p = 0; p < k && p < a.order.size(); ++p)
      order[rename[p]] = std::move(a.order[p]);
    a.order = std::move(order);
  }
  return kept;
}

}  // namespace tgraph::partition
