// SPDX-License-Identifier: MIT
// The partitioned executor (paper section 3.2): one pinned thread per processor runs its
// own tasks in order; a task needed by another processor publishes its completion count
// (signal) and the reader waits for it (spin, then park).
//
// Synchronisation: every task that another processor depends on owns a completion counter
// done[t] = (epoch << 32) | executions-this-step, so counters never need resetting between
// steps (the epoch grows). A datum's version is the completion count of its writer: the
// edges of the dataflow graph name, for each reader, exactly which writer (and for a CW
// group, which writers) produced the version it needs; WAR edges make a writer wait for the
// readers of the previous version the same way. Loops: every processor holding body tasks
// runs the loop control itself; the processor of the break task publishes, per iteration,
// loop[l] = (epoch << 32) | (iterations << 1) | stop, and the others read it before starting
// the next iteration. Calling thread = processor 0.
#include <algorithm>
#include <atomic>
#include <exception>
#include <memory>
#include <mutex>
#include <queue>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "common.hpp"
#include "sync.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/replay/executor.hpp"
#include "watchdog.hpp"

namespace tgraph::replay {
namespace {

using detail::PaddedCounter;

enum class WaitKind : std::uint8_t {
  kOnce,       ///< producer outside loops: its single execution
  kSameIter,   ///< producer in the same loop: the same iteration
  kPrevIter,   ///< loop-carried: the previous iteration (nothing in iteration 0)
  kAfterLoop,  ///< producer in an earlier loop: its last iteration
};

struct WaitPoint {
  TaskId producer = 0;
  LoopId loop = kNoLoop;  // kAfterLoop: the producer's loop
  WaitKind kind = WaitKind::kOnce;
  friend bool operator==(const WaitPoint&, const WaitPoint&) = default;
};

enum class OpKind : std::uint8_t { kTask, kLoopBegin, kLoopEnd };

// One op of a processor's program: 32 bytes, aligned, so that a record never straddles two
// cache lines and the hot loop indexes ops with a shift. Everything the loop needs for a
// task is here (its original id too), not in the exec graph's arrays.
struct alignas(32) Op {
  OpKind kind = OpKind::kTask;
  bool signal = false;    // publish done[task] after running
  bool is_break = false;  // evaluate and publish the loop decision after running
  TaskId task = 0;
  LoopId loop = kNoLoop;
  std::uint32_t wait_begin = 0, wait_end = 0;
  std::uint32_t jump = 0;       // kLoopEnd: first op of the body
  TaskId origin = kNoTask;      // kTask: the original task (ExecGraph::origin)
  friend bool operator==(const Op&, const Op&) = default;
};
static_assert(sizeof(Op) == 32);

struct ProcPlan {
  std::vector<Op> ops;
  std::vector<WaitPoint> waits;
  std::vector<DatumId> owned;
  friend bool operator==(const ProcPlan&, const ProcPlan&) = default;
};

struct Plan {
  std::vector<ProcPlan> procs;
  bool program_order = true;  // false: the assignment's explicit order is followed
  std::size_t tasks = 0;
  std::size_t loops = 0;
  // What the next incremental build compares with (by exec task of this plan).
  bool elide = true;
  std::vector<StableKey> keys;
  std::vector<LoopId> task_loop;
  std::vector<ProcId> proc;
  std::vector<std::int64_t> pos;    // position in its processor's ops
  std::vector<TaskId> breaks;       // by loop: its break task
  detail::Csr intra, carried;       // predecessors along intra-step and loop-carried edges
  std::uint32_t rebuilt_procs = 0;  // processors whose wait points this build computed
};

/// The programs of two plans are the same (ops, waits, owned data, order mode).
bool same_programs(const Plan& a, const Plan& b) {
  return a.program_order == b.program_order && a.procs == b.procs;
}

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

/// Step 1 of a plan: the ops of every processor (its tasks in order, each loop's body tasks
/// gathered in one block), each task's position, and what a later incremental build needs.
void build_ops(const ExecGraph& x, std::uint32_t k, bool use_order, bool elide, Plan& plan) {
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
        ops.push_back({OpKind::kTask, false, false, t, kNoLoop, 0, 0, 0, x.origin[t]});
        continue;
      }
      if (opened[l]) continue;
      opened[l] = true;
      ops.push_back({OpKind::kLoopBegin, false, false, 0, l, 0, 0, 0, kNoTask});
      const auto body = static_cast<std::uint32_t>(ops.size());
      for (TaskId u : in_loop[l]) {
        plan.pos[u] = static_cast<std::int64_t>(ops.size());
        ops.push_back({OpKind::kTask, false, u + 1 == g.loops[l].last, u, l, 0, 0, 0, x.origin[u]});
      }
      ops.push_back({OpKind::kLoopEnd, false, false, 0, l, 0, 0, body, kNoTask});
    }
  }
}

