// SPDX-License-Identifier: MIT
// A timeline's step unrolled: instances, their predecessors, per-thread order, the span.
#include "step_view.hpp"

#include <algorithm>

#include "tgraph/graph/metrics.hpp"

namespace tgraph::explain::detail {
namespace {

// Ceiling of the unrolled instances the span is computed over (beyond: span 0).
constexpr std::uint64_t kMaxUnrolled = 50'000'000;

// Calls add(u, iteration of u) for every predecessor of instance (task, it): intra-step
// edges (the same iteration within one loop body; the last iteration of a loop's task read
// after the loop; iteration 0 outside loops), loop-carried edges and the loop's gate (every
// body task of iteration i + 1 after the break of iteration i). `last(u)` is the last
// iteration of u.
template <typename Last, typename Add>
void for_each_pred(const TimelineGraph& g, const IncomingEdges& in, const IncomingEdges& carried,
                   TaskId task, std::uint32_t it, Last last, Add add) {
  const LoopId lt = g.task_loop[task];
  for (std::uint32_t k = in.begin[task]; k < in.begin[task + 1]; ++k) {
    const Edge& e = g.edges[in.edge[k]];
    const LoopId lu = g.task_loop[e.from];
    if (lu != kNoLoop && lu == lt)
      add(e.from, it, e.datum);
    else if (lu != kNoLoop)
      add(e.from, last(e.from), e.datum);
    else
      add(e.from, 0u, e.datum);
  }
  if (it == 0) return;
  for (std::uint32_t k = carried.begin[task]; k < carried.begin[task + 1]; ++k) {
    const Edge& e = g.carried_edges[carried.edge[k]];
    add(e.from, it - 1, e.datum);
  }
  if (lt != kNoLoop) {
    const TaskId brk = g.loops[lt].second - 1;
    add(brk, it - 1, DatumId{0xffffffffu});
  }
}

}  // namespace

StepView make_view(const Timeline& t, const TimelineStep& info) {
  StepView v;
  v.graph = &t.graphs[info.graph];
  v.info = &info;
  v.threads = t.threads;
  const TimelineGraph& g = *v.graph;
  const std::size_t n = g.task_kind.size();
  for (const TimelineTask& e : t.tasks) {
    if (e.step != info.step) continue;
    v.instances.push_back({.task = e.task, .iteration = e.iteration, .thread = e.thread,
                           .start = e.start_ns, .end = e.end_ns, .cpu = e.cpu_ns,
                           .cost = info.cost_ns[e.task], .reducer = g.origin[e.task] == kNoTask});
  }
  std::stable_sort(v.instances.begin(), v.instances.end(), [](const Instance& a, const Instance& b) {
    return a.start != b.start ? a.start < b.start : a.end < b.end;
  });
  v.wall = info.wall_ns;
  for (const Instance& i : v.instances) v.wall = std::max(v.wall, i.end);

  // (task, iteration) -> instance; iterations beyond the loop's count are not indexed.
  const auto runs = [&](TaskId task) -> std::uint32_t {
    const LoopId l = g.task_loop[task];
    return l == kNoLoop ? 1u : info.iterations[l];
  };
  std::vector<std::vector<std::uint32_t>> at(n);
  for (std::uint32_t k = 0; k < v.instances.size(); ++k) {
    const Instance& i = v.instances[k];
    if (i.iteration >= runs(i.task)) continue;
    auto& a = at[i.task];
    if (a.size() <= i.iteration) a.resize(i.iteration + 1, kNone);
    a[i.iteration] = k;
  }
  std::uint64_t expected = 0, indexed = 0;
  for (TaskId task = 0; task < n; ++task) {
    expected += runs(task);
    for (const std::uint32_t k : at[task]) indexed += k != kNone ? 1 : 0;
  }
  v.unobserved = expected - indexed;

  const IncomingEdges in = incoming_edges(n, g.edges);
  const IncomingEdges carried = incoming_edges(n, g.carried_edges);
  const auto last_observed = [&](TaskId u) -> std::uint32_t {
    const auto& a = at[u];
    for (std::size_t k = a.size(); k-- > 0;)
      if (a[k] != kNone) return static_cast<std::uint32_t>(k);
    return kNone;
  };
  for (std::uint32_t k = 0; k < v.instances.size(); ++k) {
    Instance& i = v.instances[k];
    i.pred_begin = static_cast<std::uint32_t>(v.preds.size());
    for_each_pred(g, in, carried, i.task, i.iteration, last_observed,
                  [&](TaskId u, std::uint32_t it, DatumId datum) {
                    if (it >= at[u].size() || at[u][it] == kNone || at[u][it] == k) return;
                    const std::uint32_t p = at[u][it];
                    v.preds.push_back(p);
                    if (i.latest == kNone || v.instances[p].end > i.ready) {
                      i.latest = p;
                      i.ready = v.instances[p].end;
                      i.datum = datum;
                    }
                  });
    i.pred_end = static_cast<std::uint32_t>(v.preds.size());
  }

  v.by_thread.resize(t.threads);
  for (std::uint32_t k = 0; k < v.instances.size(); ++k) {
    Instance& i = v.instances[k];
    auto& row = v.by_thread[i.thread];
    i.prev = row.empty() ? kNone : row.back();
    row.push_back(k);
  }
  for (const TimelineWait& w : t.waits) {
    if (w.step != info.step) continue;
    const std::int64_t a = std::clamp<std::int64_t>(w.start_ns, 0, v.wall);
    const std::int64_t b = std::clamp<std::int64_t>(w.end_ns, a, v.wall);
    v.waits.push_back({w.thread, a, b, w.parked});
  }
  std::sort(v.waits.begin(), v.waits.end(),
            [](const Wait& a, const Wait& b) { return a.start < b.start; });

  // The span: earliest finish over the graph unrolled, at sequential costs.
  if (expected <= kMaxUnrolled) {
    std::vector<std::vector<std::int64_t>> ef(n);
    for (TaskId task = 0; task < n; ++task) ef[task].assign(runs(task), 0);
    const auto last = [&](TaskId u) -> std::uint32_t {
      return runs(u) == 0 ? kNone : runs(u) - 1;
    };
    const auto finish = [&](TaskId task, std::uint32_t it) {
      std::int64_t start = 0;
      for_each_pred(g, in, carried, task, it, last, [&](TaskId u, std::uint32_t iu, DatumId) {
        if (iu < ef[u].size()) start = std::max(start, ef[u][iu]);
      });
      ef[task][it] = start + info.cost_ns[task];
      v.span = std::max(v.span, ef[task][it]);
    };
    for (TaskId task = 0; task < n;) {
      const LoopId l = g.task_loop[task];
      if (l == kNoLoop) {
        finish(task, 0);
        ++task;
        continue;
      }
      const auto [first, end] = g.loops[l];
      for (std::uint32_t it = 0; it < info.iterations[l]; ++it)
        for (TaskId u = first; u < end; ++u) finish(u, it);
      task = end;
    }
  }
  return v;
}

}  // namespace tgraph::explain::detail
