// SPDX-License-Identifier: MIT
#include "tgraph/partition/strategy.hpp"

#include <algorithm>
#include <chrono>
#include <memory>
#include <stdexcept>
#include <unordered_map>

#include "strategies.hpp"
#include "tgraph/graph/diff.hpp"
#include "tgraph/graph/enum_names.hpp"
#include "tgraph/graph/error.hpp"

namespace tgraph::partition {

std::string_view to_string(Objective o) {
  switch (o) {
    case Objective::kCut:
      return "cut";
    case Objective::kVolume:
      return "vol";
  }
  return "?";
}

Objective parse_objective(std::string_view s) {
  return parse_enum(s, {Objective::kCut, Objective::kVolume}, "objective");
}

std::string_view to_string(ScotchFlavour f) {
  switch (f) {
    case ScotchFlavour::kDefault:
      return "default";
    case ScotchFlavour::kQuality:
      return "quality";
    case ScotchFlavour::kSpeed:
      return "speed";
    case ScotchFlavour::kBalance:
      return "balance";
  }
  return "?";
}

ScotchFlavour parse_scotch_flavour(std::string_view s) {
  return parse_enum(s,
                    {ScotchFlavour::kDefault, ScotchFlavour::kQuality, ScotchFlavour::kSpeed,
                     ScotchFlavour::kBalance},
                    "scotch_strategy");
}

std::string_view to_string(Rebalance r) {
  switch (r) {
    case Rebalance::kGreedy:
      return "greedy";
    case Rebalance::kScotch:
      return "scotch";
  }
  return "?";
}

Rebalance parse_rebalance(std::string_view s) {
  return parse_enum(s, {Rebalance::kGreedy, Rebalance::kScotch}, "rebalance");
}

std::string_view to_string(StickyFallback f) {
  switch (f) {
    case StickyFallback::kFresh:
      return "fresh";
    case StickyFallback::kRepartition:
      return "repartition";
    case StickyFallback::kRefine:
      return "refine";
  }
  return "?";
}

StickyFallback parse_sticky_fallback(std::string_view s) {
  return parse_enum(
      s, {StickyFallback::kFresh, StickyFallback::kRepartition, StickyFallback::kRefine},
      "sticky_fallback");
}

std::string_view to_string(TaskOrder o) {
  switch (o) {
    case TaskOrder::kProgram:
      return "program";
    case TaskOrder::kList:
      return "list";
  }
  return "?";
}

TaskOrder parse_task_order(std::string_view s) {
  return parse_enum(s, {TaskOrder::kProgram, TaskOrder::kList}, "order");
}

std::vector<TaskId> match_by_key(const StepGraph& g, const StepGraph& prev) {
  return match_tasks_by_key(g, prev);
}

Result Strategy::partition(const StepGraph& g, std::uint32_t k, const Previous& prev,
                           const Options& options) {
  if (k == 0) throw UsageError("k must be at least 1");
  if ((prev.graph == nullptr) != (prev.assignment == nullptr))
    throw UsageError("previous step: graph and assignment must be given together");
  if (prev.graph != nullptr)
    if (std::string why = validate(*prev.graph, *prev.assignment, prev.assignment->k); !why.empty())
      throw UsageError("previous step: " + why);
  if (!(options.imbalance >= 1.0)) throw UsageError("imbalance tolerance must be >= 1");
  if (const std::string why = g.validate(); !why.empty())
    throw UsageError("invalid step graph: " + why);

  const auto t0 = std::chrono::steady_clock::now();
  Result r = do_partition(g, k, prev, options);
  Assignment& a = r.assignment;
  a.k = k;
  if (options.order == TaskOrder::kList && a.order.empty())
    a.order = detail::list_order(g, a, options.model);
  const auto t1 = std::chrono::steady_clock::now();
  r.stats.partition_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();

  if (std::string why = validate(g, a, k); !why.empty())
    throw std::logic_error("strategy " + std::string(name()) + ": " + why);
  // Processors left without a task while there are tasks enough for all of them.
  std::vector<bool> used(k, false);
  for (ProcId p : a.proc) used[p] = true;
  const auto busy = static_cast<std::uint32_t>(std::count(used.begin(), used.end(), true));
  if (busy < std::min<std::uint64_t>(k, g.tasks.size()))
    r.stats.warnings.push_back(std::string(name()) + " leaves " + std::to_string(k - busy) +
                               " of " + std::to_string(k) + " processors without tasks");

  if (prev.graph != nullptr) {
    const std::vector<TaskId> match = match_by_key(g, *prev.graph);
    r.stats.matched_tasks = 0;
    r.stats.moved_tasks = 0;
    for (TaskId t = 0; t < match.size(); ++t) {
      if (match[t] == kNoTask) continue;
      ++r.stats.matched_tasks;
      if (prev.assignment->proc[match[t]] != a.proc[t]) ++r.stats.moved_tasks;
    }
  }
  return r;
}

TracePartition partition_trace(const Trace& trace, std::string_view method, std::uint32_t k,
                               const Options& options) {
  std::unique_ptr<Strategy> s = make_strategy(method);
  TracePartition out;
  out.assignment.method = std::string(method);
  out.assignment.k = k;
  out.assignment.steps.reserve(trace.steps.size());
  for (std::size_t i = 0; i < trace.steps.size(); ++i) {
    Previous prev;
    if (i > 0) prev = {&trace.steps[i - 1], &out.assignment.steps[i - 1]};
    Result r = s->partition(trace.steps[i], k, prev, options);
    out.assignment.partition_ms.push_back(r.stats.partition_ms);
    out.assignment.steps.push_back(std::move(r.assignment));
    out.stats.push_back(r.stats);
  }
  // Each distinct warning once, with the steps it concerns (first and last, count).
  struct Seen {
    std::size_t first = 0, last = 0, count = 0;
  };
  std::vector<std::pair<std::string, Seen>> seen;
  std::size_t fell_back = 0;
  std::string fallback;
  for (std::size_t i = 0; i < out.stats.size(); ++i) {
    const Stats& st = out.stats[i];
    if (!st.placed_by.empty()) {
      ++fell_back;
      fallback = st.placed_by;
    }
    for (const std::string& w : st.warnings) {
      auto it = std::find_if(seen.begin(), seen.end(), [&](const auto& x) { return x.first == w; });
      if (it == seen.end()) it = seen.insert(seen.end(), {w, Seen{i, i, 0}});
      it->second.last = i;
      ++it->second.count;
    }
  }
  for (const auto& [w, at] : seen)
    out.warnings.push_back(w + " (step" +
                           (at.count == 1 ? " " + std::to_string(at.first)
                                          : "s " + std::to_string(at.first) + "-" +
                                                std::to_string(at.last)) +
                           ", " + std::to_string(at.count) + " of " +
                           std::to_string(out.stats.size()) + ")");
  out.placed_by = std::string(method);
  if (fell_back > 0)
    out.placed_by = fell_back == out.stats.size() ? fallback : out.placed_by + "+" + fallback;
  return out;
}

std::string default_method(const Trace& trace) {
  for (const StepGraph& g : trace.steps) {
    for (const Task& t : g.tasks)
      if (t.object != kNoObject) return "owner";
    for (const Datum& d : g.data)
      if (d.object != kNoObject) return "owner";
  }
  return "list";
}

model::CostModel NamedOptions::cost_model() const {
  return model::select_cost_model(model, calibration);
}

Options NamedOptions::options() const {
  Options o = values;
  o.objective = parse_objective(objective);
  o.scotch = parse_scotch_flavour(scotch_strategy);
  o.rebalance = parse_rebalance(rebalance);
  o.sticky_fallback = parse_sticky_fallback(sticky_fallback);
  o.order = parse_task_order(order);
  o.model = cost_model();
  return o;
}

StepPartitioner step_partitioner(std::string_view method, const Options& options,
                                 std::shared_ptr<std::vector<Stats>> calls) {
  std::shared_ptr<Strategy> strategy = make_strategy(method);
  return [strategy, options, calls](const StepGraph& g, std::uint32_t k,
                                    const StepGraph* prev_graph, const Assignment* prev) {
    Result r = strategy->partition(g, k, Previous{prev_graph, prev}, options);
    if (calls) calls->push_back(r.stats);
    return std::move(r.assignment);
  };
}

Assignment carry_over(const StepGraph& g, std::uint32_t k, const StepGraph* prev_graph,
                      const Assignment* prev, const std::vector<TaskId>* match_given) {
  if (k == 0) throw UsageError("k must be at least 1");
  if ((prev_graph == nullptr) != (prev == nullptr))
    throw UsageError("previous step: graph and assignment must be given together");
  if (prev == nullptr || prev->k != k)
    return detail::make_owner()->partition(g, k, {}, {}).assignment;
  const auto n = static_cast<TaskId>(g.tasks.size());
  Assignment a;
  a.k = k;
  a.proc.assign(n, 0);
  const std::vector<std::uint64_t> work = detail::task_work(g);
  std::vector<std::uint64_t> load(k, 0);
  std::vector<bool> placed(n, false);
  std::vector<TaskId> own;
  const std::vector<TaskId>* m = match_given;
  if (m == nullptr || m->size() != n) {
    own = match_by_key(g, *prev_graph);
    m = &own;
  }
  const std::vector<TaskId>& match = *m;
  for (TaskId t = 0; t < n; ++t)
    if (match[t] != kNoTask && match[t] < prev->proc.size()) {
      a.proc[t] = prev->proc[match[t]];
      load[a.proc[t]] += work[t];
      placed[t] = true;
    }
  detail::place_by_affinity(g, work, k, placed, a.proc, load);
  return a;
}

double loop_imbalance(const StepGraph& g, const Assignment& a, double loop_share) {
  const std::vector<std::uint64_t> work = detail::task_work(g);
  return detail::phased_imbalance(detail::loop_groups(g, work, loop_share), work, a.proc, a.k);
}

namespace detail {

std::vector<std::uint64_t> task_work(const StepGraph& g) {
  std::vector<std::uint64_t> w(g.tasks.size());
  for (TaskId t = 0; t < g.tasks.size(); ++t) w[t] = g.tasks[t].cost_ns * g.runs(t);
  return w;
}

std::vector<std::uint64_t> loads(const std::vector<std::uint64_t>& work,
                                 const std::vector<ProcId>& proc, std::uint32_t k) {
  std::vector<std::uint64_t> l(k, 0);
  for (std::size_t t = 0; t < proc.size(); ++t) l[proc[t]] += work[t];
  return l;
}

double imbalance(const std::vector<std::uint64_t>& load) {
  std::uint64_t total = 0, max = 0;
  for (std::uint64_t l : load) {
    total += l;
    max = std::max(max, l);
  }
  if (total == 0 || load.empty()) return 1.0;
  return static_cast<double>(max) * static_cast<double>(load.size()) / static_cast<double>(total);
}

LoopGroups loop_groups(const StepGraph& g, const std::vector<std::uint64_t>& work,
                       double loop_share) {
  LoopGroups lg;
  lg.group.assign(g.tasks.size(), 0);
  if (loop_share <= 0.0 || g.loops.empty()) return lg;
  std::uint64_t total = 0;
  std::vector<std::uint64_t> loop_work(g.loops.size(), 0);
  for (TaskId t = 0; t < g.tasks.size(); ++t) {
    total += work[t];
    if (g.tasks[t].loop < g.loops.size()) loop_work[g.tasks[t].loop] += work[t];
  }
  std::vector<std::uint32_t> of_loop(g.loops.size(), 0);
  for (LoopId l = 0; l < g.loops.size(); ++l)
    if (static_cast<long double>(loop_work[l]) >= loop_share * static_cast<long double>(total))
      of_loop[l] = lg.count++;
  for (TaskId t = 0; t < g.tasks.size(); ++t)
    if (g.tasks[t].loop < g.loops.size()) lg.group[t] = of_loop[g.tasks[t].loop];
  return lg;
}

double phased_imbalance(const LoopGroups& lg, const std::vector<std::uint64_t>& work,
                        const std::vector<ProcId>& proc, std::uint32_t k) {
  if (k == 0) return 1.0;
  std::vector<std::uint64_t> load(static_cast<std::size_t>(lg.count) * k, 0);
  std::uint64_t total = 0;
  for (std::size_t t = 0; t < proc.size() && t < work.size(); ++t) {
    load[static_cast<std::size_t>(lg.group[t]) * k + proc[t]] += work[t];
    total += work[t];
  }
  if (total == 0) return 1.0;
  long double sum_max = 0;
  for (std::uint32_t c = 0; c < lg.count; ++c)
    sum_max += *std::max_element(load.begin() + static_cast<std::ptrdiff_t>(c) * k,
                                 load.begin() + static_cast<std::ptrdiff_t>(c + 1) * k);
  return static_cast<double>(sum_max * k / static_cast<long double>(total));
}

void place_by_affinity(const StepGraph& g, const std::vector<std::uint64_t>& work,
                       std::uint32_t k, const std::vector<bool>& placed,
                       std::vector<ProcId>& proc, std::vector<std::uint64_t>& load) {
  const auto n = static_cast<TaskId>(g.tasks.size());
  // Only the data the unplaced tasks touch need their holders (a step carried over from the
  // previous one has few new tasks): marked first, the others never looked at again.
  constexpr std::uint32_t kUnused = UINT32_MAX;
  std::vector<std::uint32_t> slot(g.data.size(), kUnused);
  std::uint32_t used = 0;
  for (TaskId t = 0; t < n; ++t)
    if (!placed[t])
      for (const Access& acc : g.accesses_of(t))
        if (slot[acc.datum] == kUnused) slot[acc.datum] = used++;
  if (used == 0) return;
  std::vector<std::vector<ProcId>> holders(used);  // processors holding each marked datum
  auto hold = [&](TaskId t, ProcId p) {
    for (const Access& acc : g.accesses_of(t)) {
      if (slot[acc.datum] == kUnused) continue;
      auto& h = holders[slot[acc.datum]];
      if (std::find(h.begin(), h.end(), p) == h.end()) h.push_back(p);
    }
  };
  for (TaskId t = 0; t < n; ++t)
    if (placed[t]) hold(t, proc[t]);
  std::vector<std::uint64_t> score(k);
  for (TaskId t = 0; t < n; ++t) {
    if (placed[t]) continue;
    std::fill(score.begin(), score.end(), 0);
    for (const Access& acc : g.accesses_of(t))
      for (ProcId p : holders[slot[acc.datum]])
        score[p] += std::max<std::uint64_t>(g.data[acc.datum].bytes, 1);
    ProcId best = static_cast<ProcId>(std::min_element(load.begin(), load.end()) - load.begin());
    for (ProcId p = 0; p < k; ++p)
      if (score[p] > score[best] || (score[p] == score[best] && load[p] < load[best])) best = p;
    proc[t] = best;
    load[best] += work[t];
    hold(t, best);
  }
}

std::optional<Result> library_trivial_case(const StepGraph& g, std::uint32_t k) {
  const auto n = static_cast<std::uint32_t>(g.tasks.size());
  if (k != 1 && n != 0 && k < n) return std::nullopt;
  Result r;
  if (k == 1 || n == 0) {
    r.assignment.k = k;
    r.assignment.proc.assign(n, 0);
    r.stats.edgecut = 0;
  } else {
    r.assignment = one_task_per_processor(g, k);
    r.stats.edgecut = edgecut(library_graph(g), r.assignment.proc);
  }
  return r;
}

Assignment one_task_per_processor(const StepGraph& g, std::uint32_t k) {
  Assignment a;
  a.k = k;
  a.proc.resize(g.tasks.size());
  for (TaskId t = 0; t < g.tasks.size(); ++t) a.proc[t] = t % k;
  return a;
}

}  // namespace detail
}  // namespace tgraph::partition
