// SPDX-License-Identifier: MIT
// Baselines: `single` (the null object), `roundrobin` and `random`.
#include <random>

#include "strategies.hpp"

namespace tgraph::partition::detail {

namespace {

/// Everything on processor 0: the sequential schedule.
class Single final : public Strategy {
 public:
  std::string_view name() const override { return "single"; }

 private:
  Result do_partition(const StepGraph& g, std::uint32_t k, const Previous&, const Options&) override {
    Result r;
    r.assignment.k = k;
    r.assignment.proc.assign(g.tasks.size(), 0);
    return r;
  }
};

/// Task t on processor t mod K, blind to costs and data.
class RoundRobin final : public Strategy {
 public:
  std::string_view name() const override { return "roundrobin"; }

 private:
  Result do_partition(const StepGraph& g, std::uint32_t k, const Previous&, const Options&) override {
    return {one_task_per_processor(g, k), {}};
  }
};

/// Each task on a processor drawn uniformly (seeded, reproducible).
class Random final : public Strategy {
 public:
  std::string_view name() const override { return "random"; }

 private:
  Result do_partition(const StepGraph& g, std::uint32_t k, const Previous&,
                      const Options& options) override {
    std::mt19937_64 rng(options.seed);
    Result r;
    r.assignment.k = k;
    r.assignment.proc.resize(g.tasks.size());
    for (auto& p : r.assignment.proc) p = static_cast<ProcId>(rng() % k);
    return r;
  }
};

}  // namespace

std::unique_ptr<Strategy> make_single() { return std::make_unique<Single>(); }
std::unique_ptr<Strategy> make_roundrobin() { return std::make_unique<RoundRobin>(); }
std::unique_ptr<Strategy> make_random() { return std::make_unique<Random>(); }

}  // namespace tgraph::partition::detail
