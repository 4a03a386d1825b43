// SPDX-License-Identifier: MIT
// The partition executor's serial twin (partition_serial.hpp): the per-processor programs
// interleaved on one thread, and the deadlock check of an explicit task order.
#include "partition_serial.hpp"

#include <string>

#include "tgraph/graph/error.hpp"

namespace tgraph::replay::detail {
namespace {

/// How the deadlock message names exec task `t`: its original task id, or for a reducer
/// added by lowering (no original task), the datum it reduces.
std::string task_label(const ExecGraph& x, TaskId t) {
  if (x.origin[t] != kNoTask) return "task " + std::to_string(x.origin[t]);
  if (t < x.reduction.size() && x.reduction[t] != kNoReduction) {
    const DatumId d = x.reductions[x.reduction[t]].target;
    return "the reducer of datum " + std::to_string(d) + " '" + x.graph.data[d].name + "'";
  }
  return "exec task " + std::to_string(t);
}

/// The waits of a plan with explicit orders between whole loops: each loop contracted to one
/// node (a processor enters its block only after what precedes the block in its order, and
/// what follows the block waits for the loop's exit, which needs every iteration of every
/// block), plus the graph's edges between different nodes. A cycle can deadlock after any
/// number of iterations (a task behind one processor's block that another processor's
/// block waits for), which two simulated iterations need not show; "" when acyclic, else
/// the loop or task where the cycle was found.
std::string loop_wait_cycle(const PartitionPlan& plan, const ExecGraph& x) {
  const StepGraph& g = x.graph;
  if (g.loops.empty()) return "";
  const auto n = static_cast<TaskId>(g.tasks.size());
  auto node = [&](TaskId t) { return g.tasks[t].loop == kNoLoop ? t : n + g.tasks[t].loop; };
  const std::size_t nodes = n + g.loops.size();
  std::vector<std::vector<std::uint32_t>> succ(nodes);
  std::vector<std::uint32_t> indeg(nodes, 0);
  auto link = [&](std::uint32_t a, std::uint32_t b) {
    if (a == b) return;
    succ[a].push_back(b);
    ++indeg[b];
  };
  for (const Edge& e : g.edges) link(node(e.from), node(e.to));
  for (const ProcPlan& pp : plan.procs) {
    std::uint32_t prev = UINT32_MAX;
    for (const Op& op : pp.ops) {
      std::uint32_t v;
      if (op.kind == OpKind::kLoopBegin) {
        v = n + op.loop;
      } else if (op.kind == OpKind::kTask && op.loop == kNoLoop) {
        v = op.task;
      } else {
        continue;
      }
      if (prev != UINT32_MAX) link(prev, v);
      prev = v;
    }
  }
  std::vector<std::uint32_t> ready;
  for (std::uint32_t v = 0; v < nodes; ++v)
    if (indeg[v] == 0) ready.push_back(v);
  std::size_t seen = 0;
  while (!ready.empty()) {
    const std::uint32_t v = ready.back();
    ready.pop_back();
    ++seen;
    for (std::uint32_t s : succ[v])
      if (--indeg[s] == 0) ready.push_back(s);
  }
  if (seen == nodes) return "";
  for (std::uint32_t v = n; v < nodes; ++v)
    if (indeg[v] != 0)
      return "the processors' orders wait in a cycle through loop " + std::to_string(v - n) +
             " (a task that one processor runs after its block of the loop is needed inside "
             "the loop)";
  for (std::uint32_t v = 0; v < n; ++v)
    if (indeg[v] != 0)
      return "the processors' orders wait in a cycle through " + task_label(x, v);
  return "";
}

}  // namespace

void run_interleaved(const PartitionPlan& plan, const ExecGraph& x, Workload* w,
                     const std::vector<Observer*>* observers, ExecStepStats* stats) {
  const std::size_t k = plan.procs.size();
  const StepGraph& g = x.graph;
  std::vector<std::uint32_t> done(plan.tasks, 0);
  std::vector<std::uint32_t> loop_iters(plan.loops, 0);  // iterations decided so far
  std::vector<bool> loop_stop(plan.loops, false);
  struct Cursor {
    std::size_t pc = 0;
    std::uint32_t iter = 0;
  };
  std::vector<Cursor> cur(k);
  if (stats) {
    stats->threads.assign(k, {});
    stats->loop_iterations.assign(plan.loops, 0);
  }
  auto ready = [&](const WaitPoint& wp, std::uint32_t iter) {
    if (wp.kind == WaitKind::kAfterLoop && !loop_stop[wp.loop]) return false;
    const std::uint32_t loop_ran = wp.kind == WaitKind::kAfterLoop ? loop_iters[wp.loop] : 0;
    return done[wp.producer] >= needed_executions(wp, iter, loop_ran);
  };
  for (;;) {
    bool all_done = true, progress = false;
    for (std::size_t p = 0; p < k; ++p) {
      const ProcPlan& pp = plan.procs[p];
      Cursor& c = cur[p];
      while (c.pc < pp.ops.size()) {
        const Op& op = pp.ops[c.pc];
        if (op.kind == OpKind::kLoopBegin) {
          c.iter = 0;
          ++c.pc;
        } else if (op.kind == OpKind::kLoopEnd) {
          if (loop_iters[op.loop] < c.iter + 1) break;  // decision not known yet
          if (loop_iters[op.loop] > c.iter + 1 || !loop_stop[op.loop]) {
            ++c.iter;
            c.pc = op.jump;
          } else {
            c.iter = 0;
            ++c.pc;
          }
        } else {
          bool ok = true;
          for (auto i = op.wait_begin; i < op.wait_end && ok; ++i) ok = ready(pp.waits[i], c.iter);
          if (!ok) break;
          const auto thread = static_cast<std::uint32_t>(p);
          if (w) {
            if (observers && !observers->empty())
              notify_begin(*observers, thread, op.task, c.iter);
            w->run(TaskRun{&x, op.task, x.origin[op.task], c.iter, thread});
            if (observers && !observers->empty())
              notify_end(*observers, thread, op.task, c.iter);
          }
          if (stats) {
            auto& tc = stats->threads[p];
            ++tc.tasks;
            tc.waits += op.wait_end - op.wait_begin;
            if (op.signal) ++tc.signals;
          }
          done[op.task] = c.iter + 1;
          if (op.is_break) {
            const bool stop = w ? leave_loop(x, op.loop, c.iter, *w) : c.iter + 1 >= 2;
            loop_iters[op.loop] = c.iter + 1;
            loop_stop[op.loop] = stop;
            if (stats) stats->loop_iterations[op.loop] = c.iter + 1;
          }
          ++c.pc;
        }
        progress = true;
      }
      if (c.pc < pp.ops.size()) all_done = false;
    }
    if (all_done) return;
    if (!progress) {
      // Every processor that has not finished, and what it is stuck at.
      std::string stuck;
      for (std::size_t p = 0; p < k; ++p)
        if (cur[p].pc < plan.procs[p].ops.size()) {
          const Op& op = plan.procs[p].ops[cur[p].pc];
          stuck += (stuck.empty() ? "processor " : "; processor ") + std::to_string(p) +
                   " cannot run " +
                   (op.kind == OpKind::kTask
                        ? task_label(x, op.task) + " (" + g.kind_name(op.task) + ")"
                        : std::string("its loop control")) +
                   " in iteration " + std::to_string(cur[p].iter);
        }
      throw UsageError("the assignment's task order deadlocks: " + stuck);
    }
  }
}

void check_deadlock_free(const PartitionPlan& plan, const ExecGraph& x) {
  if (const std::string cycle = loop_wait_cycle(plan, x); !cycle.empty())
    throw UsageError("the assignment's task order deadlocks: " + cycle);
  run_interleaved(plan, x, nullptr, nullptr, nullptr);  // throws if the order deadlocks
}

}  // namespace tgraph::replay::detail
