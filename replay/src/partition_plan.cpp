// SPDX-License-Identifier: MIT
// The partition executor's plan built from scratch (partition_plan.hpp).
#include "partition_plan.hpp"

#include <algorithm>
#include <functional>
#include <queue>

namespace tgraph::replay::detail {

bool same_programs(const PartitionPlan& a, const PartitionPlan& b) {
  return a.program_order == b.program_order && a.procs == b.procs;
}

namespace {

/// `order` made consistent with the dependencies among its own tasks (a stable topological
/// sort: lowering can add edges between tasks of one processor, e.g. serialised CW writers,
/// that an order computed on the original graph did not have to respect).
std::vector<TaskId> local_topological(const ExecGraph& x, const std::vector<TaskId>& order) {
  const StepGraph& g = x.graph;
  std::vector<std::uint32_t> pos(g.tasks.size(), UINT32_MAX);
  for (std::uint32_t i = 0; i < order.size(); ++i) pos[order[i]] = i;
  std::vector<std::uint32_t> indeg(order.size(), 0);
  std::vector<std::vector<std::uint32_t>> succ(order.size());
  for (const Edge& e : g.edges)
    if (pos[e.from] != UINT32_MAX && pos[e.to] != UINT32_MAX) {
      succ[pos[e.from]].push_back(pos[e.to]);
      ++indeg[pos[e.to]];
    }
  std::priority_queue<std::uint32_t, std::vector<std::uint32_t>, std::greater<>> ready;
  for (std::uint32_t i = 0; i < order.size(); ++i)
    if (indeg[i] == 0) ready.push(i);
  std::vector<TaskId> out;
  out.reserve(order.size());
  while (!ready.empty()) {
    const std::uint32_t i = ready.top();
    ready.pop();
    out.push_back(order[i]);
    for (std::uint32_t j : succ[i])
      if (--indeg[j] == 0) ready.push(j);
  }
  return out.size() == order.size() ? out : order;
}

}  // namespace

/// Step 1: each loop's body tasks are gathered in one block of a processor's ops.
void build_ops(const ExecGraph& x, std::uint32_t k, bool use_order, bool elide,
               PartitionPlan& plan) {
  const StepGraph& g = x.graph;
  const auto n = static_cast<TaskId>(g.tasks.size());
  const Assignment& a = x.assignment;
  plan.program_order = !use_order || a.order.empty();
  plan.tasks = n;
  plan.loops = g.loops.size();
  plan.elide = elide;
  plan.procs.assign(k, {});
  plan.pos.assign(n, 0);
  plan.keys.resize(n);
  plan.task_loop.resize(n);
  for (TaskId t = 0; t < n; ++t) {
    plan.keys[t] = g.tasks[t].key;
    plan.task_loop[t] = g.tasks[t].loop;
  }
  plan.proc = a.proc;
  plan.breaks.resize(g.loops.size());
  for (LoopId l = 0; l < g.loops.size(); ++l) plan.breaks[l] = g.loops[l].last - 1;
  std::vector<std::vector<TaskId>> seqs(k);
  if (use_order && !a.order.empty()) {
    for (ProcId p = 0; p < k; ++p) seqs[p] = local_topological(x, a.order[p]);
  } else {
    for (TaskId t = 0; t < n; ++t) seqs[a.proc[t]].push_back(t);
  }
  std::vector<std::vector<TaskId>> in_loop(g.loops.size());
  std::vector<bool> opened(g.loops.size(), false);
  for (ProcId p = 0; p < k; ++p) {
    const std::vector<TaskId>& seq = seqs[p];
    for (auto& v : in_loop) v.clear();
    for (TaskId t : seq)
      if (g.tasks[t].loop != kNoLoop) in_loop[g.tasks[t].loop].push_back(t);
    std::fill(opened.begin(), opened.end(), false);
    auto& ops = plan.procs[p].ops;
    for (TaskId t : seq) {
      const LoopId l = g.tasks[t].loop;
      if (l == kNoLoop) {
        plan.pos[t] = static_cast<std::int64_t>(ops.size());
        ops.push_back(
            {OpKind::kTask, false, false, CombineRole::kNone, t, kNoLoop, 0, 0, 0, x.origin[t]});
        continue;
      }
      if (opened[l]) continue;
      opened[l] = true;
      ops.push_back({OpKind::kLoopBegin, false, false, CombineRole::kNone, 0, l, 0, 0, 0, kNoTask});
      const auto body = static_cast<std::uint32_t>(ops.size());
      for (TaskId u : in_loop[l]) {
        plan.pos[u] = static_cast<std::int64_t>(ops.size());
        ops.push_back({OpKind::kTask, false, u + 1 == g.loops[l].last, CombineRole::kNone, u, l, 0,
                       0, 0, x.origin[u]});
      }
      ops.push_back(
          {OpKind::kLoopEnd, false, false, CombineRole::kNone, 0, l, 0, 0, body, kNoTask});
    }
  }
}

/// Step 2 for processor p: its wait points, reduced along its program. Processor
/// q runs its ops in order, so a wait on the task at position i of q implies every wait on
/// q's earlier positions in the same context: outside loops (kOnce, kAfterLoop: q finished
/// what comes before), in the same iteration of a loop (kSameIter), and in the previous
/// iteration (kPrevIter, also implied by any kSameIter wait on q: q finished iteration
/// i - 1 before starting i). Per op the candidates are taken per producing processor,
/// latest first, and across ops the latest position waited for on each processor is
/// remembered (reset at each loop begin for the loop contexts), so that a reducer waits for
/// the last of another processor's CW writers, not for each of them, and only the tasks
/// still waited for signal. The waits of an op are listed by processor, then latest
/// position first: an order that only depends on each processor's order of its tasks (an
/// incremental rebuild relies on it).
void build_waits(const ExecGraph& x, ProcId p, PartitionPlan& plan) {
  const StepGraph& g = x.graph;
  const auto n = static_cast<TaskId>(g.tasks.size());
  const std::vector<ProcId>& proc = x.assignment.proc;
  const std::size_t k = plan.procs.size();
  const std::vector<std::int64_t>& pos = plan.pos;
  constexpr std::int64_t kNever = -1;
  struct Candidate {
    WaitPoint w;
    std::uint32_t proc = 0;
    std::int64_t at = 0;  // position of the producer in its processor's ops
  };
  std::vector<Candidate> cands;
  ProcPlan& pp = plan.procs[p];
  pp.waits.clear();
  std::vector<std::int64_t> done_outside(k, kNever), done_iter(k, kNever), done_prev(k, kNever);
  std::vector<std::uint8_t> seen_once, seen_iter, seen_prev;  // without elision only
  std::vector<TaskId> marks;
  if (!plan.elide) seen_once.assign(n, 0), seen_iter.assign(n, 0), seen_prev.assign(n, 0);
  for (Op& op : pp.ops) {
    if (op.kind == OpKind::kLoopBegin) {
      std::fill(done_iter.begin(), done_iter.end(), kNever);
      std::fill(done_prev.begin(), done_prev.end(), kNever);
      for (TaskId u : marks) seen_iter[u] = seen_prev[u] = 0;
      marks.clear();
    }
    if (op.kind != OpKind::kTask) continue;
    const TaskId v = op.task;
    cands.clear();
    for (auto i = plan.intra.begin[v]; i < plan.intra.begin[v + 1]; ++i) {
      const TaskId u = plan.intra.ids[i];
      if (proc[u] == p && pos[u] < pos[v]) continue;  // program order on p guarantees it
      const LoopId lu = g.tasks[u].loop;
      WaitPoint w{u, lu, WaitKind::kOnce};
      if (lu == kNoLoop) {
        w.kind = WaitKind::kOnce;
      } else if (lu == g.tasks[v].loop) {
        w.kind = WaitKind::kSameIter;
      } else {
        w.kind = WaitKind::kAfterLoop;
      }
      cands.push_back({w, proc[u], pos[u]});
    }
    for (auto i = plan.carried.begin[v]; i < plan.carried.begin[v + 1]; ++i) {
      const TaskId u = plan.carried.ids[i];
      if (proc[u] == p) continue;  // p finishes iteration i before starting i + 1
      cands.push_back({{u, g.tasks[u].loop, WaitKind::kPrevIter}, proc[u], pos[u]});
    }
    // Per processor: kSameIter first (they imply kPrevIter), then the latest position first.
    std::sort(cands.begin(), cands.end(), [](const Candidate& c, const Candidate& d) {
      if (c.proc != d.proc) return c.proc < d.proc;
      const bool cs = c.w.kind == WaitKind::kSameIter, ds = d.w.kind == WaitKind::kSameIter;
      if (cs != ds) return cs;
      if (c.at != d.at) return c.at > d.at;
      return c.w.kind < d.w.kind;
    });
    op.wait_begin = static_cast<std::uint32_t>(pp.waits.size());
    for (const Candidate& c : cands) {
      std::int64_t* done = nullptr;
      bool implied = false;
      switch (c.w.kind) {
        case WaitKind::kOnce:
        case WaitKind::kAfterLoop:
          done = &done_outside[c.proc];
          implied = c.at <= *done;
          break;
        case WaitKind::kSameIter:
          done = &done_iter[c.proc];
          implied = c.at <= *done;
          break;
        case WaitKind::kPrevIter:
          done = &done_prev[c.proc];
          implied = c.at <= *done || done_iter[c.proc] != kNever;
          break;
      }
      if (!plan.elide) {
        // Only one wait per producer and context along the program (the dedupe every plan
        // needs), as before the reduction.
        std::vector<std::uint8_t>& seen = c.w.kind == WaitKind::kSameIter   ? seen_iter
                                          : c.w.kind == WaitKind::kPrevIter ? seen_prev
                                                                            : seen_once;
        implied = seen[c.w.producer] != 0;
        if (!implied && c.w.kind != WaitKind::kOnce && c.w.kind != WaitKind::kAfterLoop)
          marks.push_back(c.w.producer);
        seen[c.w.producer] = 1;
      }
      if (implied) continue;
      *done = c.at;
      pp.waits.push_back(c.w);
    }
    op.wait_end = static_cast<std::uint32_t>(pp.waits.size());
  }
}

/// Step 3: signal flags (the tasks some processor waits for) and first-touch owners.
void finish_plan(const ExecGraph& x, PartitionPlan& plan) {
  std::vector<bool> signal(plan.tasks, false);
  for (const ProcPlan& pp : plan.procs)
    for (const WaitPoint& w : pp.waits) signal[w.producer] = true;
  for (ProcPlan& pp : plan.procs)
    for (Op& op : pp.ops)
      if (op.kind == OpKind::kTask) op.signal = signal[op.task];
  for (ProcPlan& pp : plan.procs) {
    std::uint32_t run = 0;
    for (auto op = pp.ops.rbegin(); op != pp.ops.rend(); ++op) {
      const bool plain = op->kind == OpKind::kTask && op->wait_begin == op->wait_end &&
                         !op->signal && !op->is_break;
      run = plain ? run + 1 : 0;
      op->plain_run = run;
    }
  }
  const auto owner = first_accessor_owner(x);
  const std::size_t k = plan.procs.size();
  for (ProcPlan& pp : plan.procs) pp.owned.clear();
  for (DatumId d = 0; d < owner.size(); ++d) plan.procs[owner[d] % k].owned.push_back(d);
}

/// Builds the per-processor programs from scratch.
PartitionPlan build_plan(const ExecGraph& x, std::uint32_t k, bool use_order, bool elide) {
  PartitionPlan plan;
  build_ops(x, k, use_order, elide, plan);
  const auto n = plan.tasks;
  plan.intra = build_csr(n, x.graph.edges, true);
  plan.carried = build_csr(n, x.graph.carried_edges, true);
  for (ProcId p = 0; p < k; ++p) build_waits(x, p, plan);
  plan.rebuilt_procs = k;
  finish_plan(x, plan);
  return plan;
}

namespace {

/// Whether processor q, between its offer at ops[at] in two iterations of loop l, waits for
/// something that home runs at or after ops[head] (a task there, or the loop's decision when
/// the break task is there): then every arrival of one iteration precedes those of the next.
bool orders_iterations(const ExecGraph& x, const PartitionPlan& plan, ProcId q, std::uint32_t at,
                       ProcId home, std::uint32_t head, LoopId l) {
  const auto after_head = [&](TaskId t) {
    return plan.proc[t] == home && plan.pos[t] >= head && x.graph.tasks[t].loop == l;
  };
  if (after_head(plan.breaks[l])) return true;  // q reads the decision at its loop's end
  const ProcPlan& pp = plan.procs[q];
  std::uint32_t begin = at;
  while (begin > 0 && !(pp.ops[begin].kind == OpKind::kLoopBegin && pp.ops[begin].loop == l))
    --begin;
  for (std::uint32_t i = begin + 1; i < pp.ops.size(); ++i) {
    const Op& op = pp.ops[i];
    if (op.kind == OpKind::kLoopEnd && op.loop == l) break;
    if (op.kind != OpKind::kTask) continue;
    for (auto w = op.wait_begin; w < op.wait_end; ++w) {
      const WaitPoint& wp = pp.waits[w];
      if (!after_head(wp.producer)) continue;
      if ((wp.kind == WaitKind::kSameIter && i > at) || (wp.kind == WaitKind::kPrevIter && i <= at))
        return true;
    }
  }
  return false;
}

}  // namespace

void add_combines(const ExecGraph& x, PartitionPlan& plan) {
  plan.combines.clear();
  const std::size_t k = plan.procs.size();
  if (!plan.elide || k < 2) return;
  const StepGraph& g = x.graph;
  std::vector<bool> taken(plan.tasks, false);  // a head, an offer, or in a combine's tasks
  const auto op_of = [&plan](TaskId t) -> Op& {
    return plan.procs[plan.proc[t]].ops[static_cast<std::size_t>(plan.pos[t])];
  };
  std::vector<ProcId> parties;
  for (ProcId p = 0; p < k; ++p) {
    std::vector<Op>& ops = plan.procs[p].ops;
    const std::vector<WaitPoint>& waits = plan.procs[p].waits;
    for (std::uint32_t h = 0; h < ops.size(); ++h) {
      const Op& head = ops[h];
      if (head.kind != OpKind::kTask || x.reduction[head.task] == kNoReduction ||
          head.wait_begin == head.wait_end || head.is_break || taken[head.task])
        continue;
      const LoopId l = head.loop;
      const WaitKind same = l == kNoLoop ? WaitKind::kOnce : WaitKind::kSameIter;
      parties.clear();
      bool ok = true;
      for (auto i = head.wait_begin; ok && i < head.wait_end; ++i) {
        const WaitPoint& wp = waits[i];
        const ProcId q = plan.proc[wp.producer];
        ok = wp.kind == same && g.tasks[wp.producer].loop == l && q != p &&
             std::find(parties.begin(), parties.end(), q) == parties.end() && !taken[wp.producer] &&
             !op_of(wp.producer).is_break &&
             (l == kNoLoop ||
              orders_iterations(x, plan, q, static_cast<std::uint32_t>(plan.pos[wp.producer]), p, h,
                                l));
        parties.push_back(q);
      }
      if (!ok) continue;
      // The tasks after the head that wait for nothing and that another processor waits for.
      std::uint32_t end = h + 1;
      while (end < ops.size() && ops[end].kind == OpKind::kTask &&
             ops[end].wait_begin == ops[end].wait_end && ops[end].signal && !ops[end].is_break &&
             !taken[ops[end].task])
        ++end;
      const auto s = static_cast<std::uint32_t>(plan.combines.size());
      plan.combines.push_back({p, h, end, static_cast<std::uint32_t>(parties.size() + 1)});
      for (std::uint32_t i = h; i < end; ++i) taken[ops[i].task] = true;
      ops[h].combine = CombineRole::kHead;
      ops[h].jump = s;
      for (auto i = head.wait_begin; i < head.wait_end; ++i) {
        Op& offer = op_of(waits[i].producer);
        offer.combine = CombineRole::kOffer;
        offer.jump = s;
        taken[offer.task] = true;
      }
    }
  }
}

void add_steal(const ExecGraph& x, PartitionPlan& plan) {
  const StepGraph& g = x.graph;
  const std::size_t n = plan.tasks;
  plan.stealable.assign(n, 0);
  plan.steal_begin.assign(n + 1, 0);
  plan.steal_waits.clear();
  if (plan.procs.size() < 2) return;
  std::vector<bool> excluded(n, false);
  for (const Combine& c : plan.combines)
    for (std::uint32_t i = c.head; i < c.end; ++i)
      excluded[plan.procs[c.home].ops[i].task] = true;
  // The previous CW writer of each datum along each processor's program (one region: reset
  // at every loop begin and end; lowering serialises CW groups that cross a loop boundary).
  std::vector<std::vector<TaskId>> chains(n);  // by task: the previous CW writer of each datum
  std::vector<TaskId> last(g.data.size(), kNoTask);
  std::vector<DatumId> touched;
  for (const ProcPlan& pp : plan.procs) {
    for (const Op& op : pp.ops) {
      if (op.kind != OpKind::kTask) {
        for (DatumId d : touched) last[d] = kNoTask;
        touched.clear();
        continue;
      }
      if (op.combine != CombineRole::kNone || op.is_break) excluded[op.task] = true;
      for (const Access& acc : g.accesses_of(op.task)) {
        if (acc.mode != AccessMode::CW) continue;
        const TaskId prev = last[acc.datum];
        if (prev != kNoTask && prev != op.task &&
            std::find(chains[op.task].begin(), chains[op.task].end(), prev) ==
                chains[op.task].end())
          chains[op.task].push_back(prev);
        if (prev == kNoTask) touched.push_back(acc.datum);
        last[acc.datum] = op.task;
      }
    }
    for (DatumId d : touched) last[d] = kNoTask;
    touched.clear();
  }
  for (TaskId v = 0; v < n; ++v) {
    plan.steal_begin[v] = static_cast<std::uint32_t>(plan.steal_waits.size());
    if (excluded[v]) continue;
    plan.stealable[v] = 1;
    const LoopId lv = g.tasks[v].loop;
    const auto intra = [&](TaskId u) {
      const LoopId lu = g.tasks[u].loop;
      const WaitKind kind = lu == kNoLoop  ? WaitKind::kOnce
                            : lu == lv     ? WaitKind::kSameIter
                                           : WaitKind::kAfterLoop;
      plan.steal_waits.push_back({u, lu, kind});
    };
    for (auto i = plan.intra.begin[v]; i < plan.intra.begin[v + 1]; ++i) intra(plan.intra.ids[i]);
    for (TaskId u : chains[v]) intra(u);
    for (auto i = plan.carried.begin[v]; i < plan.carried.begin[v + 1]; ++i) {
      const TaskId u = plan.carried.ids[i];
      plan.steal_waits.push_back({u, g.tasks[u].loop, WaitKind::kPrevIter});
    }
  }
  plan.steal_begin[n] = static_cast<std::uint32_t>(plan.steal_waits.size());
}

}  // namespace tgraph::replay::detail
