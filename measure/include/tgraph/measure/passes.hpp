// SPDX-License-Identifier: MIT
// Interleaved timed passes and their medians: every measurement of tgraph (replays, live
// runs, validations) times several passes, pass by pass beside its baseline so that both see
// the same machine noise, and reports the median over passes of each step and of the totals.
#pragma once

#include <array>
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

/// Several fields of a per-step record, timed over the same passes: a pass's records added at
/// once, each field's median over the passes written back step by step.
///
///   StepFieldTimes<LiveStepMeasure, 2> t({&LiveStepMeasure::wall_ns,
///                                         &LiveStepMeasure::execute_ns}, steps);
///   for (pass...) t.add_pass(pass_steps);
///   t.write_medians(result_steps);  t.times(0).median_total();
template <class Step, std::size_t N>
class StepFieldTimes {
 public:
  using Field = std::int64_t Step::*;
  StepFieldTimes(const std::array<Field, N>& fields, std::size_t steps) : fields_(fields) {
    times_.fill(PassTimes(steps));
  }
  /// One pass: the fields of its first steps() records, then the pass closed.
  void add_pass(const std::vector<Step>& pass) {
    for (std::size_t f = 0; f < N; ++f) {
      for (std::size_t s = 0; s < times_[f].steps(); ++s) times_[f].add(s, pass[s].*fields_[f]);
      times_[f].end_pass();
    }
  }
  /// Each field of each of the first steps() records set to its median over the passes.
  void write_medians(std::vector<Step>& steps) const {
    for (std::size_t f = 0; f < N; ++f)
      for (std::size_t s = 0; s < times_[f].steps(); ++s)
        steps[s].*fields_[f] = times_[f].step_median(s);
  }
  /// The passes of field `f` (in the order given).
  const PassTimes& times(std::size_t f) const { return times_[f]; }

 private:
  std::array<Field, N> fields_;
  std::array<PassTimes, N> times_;
};

}  // namespace tgraph::measure
