// SPDX-License-Identifier: MIT
// When a live run repartitions a step whose structure repeats: only when the predicted gain
// over the next steps exceeds what repartitioning costs, and the drift is more than noise.
#pragma once

#include <cstdint>
#include <vector>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/step_graph.hpp"

namespace tgraph::measure {

/// The knobs of RepartitionTrigger.
struct TriggerOptions {
  /// Drift below this share of the reference imbalance is taken for noise (measured costs
  /// of the same task vary from step to step: preemption, caches, the core it ran on).
  double tolerance = 0.05;
  /// partition::loop_imbalance's heavy-loop share.
  double loop_share = 0.1;
  /// Steps over which a repartition must pay for itself.
  std::uint32_t horizon = 10;
  /// Cost of refilling a cache with one byte of data that moved to another core, ns.
  double per_byte_ns = 0.05;
};

/// Decides, step after step, whether the assignment in use should be remade.
///
/// The reference is the mean of the assignment's imbalances (partition::loop_imbalance)
/// observed since it came into use, under the costs measured while it ran, not its
/// imbalance under the costs it was made from: a partitioner balances the noise of the costs
/// it is given, so its own imbalance is biased low, and every fresh sample of noise would
/// look like drift. An observation is a drift when it exceeds the reference by more than
/// `tolerance` of it and by more than three standard deviations of the observations so far
/// (their noise: on an oversubscribed or preempted machine the measured costs swing by tens
/// of per cent), after at least kSettle observations; drifts stay out of the reference and
/// the noise unless the next observation is not one. It fires when two drifts follow each
/// other and the predicted gain, (current - reference) x the mean processor load per step
/// over `horizon` steps, exceeds the cost: the plan rebuild (as last measured) plus the
/// migration of one processor's share of the data.
///
///   RepartitionTrigger trigger({.horizon = 10});
///   // each step, after the measured costs were written into g:
///   if (trigger.observe(g, assignment, last_build_ns)) repartition();  // then reset()
class RepartitionTrigger {
 public:
  /// Observations that set the reference and its noise before any can fire.
  static constexpr std::uint32_t kSettle = 3;

  explicit RepartitionTrigger(TriggerOptions options = {}) : o_(options) {}

  /// The assignment (or the step's structure) changed: observations start afresh.
  void reset() {
    count_ = 0;
    mean_ = m2_ = 0.0;
    pending_.clear();
  }

  /// One step measured (`g` holds the smoothed costs and loop counts; `a` the assignment in
  /// use; `rebuild_ns` what building the plans of a new assignment costs). True: repartition.
  bool observe(const StepGraph& g, const Assignment& a, std::int64_t rebuild_ns);

  /// The reference: the mean imbalance observed since the last reset (before the last
  /// observation was added).
  double reference() const { return reference_; }
  /// The imbalance of the last observation.
  double current() const { return current_; }
  /// The last drift's predicted gain over the horizon, and its cost, ns (0 otherwise).
  double gain_ns() const { return gain_ns_; }
  double cost_ns() const { return cost_ns_; }

 private:
  void add(double x);

  TriggerOptions o_;
  // Welford's running mean and sum of squared deviations of the observations that were not
  // (or turned out not to be) drifts.
  std::uint32_t count_ = 0;
  double mean_ = 0.0, m2_ = 0.0;
  std::vector<double> pending_;  // the drifts in a row so far
  double reference_ = 1.0, current_ = 1.0, gain_ns_ = 0.0, cost_ns_ = 0.0;
};

}  // namespace tgraph::measure
