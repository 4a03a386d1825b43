// SPDX-License-Identifier: MIT
#include "live_pass.hpp"

#include <algorithm>
#include <memory>
#include <string>

#include "live_observers.hpp"
#include "tgraph/graph/error.hpp"
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
  LiveStep cur;           // the program in use
  StepGraph prev_graph;   // the graph of the previous recorded program
  Assignment assignment;  // the assignment in use
  std::vector<std::uint32_t> last_iterations;
  double made_imbalance = 1.0;  // the assignment's loop_imbalance when it was made
  bool informed = false;        // the assignment was made from measured costs
  bool have_prev = false;
  try {
    for (std::uint32_t s = 0; s < o.steps; ++s) {
      LiveStepMeasure m;
      const std::int64_t t0 = replay::now_ns();
      LiveStep next = engine->record_step(o.reuse_structure);
      const bool reused = next.reuse_previous && s > 0;
      if (!reused) {
        if (next.reuse_previous)
          throw UsageError("live run: the engine reused a program at step 0");
        if (partition && s > 0) prev_graph = std::move(cur.graph);
        cur = std::move(next);
      }
      m.recorded = !reused;
      if (!reused) m.graph_update_ns = cur.graph_update_ns;
      const std::int64_t t1 = replay::now_ns();
      if (partition) {
        const StepGraph& measured = reused ? cur.graph : prev_graph;
        if (feed_costs) {
          if (have_prev) {
            costs.apply(measured, cur.graph);
          } else {
            for (Task& t : cur.graph.tasks) t.cost_ns = 1;
          }
        }
        apply_iterations(last_iterations, reused, cur.graph);
        if (fixed != nullptr) {
          if (s >= fixed->size())
            throw UsageError("live check: no assignment for step " + std::to_string(s));
          assignment = (*fixed)[s];
        } else if (!informed || !reused || o.repartition_every_step ||
                   partition::loop_imbalance(cur.graph, assignment, o.loop_share) >
                       (1.0 + o.rebalance_tolerance) * std::max(1.0, made_imbalance)) {
          // The first assignment is made before any cost is measured (every task 1 ns): the
          // next starts afresh, not from it (sticky would keep it while its imbalance under
          // the measured costs, falling64's 1.13, is within its threshold).
          const bool from_prev = have_prev && informed;
          assignment = (*partitioner)(cur.graph, ex.threads(), from_prev ? &measured : nullptr,
                                      from_prev ? &assignment : nullptr);
          informed = have_prev || !feed_costs;
          made_imbalance = partition::loop_imbalance(cur.graph, assignment, o.loop_share);
          m.partitioned = true;
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
  } catch (...) {
    ex.clear_observers();
    throw;
  }
  if (feed_costs) ex.clear_observers();
  if (po.keep_state) r.state = snapshot(engine->state());
  return r;
}

}  // namespace tgraph::measure::detail
