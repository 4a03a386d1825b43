// SPDX-License-Identifier: MIT
#include "tgraph/measure/passes.hpp"

#include "tgraph/graph/median.hpp"

namespace tgraph::measure {

void PassTimes::add(std::size_t step, std::int64_t ns) {
  by_step_[step].push_back(ns);
  current_ += ns;
}

void PassTimes::end_pass() {
  totals_.push_back(current_);
  current_ = 0;
}

std::int64_t PassTimes::step_median(std::size_t step) const { return median(by_step_[step]); }

std::int64_t PassTimes::median_total() const { return median(totals_); }

}  // namespace tgraph::measure