/// Step 2 of a plan for processor p: its wait points, reduced along its program. Processor
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
void build_waits(const ExecGraph& x, ProcId p, Plan& plan) {
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
void finish_plan(const ExecGraph& x, Plan& plan) {
  std::vector<bool> signal(plan.tasks, false);
  for (const ProcPlan& pp : plan.procs)
    for (const WaitPoint& w : pp.waits) signal[w.producer] = true;
  for (ProcPlan& pp : plan.procs)
    for (Op& op : pp.ops)
      if (op.kind == OpKind::kTask) op.signal = signal[op.task];
  const auto owner = detail::first_accessor_owner(x);
  const std::size_t k = plan.procs.size();
  for (ProcPlan& pp : plan.procs) pp.owned.clear();
  for (DatumId d = 0; d < owner.size(); ++d) plan.procs[owner[d] % k].owned.push_back(d);
}

/// Builds the per-processor programs from scratch.
Plan build_plan(const ExecGraph& x, std::uint32_t k, bool use_order, bool elide) {
  Plan plan;
  build_ops(x, k, use_order, elide, plan);
  const auto n = plan.tasks;
  plan.intra = detail::build_csr(n, x.graph.edges, true);
  plan.carried = detail::build_csr(n, x.graph.carried_edges, true);
  for (ProcId p = 0; p < k; ++p) build_waits(x, p, plan);
  plan.rebuilt_procs = k;
  finish_plan(x, plan);
  return plan;
}

/// Builds the per-processor programs from those of `prev` (the plan of an earlier exec
/// graph): every processor gets its ops afresh (cheap), but keeps its previous wait points,
/// task ids renumbered, when nothing they depend on changed: its ops are the previous ones
/// (tasks matched by stable key), each of its tasks has the same predecessors (matched),
/// each predecessor is on the same processor, in the same loop, and every other processor
/// it waits on kept the order of its matched tasks. Otherwise (and for the processors whose
/// task list changed) the wait points are computed again. Equals build_plan().
Plan update_plan(const ExecGraph& x, const Plan& prev, std::uint32_t k, bool use_order,
                 bool elide) {
  if (prev.procs.size() != k || prev.elide != elide) return build_plan(x, k, use_order, elide);
  const StepGraph& g = x.graph;
  Plan plan;
  build_ops(x, k, use_order, elide, plan);
  const auto n = static_cast<TaskId>(plan.tasks);
  plan.intra = detail::build_csr(n, g.edges, true);
  plan.carried = detail::build_csr(n, g.carried_edges, true);
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
      same = o.kind == q.kind && o.is_break == q.is_break && o.jump == q.jump &&
             same_loop(o.loop, q.loop) && (o.kind != OpKind::kTask || old_of[o.task] == q.task);
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
  auto same_preds = [&](const detail::Csr& now, const detail::Csr& before, TaskId v, TaskId ov,
                        ProcId p) {
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
std::string loop_wait_cycle(const Plan& plan, const ExecGraph& x) {
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

/// Runs the per-processor programs interleaved on one thread (round robin, each processor
/// advancing while its waits hold). With a workload: the serial executor (deterministic);
/// without: the deadlock check of a plan (every loop runs two iterations).
/// Throws UsageError naming the first blocked processor when no processor can advance.
void run_interleaved(const Plan& plan, const ExecGraph& x, Workload* w,
                     const std::vector<Observer*>* observers, StepStats* stats) {
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
    switch (wp.kind) {
      case WaitKind::kOnce:
        return done[wp.producer] >= 1;
      case WaitKind::kSameIter:
        return done[wp.producer] >= iter + 1;
      case WaitKind::kPrevIter:
        return iter == 0 || done[wp.producer] >= iter;
      case WaitKind::kAfterLoop:
        return loop_stop[wp.loop] && done[wp.producer] >= loop_iters[wp.loop];
    }
    return false;
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
              detail::notify_begin(*observers, thread, op.task, c.iter);
            w->run(TaskRun{&x, op.task, x.origin[op.task], c.iter, thread});
            if (observers && !observers->empty())
              detail::notify_end(*observers, thread, op.task, c.iter);
          }
          if (stats) {
            auto& tc = stats->threads[p];
            ++tc.tasks;
            tc.waits += op.wait_end - op.wait_begin;
            if (op.signal) ++tc.signals;
          }
          done[op.task] = c.iter + 1;
          if (op.is_break) {
            const bool stop = w ? detail::leave_loop(x, op.loop, c.iter, *w) : c.iter + 1 >= 2;
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

class PartitionExecutor final : public Executor {
 public:
  explicit PartitionExecutor(const ExecOptions& o)
      : Executor(Policy::kPartition, o), parking_(o.spin_ns, o.threads > detail::hardware_pus()) {
    counters_ = std::make_unique<Slot[]>(o.threads);
  }

  std::uint64_t order_fallbacks() const override { return order_fallbacks_; }

  ~PartitionExecutor() override {
    watchdog_.reset();
    if (!workers_.empty()) {
      // relaxed: published by the seq_cst store of step_seq_ just below (a release); the
      // workers read shutdown_ after acquiring that value.
      shutdown_.store(true, std::memory_order_relaxed);
      // relaxed: only this thread writes step_seq_.
      parking_.signal(step_seq_, step_seq_.load(std::memory_order_relaxed) + 1);
      parking_.wake(step_seq_);
      for (auto& t : workers_) t.join();
    }
    if (pinned_main_) detail::restore_binding(main_binding_);
  }

 private:
  struct alignas(64) Slot {
    ThreadCounters c;
    // For the watchdog (relaxed: diagnostics; only the owning thread writes them).
    std::atomic<std::uint64_t> progress{0};       // tasks finished + blocked waits passed
    std::atomic<std::uint32_t> at_task{kNoTask};  // the task run or waited for last
    std::atomic<std::uint32_t> wait_kind{0};      // 0: none, 1: task, 2: loop, 3: first touch
    std::atomic<std::uint32_t> wait_id{0};        // the producer task or the loop
  };

  std::shared_ptr<void> build(const ExecGraph& x) override {
    return checked(
        x, std::make_shared<Plan>(build_plan(x, options_.threads, true, options_.elide_waits)));
  }

  std::shared_ptr<void> rebuild(const ExecGraph& x, const ExecGraph&,
                                const void* previous) override {
    const Plan& prev = *static_cast<const Plan*>(previous);
    auto plan =
        std::make_shared<Plan>(update_plan(x, prev, options_.threads, true, options_.elide_waits));
    if (options_.verify_plans &&
        !same_programs(*plan, build_plan(x, options_.threads, true, options_.elide_waits)))
      throw std::logic_error("partition executor: the incremental plan differs from a full build");
    return checked(x, std::move(plan));
  }

  std::uint32_t rebuilt_procs(const void* plan) const override {
    return static_cast<const Plan*>(plan)->rebuilt_procs;
  }

  // Program order on every processor never deadlocks (every wait names an earlier task in
  // program order); only an explicit order needs the check.
  // ExecOptions::test_lose_signal is applied here, to full and incremental builds alike.
  std::shared_ptr<Plan> checked(const ExecGraph& x, std::shared_ptr<Plan> plan) {
    lose_signal(*plan, x);
    if (plan->program_order) return plan;
    try {
      if (const std::string cycle = loop_wait_cycle(*plan, x); !cycle.empty())
        throw UsageError("the assignment's task order deadlocks: " + cycle);
      run_interleaved(*plan, x, nullptr, nullptr, nullptr);  // throws if the order deadlocks
    } catch (const UsageError&) {
      if (plan->program_order || !x.added_edges) throw;  // the order itself is invalid
      // The explicit order cannot be kept with the lowered graph's extra edges (serialised
      // CW writers): fall back to program order on each processor, which never deadlocks.
      plan = std::make_shared<Plan>(build_plan(x, options_.threads, false, options_.elide_waits));
      lose_signal(*plan, x);
      ++order_fallbacks_;
    }
    return plan;
  }

  void execute(void* plan_ptr, const ExecGraph& x, Workload& w, bool fresh,
               StepStats& stats) override {
    Plan& plan = *static_cast<Plan*>(plan_ptr);
    const std::uint32_t k = options_.threads;
    if (options_.serial) {
      if (fresh)
        for (const ProcPlan& pp : plan.procs)
          for (DatumId d : pp.owned)
            if (w.needs_touch(d)) w.first_touch(d);
      run_interleaved(plan, x, &w, &observers_, &stats);
      return;
    }
    start_workers();
    if (plan.tasks > done_cap_) {
      done_ = std::make_unique<PaddedCounter[]>(plan.tasks);
      done_cap_ = plan.tasks;
    }
    if (plan.loops > loop_cap_) {
      loop_ = std::make_unique<PaddedCounter[]>(plan.loops);
      loop_cap_ = plan.loops;
    }
    plan_ = &plan;
    exec_ = &x;
    workload_ = &w;
    fresh_ = fresh;
    if (fresh) ++touch_rounds_;
    error_ = nullptr;
    // relaxed: published to the workers by the release in signal(step_seq_) below.
    abort_.store(false, std::memory_order_relaxed);
    const std::uint64_t seq = ++steps_;
    epoch_ = seq << 32;
    start_watchdog();
    if (watchdog_) watchdog_->begin_step(seq);  // a release: step context visible
    parking_.signal(step_seq_, seq);            // seq_cst store (a release): step context visible
    run_proc(0);
    if (k > 1) {
      bool parked = false;
      std::int64_t waited = 0;
      const std::uint64_t target = seq * (k - 1);
      // acquire (inside wait): every worker's counters and writes are visible afterwards.
      parking_.wait(
          finished_, [target](std::uint64_t v) { return v >= target; }, never_abort_, parked,
          waited);
    }
    if (watchdog_) watchdog_->end_step();
    stats.threads.resize(k);
    for (std::uint32_t p = 0; p < k; ++p) stats.threads[p] = counters_[p].c;
    stats.loop_iterations.resize(plan.loops);
    for (std::size_t l = 0; l < plan.loops; ++l) {
      // relaxed: all writers finished (acquire on finished_ above).
      const std::uint64_t v = loop_[l].v.load(std::memory_order_relaxed);
      stats.loop_iterations[l] =
          (v >> 32) == seq ? static_cast<std::uint32_t>((v & 0xffffffffu) >> 1) : 0;
    }
    if (error_) std::rethrow_exception(error_);
  }

  void start_workers() {
    if (started_) return;
    started_ = true;
    if (options_.pin) {
      detail::save_binding(main_binding_);
      pinned_main_ = detail::pin_current_thread(0);
    }
    for (std::uint32_t p = 1; p < options_.threads; ++p)
      workers_.emplace_back([this, p] { worker(p); });
  }

  void worker(std::uint32_t p) {
    if (options_.pin) detail::pin_current_thread(p);
    std::uint64_t seen = 0;
    for (;;) {
      bool parked = false;
      std::int64_t waited = 0;
      // acquire (inside wait): the step context written before the store is visible.
      seen = parking_.wait(
          step_seq_, [seen](std::uint64_t v) { return v > seen; }, never_abort_, parked, waited);
      // relaxed: ordered by the acquire of step_seq_ above.
      if (shutdown_.load(std::memory_order_relaxed)) return;
      run_proc(p);
      // seq_cst RMW (a release): the counters and the task's writes reach the main thread.
      finished_.fetch_add(1, std::memory_order_seq_cst);
      if (parking_.parked() != 0) parking_.wake(finished_);
    }
  }

  void fail(std::exception_ptr e) {
    {
      std::lock_guard<std::mutex> lock(error_mutex_);
      if (!error_) error_ = e;
    }
    // seq_cst: Dekker with the waiters' abort check before they sleep (sync.hpp).
    if (abort_.exchange(true, std::memory_order_seq_cst)) return;
    // std::atomic::wait only promises to wake a sleeper whose value changed, so each
    // counter is bumped (within this epoch: below every later target) before the notify;
    // a woken waiter sees abort_ and leaves.
    for (std::size_t t = 0; t < plan_->tasks; ++t) parking_.poke(done_[t].v);
    for (std::size_t l = 0; l < plan_->loops; ++l) parking_.poke(loop_[l].v);
  }

  // Waits until ok(c); false when the step is aborting. The check that holds at once is
  // inlined into the hot loop; blocking is out of line (block()).
  // `kind`/`id`: what is waited for, for the watchdog's report (1: task id's completion,
  // 2: loop id's decision, 3: the first-touch barrier).
  template <class Ok>
  bool wait(std::atomic<std::uint64_t>& c, Ok ok, std::uint32_t thread, TaskId task,
            ThreadCounters& tc, std::uint64_t& value, std::uint32_t kind, std::uint32_t id) {
    ++tc.waits;
    // acquire: pairs with the signaller's store; its writes are visible to our task.
    value = c.load(std::memory_order_acquire);
    if (!ok(value)) [[unlikely]]
      value = block(c, ok, thread, task, tc, kind, id);
    // relaxed: a hint; when set, no task runs after this point, so nothing depends on it.
    return !abort_.load(std::memory_order_relaxed);
  }

  // The blocking part of wait(): spin, then park; returns the value that satisfied ok (or
  // the last one read when aborting).
  template <class Ok>
  [[gnu::noinline]] std::uint64_t block(std::atomic<std::uint64_t>& c, Ok ok,
                                        std::uint32_t thread, TaskId task, ThreadCounters& tc,
                                        std::uint32_t kind, std::uint32_t id) {
    Slot& slot = counters_[thread];
    // relaxed: read by the watchdog for its report only.
    slot.at_task.store(task, std::memory_order_relaxed);
    slot.wait_id.store(id, std::memory_order_relaxed);
    slot.wait_kind.store(kind, std::memory_order_relaxed);
    bool parked = false;
    std::int64_t waited = 0;
    const std::int64_t t0 = observers_.empty() ? 0 : now_ns();
    const std::uint64_t value = parking_.wait(c, ok, abort_, parked, waited);
    // relaxed: as above; progress is only compared between two samples.
    slot.wait_kind.store(0, std::memory_order_relaxed);
    slot.progress.store(slot.progress.load(std::memory_order_relaxed) + 1,
                        std::memory_order_relaxed);
    ++tc.blocked_waits;
    tc.parks += parked ? 1 : 0;
    tc.wait_ns += waited;
    if (!observers_.empty())
      for (Observer* o : observers_) o->on_wait(thread, task, t0, t0 + waited, parked);
    return value;
  }

  // ExecOptions::test_lose_signal: the task's completion is never published.
  void lose_signal(Plan& plan, const ExecGraph& x) const {
    if (!options_.test_lose_signal || *options_.test_lose_signal >= x.exec_of.size()) return;
    const TaskId t = x.exec_of[*options_.test_lose_signal];
    for (ProcPlan& pp : plan.procs)
      for (Op& op : pp.ops)
        if (op.kind == OpKind::kTask && op.task == t) op.signal = false;
  }

  void start_watchdog() {
    if (watchdog_ || options_.timeout_ms <= 0) return;
    watchdog_ = std::make_unique<detail::Watchdog>(
        options_.timeout_ms,
        [this] {
          std::uint64_t sum = 0;
          for (std::uint32_t p = 0; p < options_.threads; ++p)
            sum += counters_[p].progress.load(std::memory_order_relaxed);  // relaxed: a sample
          return sum;
        },
        [this] { return stall_report(); }, [this](std::exception_ptr e) { fail(e); },
        options_.timeout_exits);
  }

  // Where each thread stands (the watchdog's report; the step context is valid).
  std::string stall_report() const {
    const ExecGraph& x = *exec_;
    std::string out;
    for (std::uint32_t p = 0; p < options_.threads; ++p) {
      const Slot& s = counters_[p];
      // relaxed: diagnostics, a racy snapshot is fine.
      const std::uint32_t kind = s.wait_kind.load(std::memory_order_relaxed);
      const std::uint32_t id = s.wait_id.load(std::memory_order_relaxed);
      const std::uint32_t task = s.at_task.load(std::memory_order_relaxed);
      if (!out.empty()) out += "; ";
      out += "thread " + std::to_string(p);
      const auto label = [&x](TaskId t) {
        return t < x.graph.tasks.size()
                   ? "task " + std::to_string(t) + " (" + x.graph.kind_name(t) + ")"
                   : std::string("no task");
      };
      if (kind == 1 && id < x.graph.tasks.size()) {
        out += " waits for " + label(id) + " on thread " + std::to_string(x.assignment.proc[id]);
        for (const Edge& e : x.graph.edges)
          if (e.from == id && e.to == task && e.datum < x.graph.data.size()) {
            out += " (datum '" + x.graph.data[e.datum].name + "')";
            break;
          }
        if (task < x.graph.tasks.size()) out += " before running " + label(task);
      } else if (kind == 2) {
        out += " waits for the decision of loop " + std::to_string(id);
      } else if (kind == 3) {
        out += " waits at the first-touch barrier";
      } else if (task < x.graph.tasks.size()) {
        out += " runs or last ran " + label(task);
      } else {
        out += " has run no task yet";
      }
    }
    return out;
  }

  void run_proc(std::uint32_t p) {
    ThreadCounters tc{};
    const Plan& plan = *plan_;
    const ExecGraph& x = *exec_;
    Workload& w = *workload_;
    const ProcPlan& pp = plan.procs[p];
    const std::uint64_t E = epoch_;
    const bool observe = !observers_.empty();
    const std::uint32_t stride = observe_stride_;
    const bool watch = watchdog_ != nullptr;
    Slot& slot = counters_[p];
    // Kept in registers in the loop (tc escapes into wait()), added to tc at the end.
    std::uint64_t tasks = 0, signals = 0;
    try {
      if (fresh_) {
        // A failed allocation still arrives at the barrier below (the others would wait
        // for it forever otherwise) and then leaves with the step aborted.
        try {
          for (DatumId d : pp.owned)
            if (w.needs_touch(d)) w.first_touch(d);
        } catch (...) {
          fail(std::current_exception());
        }
        // Every buffer exists before any task runs: a barrier over the k threads.
        // seq_cst RMW (a release): our allocations reach the threads acquiring the total.
        touched_.fetch_add(1, std::memory_order_seq_cst);
        if (parking_.parked() != 0) parking_.wake(touched_);
        const std::uint64_t all = touch_rounds_ * options_.threads;
        std::uint64_t seen = 0;
        if (!wait(
                touched_, [all](std::uint64_t s) { return s >= all; }, p, kNoTask, tc, seen, 3, 0))
          goto out;
      }
      std::uint32_t iter = 0;
      std::uint64_t v = 0;
      const Op* const ops = pp.ops.data();
      const WaitPoint* const waits = pp.waits.data();
      const std::size_t n_ops = pp.ops.size();
      for (std::size_t pc = 0; pc < n_ops;) {
        const Op& op = ops[pc];
        switch (op.kind) {
          case OpKind::kLoopBegin:
            iter = 0;
            ++pc;
            break;
          case OpKind::kLoopEnd: {
            const std::uint64_t need = E | (static_cast<std::uint64_t>(iter + 1) << 1);
            if (!wait(
                    loop_[op.loop].v, [need](std::uint64_t s) { return s >= need; }, p, kNoTask, tc,
                    v, 2, op.loop))
              goto out;
            const std::uint64_t decided = (v & 0xffffffffu) >> 1;
            if (decided > iter + 1 || (v & 1u) == 0) {
              ++iter;
              pc = op.jump;
            } else {
              iter = 0;
              ++pc;
            }
            break;
          }
          case OpKind::kTask: {
            for (auto i = op.wait_begin; i < op.wait_end; ++i) {
              const WaitPoint& wp = waits[i];
              std::uint64_t target = E + 1;
              switch (wp.kind) {
                case WaitKind::kOnce:
                  target = E + 1;
                  break;
                case WaitKind::kSameIter:
                  target = E + iter + 1;
                  break;
                case WaitKind::kPrevIter:
                  if (iter == 0) continue;
                  target = E + iter;
                  break;
                case WaitKind::kAfterLoop: {
                  const std::uint64_t epoch = E;
                  if (!wait(
                          loop_[wp.loop].v,
                          [epoch](std::uint64_t s) {
                            return (s >> 32) == (epoch >> 32) && (s & 1u);
                          },
                          p, op.task, tc, v, 2, wp.loop))
                    goto out;
                  target = E + ((v & 0xffffffffu) >> 1);
                  break;
                }
              }
              if (!wait(
                      done_[wp.producer].v, [target](std::uint64_t s) { return s >= target; }, p,
                      op.task, tc, v, 1, wp.producer))
                goto out;
            }
            if (observe && detail::sampled(iter, stride))
              detail::notify_begin(observers_, p, op.task, iter);
            if (watch) slot.at_task.store(op.task, std::memory_order_relaxed);  // relaxed: report
            w.run(TaskRun{&x, op.task, op.origin, iter, p});
            if (observe && detail::sampled(iter, stride))
              detail::notify_end(observers_, p, op.task, iter);
            if (watch)  // relaxed: compared between two samples of the watchdog only
              slot.progress.store(slot.progress.load(std::memory_order_relaxed) + 1,
                                  std::memory_order_relaxed);
            ++tasks;
            if (op.signal) {
              parking_.signal(done_[op.task].v, E + iter + 1);
              ++signals;
            }
            if (op.is_break) {
              const bool stop = detail::leave_loop(x, op.loop, iter, w);
              parking_.signal(loop_[op.loop].v,
                              E | (static_cast<std::uint64_t>(iter + 1) << 1) | (stop ? 1u : 0u));
              ++signals;
            }
            ++pc;
            break;
          }
        }
      }
    } catch (...) {
      fail(std::current_exception());
    }
  out:
    tc.tasks += tasks;
    tc.signals += signals;
    counters_[p].c = tc;
  }

  detail::Parking parking_;
  std::vector<std::thread> workers_;
  bool started_ = false;
  bool pinned_main_ = false;
  detail::SavedBinding main_binding_;
  std::unique_ptr<Slot[]> counters_;
  std::unique_ptr<PaddedCounter[]> done_;
  std::size_t done_cap_ = 0;
  std::unique_ptr<PaddedCounter[]> loop_;
  std::size_t loop_cap_ = 0;
  // Step context: written by the main thread before the step_seq_ store, read by workers
  // after acquiring it.
  const Plan* plan_ = nullptr;
  const ExecGraph* exec_ = nullptr;
  Workload* workload_ = nullptr;
  bool fresh_ = false;
  std::uint64_t epoch_ = 0;
  std::uint64_t steps_ = 0;
  alignas(64) std::atomic<std::uint64_t> step_seq_{0};
  alignas(64) std::atomic<std::uint64_t> finished_{0};
  alignas(64) std::atomic<std::uint64_t> touched_{0};  // first-touch barrier arrivals
  std::uint64_t touch_rounds_ = 0;
  std::uint64_t order_fallbacks_ = 0;
  alignas(64) std::atomic<bool> abort_{false};
  std::atomic<bool> shutdown_{false};
  const std::atomic<bool> never_abort_{false};
  std::mutex error_mutex_;
  std::exception_ptr error_;
  std::unique_ptr<detail::Watchdog> watchdog_;  // last member: stopped first
};

}  // namespace

std::unique_ptr<Executor> make_partition_executor(const ExecOptions& o) {
  return std::make_unique<PartitionExecutor>(o);
}

}  // namespace tgraph::replay
