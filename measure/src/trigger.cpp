// SPDX-License-Identifier: MIT
#include "tgraph/measure/trigger.hpp"

#include <algorithm>
#include <cmath>

#include "tgraph/partition/strategy.hpp"

namespace tgraph::measure {

void RepartitionTrigger::add(double x) {
  ++count_;
  const double delta = x - mean_;
  mean_ += delta / count_;
  m2_ += delta * (x - mean_);
}

bool RepartitionTrigger::observe(const StepGraph& g, const Assignment& a, std::int64_t rebuild_ns) {
  current_ = partition::loop_imbalance(g, a, o_.loop_share);
  gain_ns_ = cost_ns_ = 0.0;
  if (count_ < kSettle) {
    reference_ = count_ == 0 ? current_ : mean_;
    add(current_);
    return false;
  }
  reference_ = mean_;
  const double sigma = std::sqrt(m2_ / (count_ - 1));
  const double band = std::max(o_.tolerance * mean_, 3.0 * sigma);
  if (a.k < 2 || current_ <= mean_ + band) {
    // Not a drift: the drifts before it did not persist, they were noise.
    for (double x : pending_) add(x);
    pending_.clear();
    add(current_);
    return false;
  }
  pending_.push_back(current_);
  if (pending_.size() < 2) return false;
  long double work = 0, bytes = 0;
  for (TaskId t = 0; t < g.tasks.size(); ++t)
    work += static_cast<long double>(g.tasks[t].cost_ns) * g.runs(t);
  for (const Datum& d : g.data) bytes += static_cast<long double>(d.bytes);
  const long double mean_load = work / a.k;
  gain_ns_ = static_cast<double>((current_ - mean_) * mean_load * o_.horizon);
  cost_ns_ = static_cast<double>(rebuild_ns) + static_cast<double>(bytes / a.k) * o_.per_byte_ns;
  if (gain_ns_ > cost_ns_) return true;
  // A drift that does not pay for itself is the new normal.
  for (double x : pending_) add(x);
  pending_.clear();
  return false;
}

}  // namespace tgraph::measure
