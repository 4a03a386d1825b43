// SPDX-License-Identifier: MIT
// Interleaved timed passes and their medians: every measurement of tgraph (replays, live
// runs, validations) times several passes, pass by pass beside its baseline so that both see
// the same machine noise, and reports the median over passes of each step and of the totals.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace tgraph::measure {

/// One quantity timed over passes, step by step.
///
///   PassTimes wall(steps);
///   for (pass...) { for (s...) wall.add(s, ns); wall.end_pass(); }
///   wall.step_median(s); wall.median_total();
class PassTimes {
 public:
  explicit PassTimes(std::size_t steps = 0) : by_step_(steps) {}
  /// This pass's value of step `step` (added to the pass's total).
  void add(std::size_t step, std::int64_t ns);
  /// Closes the pass: its total joins pass_totals().
  void end_pass();
  /// Median over the passes of step `step` (0: no pass).
  std::int64_t step_median(std::size_t step) const;
  /// Median over the passes of their totals (0: no pass).
  std::int64_t median_total() const;
  /// Each closed pass's total, in order.
  const std::vector<std::int64_t>& pass_totals() const { return totals_; }
  std::size_t steps() const { return by_step_.size(); }

 private:
  std::vector<std::vector<std::int64_t>> by_step_;
  std::vector<std::int64_t> totals_;
  std::int64_t current_ = 0;
};

}  // namespace tgraph::measure
