// SPDX-License-Identifier: MIT
// CW lowering (paper section 3.2): temporaries + reducer, or serialisation.
#include "tgraph/graph/lowering.hpp"

#include <algorithm>
#include <cstdint>
#include <string>
#include <unordered_map>

namespace tgraph {

std::string_view to_string(CwMode mode) {
  switch (mode) {
    case CwMode::kReduce:
      return "reduce";
    case CwMode::kSerialize:
      return "serialize";
  }
  return "?";
}

std::string_view to_string(ReduceScope scope) {
  switch (scope) {
    case ReduceScope::kNone:
      return "none";
    case ReduceScope::kPerProcessor:
      return "per-processor";
    case ReduceScope::kPerWriter:
      return "per-writer";
    case ReduceScope::kPerThread:
      return "per-thread";
  }
  return "?";
}

std::optional<ReduceScope> parse_reduce_scope(std::string_view name) {
  for (ReduceScope s : {ReduceScope::kNone, ReduceScope::kPerProcessor, ReduceScope::kPerWriter,
                        ReduceScope::kPerThread})
    if (to_string(s) == name) return s;
  return std::nullopt;
}

namespace {

struct Segment {
  std::vector<TaskId> members;
};

struct PendingReducer {
  DatumId target = 0;
  ProcId home = 0;            // processor that runs the reducer (the first writer's)
  std::vector<ProcId> slots;  // temporaries to add, increasing (processors or writer ranks)
};

std::uint64_t pair_key(std::uint32_t a, std::uint32_t b) {
  return (static_cast<std::uint64_t>(a) << 32) | b;
}

}  // namespace

ExecGraph lower(const StepGraph& g, const Assignment* a, CwMode mode) {
  return lower(g, a, mode, a != nullptr ? ReduceScope::kPerProcessor : ReduceScope::kNone);
}

ExecGraph lower(const StepGraph& g, const Assignment* a, CwMode mode, ReduceScope scope,
                const std::vector<bool>* reducible, EdgeDeriver* deriver, std::uint32_t threads) {
  const auto n = static_cast<TaskId>(g.tasks.size());
  auto proc = [&](TaskId t) -> ProcId { return a ? a->proc[t] : 0; };
  // One thread needs no per-thread temporaries: its writers run one after the other.
  const bool per_thread = scope == ReduceScope::kPerThread && threads > 1;
  // Per writer and per thread, a group is lowered wherever it has two writers or more.
  const bool per_writer = scope == ReduceScope::kPerWriter || per_thread;

  // 1. Find the CW groups that span processors (split at loop-region boundaries).
  std::unordered_map<std::uint64_t, ProcId> redirect;     // (task, datum) -> processor temp
  std::unordered_map<std::uint64_t, bool> serialize_acc;  // (task, datum) -> CW becomes RW
  std::vector<std::vector<PendingReducer>> after(n);      // reducers emitted after task t
  std::vector<std::vector<PendingReducer>> before(n);     // reducers emitted before task t
  const bool lower_groups =
      mode == CwMode::kReduce &&
      (per_writer || (scope == ReduceScope::kPerProcessor && a != nullptr && a->k > 1));
  const std::uint32_t slots_per_group = per_thread ? threads : 0;
  if (lower_groups) {
    // A CW group of derive_edges() can run on across a loop boundary (into the body, out of
    // it, or from the end of one iteration into the next): its members there have no edge
    // between them. A segment cut by such a boundary is therefore kept pending until the
    // next access to its datum: if that access is CW too, the segment is serialised (CW ->
    // RW, which orders it before the following writers); otherwise it is lowered normally.
    std::vector<Segment> open(g.data.size()), pending(g.data.size());
    std::vector<DatumId> open_list;
    auto serialize = [&](Segment& s, DatumId d) {
      for (TaskId m : s.members) serialize_acc[pair_key(m, d)] = true;
      s.members.clear();
    };
    // Temporary slot of the i-th member of a segment: its processor, or (per writer) its
    // rank in the group; slot of the first member = the home, which needs no temporary.
    auto slot = [&](const Segment& s, std::size_t i) -> ProcId {
      return per_writer ? static_cast<ProcId>(i) : proc(s.members[i]);
    };
    // `reader`: the task of the same loop region whose access ends the segment; the reducer
    // goes right before it (its home processor first runs what precedes that task in its
    // program rather than block on the other processors' writers), else right after the
    // last writer.
    auto lower_segment = [&](Segment& s, DatumId d, TaskId reader = kNoTask) {
      if (s.members.empty()) return;
      std::vector<ProcId> slots;
      for (std::size_t i = 0; i < s.members.size(); ++i) slots.push_back(slot(s, i));
      std::sort(slots.begin(), slots.end());
      slots.erase(std::unique(slots.begin(), slots.end()), slots.end());
      if (slots.size() > 1) {
        const TaskId last = s.members.back();
        const LoopId l = g.tasks[last].loop;
        if (l != kNoLoop && last + 1 == g.loops[l].last) {
          serialize(s, d);  // a break task with a CW access: no room for a reducer after it
          return;
        }
        if (reducible != nullptr && d < reducible->size() && !(*reducible)[d]) {
          serialize(s, d);  // the writers cannot be redirected to temporaries
          return;
        }
        PendingReducer r;
        r.target = d;
        r.home = proc(s.members.front());
        if (per_thread) {
          // Every writer writes its thread's temporary, found at run time from the first of
          // the group's block (ExecGraph::datum_on); the reducer adds all of them.
          for (ProcId p = 0; p < slots_per_group; ++p) r.slots.push_back(p);
          for (TaskId m : s.members) redirect[pair_key(m, d)] = 0;
        } else {
          const ProcId home_slot = slot(s, 0);
          for (ProcId p : slots)
            if (p != home_slot) r.slots.push_back(p);
          for (std::size_t i = 0; i < s.members.size(); ++i)
            if (slot(s, i) != home_slot) redirect[pair_key(s.members[i], d)] = slot(s, i);
        }
        (reader != kNoTask ? before[reader] : after[last]).push_back(std::move(r));
      }
      s.members.clear();
    };
    // First access mode of each datum in each loop body (for the wrap-around).
    std::vector<std::unordered_map<DatumId, AccessMode>> first_in_body(g.loops.size());
    for (LoopId l = 0; l < g.loops.size(); ++l)
      for (TaskId t = g.loops[l].first; t < g.loops[l].last; ++t)
        for (const Access& acc : g.accesses_of(t)) first_in_body[l].emplace(acc.datum, acc.mode);
    auto cut_all = [&](LoopId leaving) {
      for (DatumId d : open_list) {
        Segment& s = open[d];
        if (s.members.empty()) continue;
        if (leaving != kNoLoop) {
          auto it = first_in_body[leaving].find(d);
          if (it != first_in_body[leaving].end() && it->second == AccessMode::CW) {
            serialize(s, d);  // continues into the next iteration's CW writers
            continue;
          }
        }
        pending[d] = std::move(s);
        s.members.clear();
      }
      open_list.clear();
    };
    LoopId region = kNoLoop;
    for (TaskId t = 0; t < n; ++t) {
      const LoopId l = g.tasks[t].loop;
      const bool body_start = l != kNoLoop && g.loops[l].first == t;
      if (l != region || body_start) cut_all(region);
      region = l;
      for (const Access& acc : g.accesses_of(t)) {
        const DatumId d = acc.datum;
        if (!pending[d].members.empty()) {
          if (acc.mode == AccessMode::CW) {
            serialize(pending[d], d);
          } else {
            lower_segment(pending[d], d);
          }
        }
        Segment& s = open[d];
        if (acc.mode == AccessMode::CW) {
          if (s.members.empty()) open_list.push_back(d);
          if (s.members.empty() || s.members.back() != t) s.members.push_back(t);
        } else {
          lower_segment(s, d, t);
        }
      }
    }
    cut_all(region);
    for (DatumId d = 0; d < g.data.size(); ++d) lower_segment(pending[d], d);
  }

  // 2. Emit the exec graph.
  ExecGraph x;
  x.cw = mode;
  x.scope = lower_groups ? scope : ReduceScope::kNone;
  x.thread_temps = slots_per_group;
  StepGraph& out = x.graph;
  out.kinds = g.kinds;
  out.objects = g.objects;
  out.data = g.data;
  out.contacts = g.contacts;
  out.groups = g.groups;
  x.datum_origin.resize(g.data.size());
  for (DatumId d = 0; d < g.data.size(); ++d) x.datum_origin[d] = d;
  std::unordered_map<std::uint64_t, DatumId> temp_of;  // (datum, proc) -> exec datum
  auto temp = [&](DatumId d, ProcId p) {
    const auto key = pair_key(d, p);
    if (auto it = temp_of.find(key); it != temp_of.end()) return it->second;
    // Per thread, a datum's temporaries are made together, one block of consecutive ids.
    const ProcId from = per_thread ? 0 : p, to = per_thread ? slots_per_group : p + 1;
    for (ProcId q = from; q < to; ++q) {
      Datum t = g.data[d];
      t.name.push_back('@');
      t.name.append(std::to_string(q));
      out.data.push_back(std::move(t));
      x.datum_origin.push_back(d);
      temp_of.emplace(pair_key(d, q), static_cast<DatumId>(out.data.size() - 1));
    }
    return temp_of.at(key);
  };
  KindId reduce_kind = 0;
  bool have_reduce_kind = false;
  x.exec_of.resize(n);
  std::vector<ProcId> exec_proc;
  std::vector<Access> acc_buf;
  // A reducer in the loop region of task `at`, its stable key derived from `at`'s.
  auto emit_reducer = [&](PendingReducer& r, const Task& at) {
    if (!have_reduce_kind) {
      reduce_kind = out.intern_kind("reduce");
      have_reduce_kind = true;
    }
    Reduction red;
    red.target = r.target;
    acc_buf.clear();
    for (ProcId p : r.slots) {
      const DatumId tmp = temp(r.target, p);
      red.temps.push_back(tmp);
      acc_buf.push_back({tmp, AccessMode::RW});
    }
    // Per processor, the reducer and the home writers share a processor: CW leaves the
    // reducer free to go before them in an explicit order. Per writer, the first writer
    // may run on any thread: RW orders the reducer after it (consecutive CW accesses of
    // one datum have no edge between them); per thread, RW orders it after the previous
    // accesses of the datum, which no writer waits for.
    acc_buf.push_back({r.target, per_writer ? AccessMode::RW : AccessMode::CW});
    const TaskId rid = out.add_task(reduce_kind, g.data[r.target].object, acc_buf, 0,
                                    at.key * 1099511628211ull + r.target + 1);
    out.tasks[rid].loop = at.loop;
    x.origin.push_back(kNoTask);
    x.reduction.push_back(static_cast<std::uint32_t>(x.reductions.size()));
    x.reductions.push_back(std::move(red));
    exec_proc.push_back(r.home);
  };
  for (TaskId t = 0; t < n; ++t) {
    const Task& task = g.tasks[t];
    for (PendingReducer& r : before[t]) emit_reducer(r, task);
    acc_buf.clear();
    for (Access acc : g.accesses_of(t)) {
      if (acc.mode == AccessMode::CW) {
        if (mode == CwMode::kSerialize || serialize_acc.count(pair_key(t, acc.datum)) != 0) {
          acc.mode = AccessMode::RW;
          x.added_edges = true;
        } else if (auto it = redirect.find(pair_key(t, acc.datum)); it != redirect.end()) {
          acc.datum = temp(acc.datum, it->second);
        }
      }
      acc_buf.push_back(acc);
    }
    const TaskId id = out.add_task(task.kind, task.object, acc_buf, task.cost_ns, task.key);
    out.tasks[id].loop = task.loop;
    x.exec_of[t] = id;
    x.origin.push_back(t);
    x.reduction.push_back(kNoReduction);
    exec_proc.push_back(proc(t));
    for (PendingReducer& r : after[t]) emit_reducer(r, task);
  }
  out.loops = g.loops;
  for (Loop& l : out.loops) {
    l.first = x.exec_of[l.first];
    l.last = x.exec_of[l.last - 1] + 1;
  }
  if (deriver != nullptr) {
    deriver->derive(out);
  } else {
    out.derive_edges();
  }

  // 3. The assignment on exec tasks. With explicit orders, each processor's order is first
  // put in the form the partitioned executor runs (a loop's tasks gathered into one block at
  // the first of them), then each reducer goes right after the last task of its home
  // processor that it transitively depends on, inside its loop's block there when it has a
  // loop. "Depends" follows what a processor actually waits for: the graph's edges, its
  // predecessor in its processor's order, and, for a task that follows a loop (by an edge or
  // in its processor's order), every task of the loop (its exit). The orders plus
  // these relations are acyclic (the orders do not deadlock); inserting a task after all its
  // ancestors on one processor keeps them acyclic. The graph's edges alone are not enough:
  // reducers placed early on two processors can each wait for tasks behind the other's
  // (bars64 under `list`), and a reducer placed before its loop's block drags the whole
  // block ahead of other loops whose exit it needs (falling under `list`).
  Assignment& ax = x.assignment;
  ax.k = a ? a->k : 1;
  ax.proc = std::move(exec_proc);
  if (a != nullptr && !a->order.empty()) {
    const auto ne = static_cast<TaskId>(out.tasks.size());
    const StepGraph& xg = out;
    auto loop_of = [&](TaskId t) { return xg.tasks[t].loop; };
    ax.order.assign(ax.k, {});
    for (ProcId p = 0; p < ax.k && p < a->order.size(); ++p) {
      std::vector<std::vector<TaskId>> body(xg.loops.size());
      for (TaskId t : a->order[p])
        if (g.tasks[t].loop != kNoLoop) body[g.tasks[t].loop].push_back(x.exec_of[t]);
      std::vector<bool> opened(xg.loops.size(), false);
      for (TaskId t : a->order[p]) {
        const LoopId l = g.tasks[t].loop;
        if (l == kNoLoop) {
          ax.order[p].push_back(x.exec_of[t]);
        } else if (!opened[l]) {
          opened[l] = true;
          ax.order[p].insert(ax.order[p].end(), body[l].begin(), body[l].end());
        }
      }
    }
    std::vector<std::vector<TaskId>> preds(ne);
    for (const Edge& e : out.edges) preds[e.to].push_back(e.from);
    // Position of each ordered task in its processor's order (UINT32_MAX: not placed yet).
    std::vector<std::uint32_t> at(ne, UINT32_MAX);
    for (const auto& ord : ax.order)
      for (std::uint32_t i = 0; i < ord.size(); ++i) at[ord[i]] = i;
    std::vector<std::uint32_t> mark(ne, 0);
    std::uint32_t stamp = 0;
    std::vector<TaskId> stack;
    for (TaskId r = 0; r < ne; ++r) {
      if (x.origin[r] != kNoTask) continue;
      const ProcId home = ax.proc[r];
      ++stamp;
      stack.assign(1, r);
      auto visit = [&](TaskId u) {
        if (mark[u] != stamp) {
          mark[u] = stamp;
          stack.push_back(u);
        }
      };
      // t waits for u; when u is in a loop that t is not in, t waits for the loop's exit,
      // and the exit waits for the last iteration of every task of the loop, on every
      // processor: an iteration's tasks can wait, through loop-carried edges and each
      // processor's order, for any task of the previous one (a reducer placed before its
      // home processor's block of that loop would stall the loop it waits for).
      auto waits_for = [&](TaskId t, TaskId u) {
        visit(u);
        const LoopId lu = loop_of(u);
        if (lu != kNoLoop && lu != loop_of(t))
          for (TaskId v = xg.loops[lu].first; v < xg.loops[lu].last; ++v) visit(v);
      };
      while (!stack.empty()) {
        const TaskId t = stack.back();
        stack.pop_back();
        for (TaskId u : preds[t]) waits_for(t, u);
        if (t != r && at[t] != UINT32_MAX && at[t] > 0)
          waits_for(t, ax.order[ax.proc[t]][at[t] - 1]);
      }
      auto& ord = ax.order[home];
      std::size_t pos = 0;
      for (std::size_t i = 0; i < ord.size(); ++i)
        if (mark[ord[i]] == stamp) pos = i + 1;
      if (const LoopId l = loop_of(r); l != kNoLoop) {
        // Inside the block of l on the home processor (which holds the group's first writer).
        std::size_t begin = ord.size(), end = 0;
        for (std::size_t i = 0; i < ord.size(); ++i)
          if (loop_of(ord[i]) == l) {
            begin = std::min(begin, i);
            end = i + 1;
          }
        if (begin < end) pos = std::clamp(pos, begin, end);
      }
      ord.insert(ord.begin() + static_cast<std::ptrdiff_t>(pos), r);
      for (std::size_t i = pos; i < ord.size(); ++i) at[ord[i]] = static_cast<std::uint32_t>(i);
    }
  }
  return x;
}

}  // namespace tgraph
