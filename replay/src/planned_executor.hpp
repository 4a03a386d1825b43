// SPDX-License-Identifier: MIT
// Internal: the typed side of Executor's plan cache. Each executor derives from
// PlannedExecutor<ItsPlan> and builds, updates and runs plans of its own type; the cache in
// the base holds them as ExecPlan.
#pragma once

#include <cstdint>
#include <memory>
#include <utility>

#include "tgraph/replay/executor.hpp"

namespace tgraph::replay::detail {

/// What the tasks of the running step read (set by the executor before any task starts).
template <class Plan>
struct StepContext {
  Plan* plan = nullptr;
  const ExecGraph* exec = nullptr;
  Workload* workload = nullptr;
};

/// A plan in Executor's cache; its dynamic type is PlannedExecutor<P>::Held.
class ExecPlan {
 public:
  virtual ~ExecPlan() = default;
};

/// An executor whose plans are `Plan`s.
template <class Plan>
class PlannedExecutor : public Executor {
 protected:
  using Executor::Executor;

 private:
  /// Builds the plan for `x` from scratch.
  virtual std::unique_ptr<Plan> build_plan(const ExecGraph& x) = 0;
  /// Builds the plan for `x` from `previous`, the plan of the previous step. Default: from
  /// scratch.
  virtual std::unique_ptr<Plan> update_plan(const ExecGraph& x, const Plan& /*previous*/) {
    return build_plan(x);
  }
  /// Processors whose program the build of `plan` computed (default: every thread).
  virtual std::uint32_t rebuilt(const Plan& /*plan*/) const { return threads(); }
  /// Runs one step with `plan`.
  virtual void run(Plan& plan, const ExecGraph& x, Workload& w, bool fresh,
                   ExecStepStats& stats) = 0;

  struct Held final : ExecPlan {
    explicit Held(std::unique_ptr<Plan> p) : plan(std::move(p)) {}
    std::unique_ptr<Plan> plan;
  };
  // Every plan in this executor's cache was made by build() below: the casts are exact.
  static Plan& of(ExecPlan& p) { return *static_cast<Held&>(p).plan; }
  static const Plan& of(const ExecPlan& p) { return *static_cast<const Held&>(p).plan; }

  std::unique_ptr<ExecPlan> build(const ExecGraph& x, const ExecPlan* previous) final {
    return std::make_unique<Held>(previous != nullptr ? update_plan(x, of(*previous))
                                                      : build_plan(x));
  }
  std::uint32_t rebuilt_procs(const ExecPlan& plan) const final { return rebuilt(of(plan)); }
  void execute(ExecPlan& plan, const ExecGraph& x, Workload& w, bool fresh,
               ExecStepStats& stats) final {
    run(of(plan), x, w, fresh, stats);
  }
};

}  // namespace tgraph::replay::detail
