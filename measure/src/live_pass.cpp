// SPDX-License-Identifier: MIT
#include "live_pass.hpp"

#include <algorithm>
#include <memory>
#include <string>

#include "background_partitioner.hpp"
#include "live_observers.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/measure/trigger.hpp"
#include "tgraph/replay/program_workload.hpp"

namespace tgraph::measure::detail {
namespace {

/// Loop iteration counts for the partitioner: the last step's, by loop index when the
/// structure is the same, else their mean (a deferred recording runs no iteration).
void apply_iterations(const std::vector<std::uint32_t>& last, bool same, StepGraph& g) {
  if (last.empty()) return;
  std::uint64_t sum = 0;
  for (std::uint32_t i : last) sum += i;
  const auto mean = static_cast<std::uint32_t>(std::max<std::uint64_t>(1, sum / last.size()));
  for (LoopId l = 0; l < g.loops.size(); ++l)
    g.loops[l].iterations = same && l < last.size() ? std::max(1u, last[l]) : mean;
}

}  // namespace

PassResult run_pass(const EngineFactory& make_engine, const partition::StepPartitioner* partitioner,
                    replay::Executor& ex, const LiveOptions& o, const PassOptions& po) {
  const bool feed_costs = po.feed_costs;
  const std::vector<Assignment>* fixed = po.fixed;
  PassResult r;
  std::unique_ptr<LiveEngine> engine = make_engine();
  replay::ProgramWorkload w;
  CostObserver costs;
  if (feed_costs) ex.add_observer(costs);
  const bool partition = ex.policy() == replay::Policy::kPartition;
  LiveStep cur;  // the program in use
  // The graph of the previous recorded program: never changed once replaced, so background
  // jobs share it.
  std::shared_ptr<const StepGraph> prev_graph;
  Assignment assignment;  // the assignment in use
  std::vector<std::uint32_t> last_iterations;
  std::unique_ptr<BackgroundPartitioner> bg;
  if (partition && fixed == nullptr)
    bg = std::make_unique<BackgroundPartitioner>(*partitioner, o.background_partition);
  RepartitionTrigger trigger({.tolerance = o.rebalance_tolerance,
                              .loop_share = o.loop_share,
                              .horizon = o.repartition_horizon});
  std::int64_t last_build_ns = 0;  // the plan build of the last new assignment
  bool informed = false;           // an assignment from measured costs was asked for
  bool have_prev = false;
  auto copy_of = [](const StepGraph& g) { return std::make_shared<const StepGraph>(g); };
  try {
    for (std::uint32_t s = 0; s < o.steps; ++s) {
      LiveStepMeasure m;
      const std::int64_t t0 = replay::now_ns();
      LiveStep next = engine->record_step(o.reuse_structure);
      const bool reused = next.reuse_previous && s > 0;
      if (!reused) {
        if (next.reuse_previous)
          throw UsageError("live run: the engine reused a program at step 0");
        if (partition && s > 0) prev_graph = std::make_shared<const StepGraph>(std::move(cur.graph));
        cur = std::move(next);
        if (po.keep_state)  // the check's pass: the bound of its reduction order
          r.longest_reduction = std::max(r.longest_reduction, longest_reduction(cur.graph));
      }
      m.recorded = !reused;
      if (!reused) m.graph_update_ns = cur.graph_update_ns;
      const std::int64_t t1 = replay::now_ns();
      if (partition) {
        // A changed structure: its tasks matched in the previous one by stable key, once for
        // the costs and the carried-over assignment.
        std::vector<TaskId> match;
        if (have_prev && !reused) match = partition::match_by_key(cur.graph, *prev_graph);
        if (feed_costs) {
          if (have_prev) {
            costs.apply(reused ? cur.graph : *prev_graph, cur.graph, reused ? nullptr : &match);
          } else {
            for (Task& t : cur.graph.tasks) t.cost_ns = 1;
          }
        }
        apply_iterations(last_iterations, reused, cur.graph);
        const std::uint32_t k = ex.threads();
        // An assignment made for `g` (maybe of an earlier structure), for the current step.
        auto adopt = [&](Assignment a, const StepGraph& g) {
          if (&g != &cur.graph && !cur.graph.same_structure(g))
            a = partition::carry_over(cur.graph, k, &g, &a);
          if (a.proc != assignment.proc || a.order != assignment.order) m.reassigned = true;
          assignment = std::move(a);
          trigger.reset();
        };
        if (fixed != nullptr) {
          if (s >= fixed->size())
            throw UsageError("live check: no assignment for step " + std::to_string(s));
          assignment = (*fixed)[s];
        } else {
          // The assignment in use was made for the previous structure: carried over at once
          // (the strategy's own, given the previous step, follows from the background).
          const bool changed = have_prev && !reused;
          std::shared_ptr<const Assignment> before;
          if (changed) {
            before = std::make_shared<const Assignment>(assignment);
            adopt(partition::carry_over(cur.graph, k, prev_graph.get(), before.get(), &match),
                  cur.graph);
          }
          if (auto done = bg->take()) {
            m.background_partition_ns += done->partition_ns;
            adopt(std::move(done->assignment), *done->graph);
          }
          if (!have_prev && feed_costs) {
            // Nothing measured yet (every cost 1): the owner rule at once; the strategy
            // follows from the first measured costs.
            adopt(partition::carry_over(cur.graph, k, nullptr, nullptr), cur.graph);
            m.partitioned = true;
          } else if (!informed || changed || o.repartition_every_step ||
                     (!bg->busy() && !m.reassigned &&
                      trigger.observe(cur.graph, assignment, last_build_ns))) {
            // The first assignment from measured costs starts afresh; later ones are given
            // the previous step and its assignment (what sticky needs).
            BackgroundPartitioner::Job job{copy_of(cur.graph), nullptr, nullptr, k};
            if (changed && informed) {
              job.prev_graph = prev_graph;
              job.prev = before;
            } else if (informed) {
              job.prev_graph = job.graph;
              job.prev = std::make_shared<const Assignment>(assignment);
            }
            bg->submit(std::move(job));
            informed = true;
            m.partitioned = true;
            if (!o.background_partition || assignment.proc.size() != cur.graph.tasks.size()) {
              // In the foreground (or nothing to run yet): the step waits for it.
              bg->drain();
              if (auto done = bg->take()) {
                m.background_partition_ns += done->partition_ns;
                adopt(std::move(done->assignment), *done->graph);
              }
            }
          }
        }
        have_prev = true;
      }
      const std::int64_t t2 = replay::now_ns();
      w.set_program(cur.bodies, cur.conditions, cur.accumulators);
      const replay::ExecStepStats ss = ex.run_step(cur.graph, partition ? &assignment : nullptr, w);
      const std::int64_t t3 = replay::now_ns();
      m.record_ns = t1 - t0;
      m.partition_ns = t2 - t1;
      m.prepare_ns = ss.prepare_ns;
      m.build_ns = ss.build_ns;
      m.rebuild_ns = ss.rebuild_ns;
      m.rebuilt_procs = ss.rebuilt_procs;
      m.execute_ns = ss.wall_ns - ss.prepare_ns;
      m.wall_ns = t3 - t0;
      m.rebuilt = ss.rebuilt;
      if (ss.rebuilt) last_build_ns = ss.build_ns;
      m.loop_iterations = ss.loop_iterations;
      last_iterations = ss.loop_iterations;
      if (po.stats != nullptr) m.threads = po.stats->threads();
      r.signals += ss.signals();
      r.waits += ss.waits();
      r.blocked_waits += ss.blocked_waits();
      r.parks += ss.parks();
      r.wall_ns += m.wall_ns;
      r.steps.push_back(std::move(m));
      if (po.keep_assignments) r.assignments.push_back(assignment);
    }
    if (bg && !r.steps.empty()) {
      // The partitioner's time of a job still running when the steps ended.
      bg->drain();
      if (auto done = bg->take()) r.steps.back().background_partition_ns += done->partition_ns;
    }
  } catch (...) {
    ex.clear_observers();
    throw;
  }
  if (feed_costs) ex.clear_observers();
  if (po.keep_state) r.state = snapshot(engine->state());
  return r;
}

}  // namespace tgraph::measure::detail
