// SPDX-License-Identifier: MIT
// The partition executor's incremental plan update (partition_plan.hpp): on a structure or
// assignment change, the processors whose programs and dependencies did not change keep
// their wait points; the result equals a build from scratch.
#include "partition_plan.hpp"

namespace tgraph::replay::detail {

/// Builds the per-processor programs from those of `prev` (the plan of an earlier exec
/// graph): every processor gets its ops afresh (cheap), but keeps its previous wait points,
/// task ids renumbered, when nothing they depend on changed: its ops are the previous ones
/// (tasks matched by stable key), each of its tasks has the same predecessors (matched),
/// each predecessor is on the same processor, in the same loop, and every other processor
/// it waits on kept the order of its matched tasks. Otherwise (and for the processors whose
/// task list changed) the wait points are computed again. Equals build_plan().
PartitionPlan update_plan(const ExecGraph& x, const PartitionPlan& prev, std::uint32_t k,
                          bool use_order, bool elide) {
  if (prev.procs.size() != k || prev.elide != elide) return build_plan(x, k, use_order, elide);
  const StepGraph& g = x.graph;
  PartitionPlan plan;
  build_ops(x, k, use_order, elide, plan);
  const auto n = static_cast<TaskId>(plan.tasks);
  plan.intra = build_csr(n, g.edges, true);
  plan.carried = build_csr(n, g.carried_edges, true);
  auto from_scratch = [&] {
    for (ProcId p = 0; p < k; ++p) build_waits(x, p, plan);
    plan.rebuilt_procs = k;
    finish_plan(x, plan);
    return std::move(plan);
  };
  if (plan.program_order != prev.program_order) return from_scratch();

  // Tasks and loops matched by stable key (both ways; keys must be unique). The keys are
  // hashes: an open-addressing table with linear probing.
  std::size_t size = 16;
  while (size < 2 * prev.keys.size()) size *= 2;
  const std::size_t mask = size - 1;
  std::vector<TaskId> slot(size, kNoTask);
  auto home = [mask](StableKey key) { return static_cast<std::size_t>(key ^ (key >> 29)) & mask; };
  for (TaskId t = 0; t < prev.keys.size(); ++t) {
    std::size_t i = home(prev.keys[t]);
    for (; slot[i] != kNoTask; i = (i + 1) & mask)
      if (prev.keys[slot[i]] == prev.keys[t]) return from_scratch();
    slot[i] = t;
  }
  std::vector<TaskId> old_of(n, kNoTask), new_of(prev.keys.size(), kNoTask);
  for (TaskId t = 0; t < n; ++t)
    for (std::size_t i = home(plan.keys[t]); slot[i] != kNoTask; i = (i + 1) & mask)
      if (prev.keys[slot[i]] == plan.keys[t]) {
        if (new_of[slot[i]] != kNoTask) return from_scratch();
        old_of[t] = slot[i];
        new_of[slot[i]] = t;
        break;
      }
  constexpr LoopId kUnmatched = kNoLoop - 1;
  std::vector<LoopId> old_loop(g.loops.size(), kUnmatched),
      new_loop(prev.breaks.size(), kUnmatched);
  for (LoopId l = 0; l < g.loops.size(); ++l) {
    const TaskId ob = old_of[plan.breaks[l]];
    if (ob == kNoTask) continue;
    const LoopId ol = prev.task_loop[ob];
    if (ol == kNoLoop || prev.breaks[ol] != ob) continue;
    old_loop[l] = ol;
    new_loop[ol] = l;
  }
  auto same_loop = [&](LoopId l, LoopId ol) {
    return l == kNoLoop ? ol == kNoLoop : old_loop[l] == ol;
  };

  // Processors whose ops are the previous ones, and those that kept their tasks' order.
  std::vector<bool> same_ops(k, false), same_order(k, true);
  for (ProcId p = 0; p < k; ++p) {
    const auto& ops = plan.procs[p].ops;
    const auto& old = prev.procs[p].ops;
    bool same = ops.size() == old.size();
    for (std::size_t i = 0; same && i < ops.size(); ++i) {
      const Op& o = ops[i];
      const Op& q = old[i];
      // (a task op's jump is its combine, which add_combines() sets after this build)
      same = o.kind == q.kind && o.is_break == q.is_break &&
             (o.kind != OpKind::kLoopEnd || o.jump == q.jump) && same_loop(o.loop, q.loop) &&
             (o.kind != OpKind::kTask || old_of[o.task] == q.task);
    }
    same_ops[p] = same;
    std::int64_t last = -1;
    for (const Op& o : ops) {
      if (o.kind != OpKind::kTask || old_of[o.task] == kNoTask) continue;
      const TaskId ot = old_of[o.task];
      if (prev.proc[ot] != p) continue;
      if (prev.pos[ot] <= last) {
        same_order[p] = false;
        break;
      }
      last = prev.pos[ot];
    }
  }

  std::vector<std::uint32_t> mark(n, 0);
  std::uint32_t stamp = 0;
  // Predecessor lists of v and of its previous task ov are the same, each predecessor where
  // it was, in the same loop, on a processor that kept its order.
  auto same_preds = [&](const Csr& now, const Csr& before, TaskId v, TaskId ov, ProcId p) {
    if (now.size(v) != before.size(ov)) return false;
    ++stamp;
    for (auto i = now.begin[v]; i < now.begin[v + 1]; ++i) {
      const TaskId u = now.ids[i];
      const TaskId ou = old_of[u];
      if (ou == kNoTask || prev.proc[ou] != plan.proc[u] ||
          !same_loop(g.tasks[u].loop, prev.task_loop[ou]))
        return false;
      if (plan.proc[u] != p && !same_order[plan.proc[u]]) return false;
      mark[u] = stamp;
    }
    for (auto i = before.begin[ov]; i < before.begin[ov + 1]; ++i) {
      const TaskId nu = new_of[before.ids[i]];
      if (nu == kNoTask || mark[nu] != stamp) return false;
    }
    return true;
  };
  for (ProcId p = 0; p < k; ++p) {
    bool reuse = same_ops[p];
    for (const Op& op : plan.procs[p].ops) {
      if (!reuse) break;
      if (op.kind != OpKind::kTask) continue;
      const TaskId ov = old_of[op.task];
      reuse = same_preds(plan.intra, prev.intra, op.task, ov, p) &&
              same_preds(plan.carried, prev.carried, op.task, ov, p);
    }
    if (!reuse) {
      build_waits(x, p, plan);
      ++plan.rebuilt_procs;
      continue;
    }
    ProcPlan& pp = plan.procs[p];
    const ProcPlan& old = prev.procs[p];
    for (std::size_t i = 0; i < pp.ops.size(); ++i) {
      pp.ops[i].wait_begin = old.ops[i].wait_begin;
      pp.ops[i].wait_end = old.ops[i].wait_end;
    }
    pp.waits.resize(old.waits.size());
    for (std::size_t i = 0; i < old.waits.size(); ++i) {
      const WaitPoint& w = old.waits[i];
      pp.waits[i] = {new_of[w.producer], w.loop == kNoLoop ? kNoLoop : new_loop[w.loop], w.kind};
    }
  }
  finish_plan(x, plan);
  return plan;
}

}  // namespace tgraph::replay::detail
