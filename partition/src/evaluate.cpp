// SPDX-License-Identifier: MIT
#include "tgraph/partition/evaluate.hpp"

#include <algorithm>
#include <optional>
#include <unordered_map>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/metrics.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/model/simulator.hpp"
#include "tgraph/partition/assignment_io.hpp"
#include "tgraph/partition/strategy.hpp"

namespace tgraph::partition {

namespace {

// CW groups (maximal runs of cumulative writes to one datum, within one loop level) whose
// writers run on more than one processor: each needs a reducer, per execution.
std::uint64_t count_reducers(const StepGraph& g, const Assignment& a) {
  struct Group {
    bool open = false;
    LoopId loop = kNoLoop;
    ProcId first = 0;
    bool spans = false;
  };
  std::vector<Group> group(g.data.size());
  std::uint64_t reducers = 0;
  auto close = [&](Group& gr) {
    if (gr.open && gr.spans) reducers += gr.loop == kNoLoop ? 1 : g.loops[gr.loop].iterations;
    gr = Group{};
  };
  for (TaskId t = 0; t < g.tasks.size(); ++t)
    for (const Access& acc : g.accesses_of(t)) {
      Group& gr = group[acc.datum];
      if (acc.mode != AccessMode::CW) {
        close(gr);
        continue;
      }
      if (gr.open && gr.loop != g.tasks[t].loop) close(gr);
      if (!gr.open) {
        gr.open = true;
        gr.loop = g.tasks[t].loop;
        gr.first = a.proc[t];
      } else if (a.proc[t] != gr.first) {
        gr.spans = true;
      }
    }
  for (Group& gr : group) close(gr);
  return reducers;
}

// Cycles and ping-pong pairs of the processor graph of intra-step cross dependencies.
void quotient(const QuotientGraph& qg, std::uint32_t k, StepReport& r) {
  std::vector<std::uint8_t> adj(static_cast<std::size_t>(k) * k, 0);
  for (const QuotientEdge& e : qg.edges)
    if (e.deps > 0) adj[static_cast<std::size_t>(e.from) * k + e.to] = 1;
  r.ping_pong_pairs = 0;
  for (ProcId p = 0; p < k; ++p)
    for (ProcId q = p + 1; q < k; ++q)
      if (adj[static_cast<std::size_t>(p) * k + q] && adj[static_cast<std::size_t>(q) * k + p]) ++r.ping_pong_pairs;
  std::vector<std::uint32_t> indeg(k, 0);
  for (ProcId p = 0; p < k; ++p)
    for (ProcId q = 0; q < k; ++q) indeg[q] += adj[static_cast<std::size_t>(p) * k + q];
  std::vector<ProcId> stack;
  for (ProcId p = 0; p < k; ++p)
    if (indeg[p] == 0) stack.push_back(p);
  std::uint32_t removed = 0;
  while (!stack.empty()) {
    const ProcId p = stack.back();
    stack.pop_back();
    ++removed;
    for (ProcId q = 0; q < k; ++q)
      if (adj[static_cast<std::size_t>(p) * k + q] && --indeg[q] == 0) stack.push_back(q);
  }
  r.quotient_acyclic = removed == k;
}

void migrations(const StepGraph& g, const Assignment& a, const StepGraph& prev,
                const Assignment& prev_a, StepReport& r) {
  const std::vector<TaskId> match = match_by_key(g, prev);
  std::vector<DatumId> seen;
  for (TaskId t = 0; t < g.tasks.size(); ++t) {
    if (match[t] == kNoTask || prev_a.proc[match[t]] == a.proc[t]) continue;
    ++r.migrated_tasks;
    seen.clear();
    for (const Access& acc : g.accesses_of(t))
      if (std::find(seen.begin(), seen.end(), acc.datum) == seen.end()) {
        seen.push_back(acc.datum);
        r.migrated_bytes += g.data[acc.datum].bytes;
      }
  }
}

// Load, imbalance and the predicted makespan of `a` with each task's robust cost.
void robust_figures(const StepGraph& g, const Assignment& a, const std::vector<std::uint64_t>& costs,
                    const model::CostModel& model, std::optional<std::uint64_t> serial_ns,
                    StepReport& r) {
  StepGraph robust = g;
  for (TaskId t = 0; t < robust.tasks.size(); ++t) robust.tasks[t].cost_ns = costs[t];
  std::vector<std::uint64_t> load(a.k, 0);
  for (TaskId t = 0; t < robust.tasks.size(); ++t)
    load[a.proc[t]] += robust.tasks[t].cost_ns * robust.runs(t);
  for (std::uint64_t l : load) {
    r.robust_work_ns += l;
    r.robust_max_load_ns = std::max(r.robust_max_load_ns, l);
  }
  r.robust_imbalance = r.robust_work_ns == 0 ? 1.0
                                             : static_cast<double>(r.robust_max_load_ns) * a.k /
                                                   static_cast<double>(r.robust_work_ns);
  r.robust_makespan_ns = model::simulate(robust, a, model, serial_ns).makespan_ns;
  r.robust_speedup = r.robust_makespan_ns == 0
                         ? 1.0
                         : static_cast<double>(r.robust_work_ns + g.host_ns) /
                               static_cast<double>(r.robust_makespan_ns);
}

StepReport evaluate_step(const StepGraph& g, const Assignment& a, const model::CostModel& model,
                         std::optional<std::uint64_t> serial_ns,
                         const std::vector<std::uint64_t>& robust_costs) {
  StepReport r;
  r.tasks = g.tasks.size();
  const QuotientGraph q = quotient_graph(g, a);
  for (std::uint64_t l : q.load_ns) {
    r.work_ns += l;
    r.max_load_ns = std::max(r.max_load_ns, l);
  }
  r.imbalance = r.work_ns == 0 ? 1.0
                               : static_cast<double>(r.max_load_ns) * a.k / static_cast<double>(r.work_ns);
  for (const QuotientEdge& e : q.edges) {
    r.cut_edges += e.deps + e.carried_deps;
    r.cut_bytes += e.bytes;
  }
  r.reducers = count_reducers(g, a);
  quotient(q, a.k, r);

  const model::Schedule s = model::simulate(g, a, model, serial_ns);
  r.makespan_ns = s.makespan_ns;
  r.signals = s.signals;
  r.waits = s.waits;
  r.transfer_bytes = s.transfer_bytes;
  const Metrics m = compute_metrics(g);
  r.span_ns = m.span_ns;
  r.host_ns = g.host_ns;
  r.lower_bound_ns = step_lower_bound_ns(g.host_ns, r.work_ns, m.span_ns, a.k);
  r.speedup = r.makespan_ns == 0 ? 1.0
                                 : static_cast<double>(r.work_ns + r.host_ns) /
                                       static_cast<double>(r.makespan_ns);
  robust_figures(g, a, robust_costs, model, serial_ns, r);
  return r;
}

}  // namespace

void check_fits(const Trace& trace, const TraceAssignment& a, const std::string& a_name) {
  if (a.steps.size() != trace.steps.size())
    throw InputError(a_name, std::nullopt,
                     "has " + std::to_string(a.steps.size()) + " steps, the trace has " +
                         std::to_string(trace.steps.size()));
  for (std::size_t s = 0; s < a.steps.size(); ++s)
    if (std::string why = validate(trace.steps[s], a.steps[s], a.k); !why.empty())
      throw InputError(a_name, std::nullopt, "step " + std::to_string(s) + ": " + why);
}

Report evaluate(const Trace& trace, const TraceAssignment& a, const model::CostModel& model,
                const std::string& a_name, const std::vector<std::uint64_t>* serial_ns) {
  check_fits(trace, a, a_name);
  Report rep;
  rep.method = a.method;
  rep.k = a.k;
  rep.model = model.source;
  StepReport& tot = rep.total;
  double sum_mean_load = 0.0, sum_robust_mean_load = 0.0, sum_partition_ms = 0.0;
  tot.quotient_acyclic = true;
  const std::vector<std::vector<std::uint64_t>> robust = robust_costs(trace.steps);
  for (std::size_t s = 0; s < trace.steps.size(); ++s) {
    StepReport r;
    try {
      std::optional<std::uint64_t> serial;
      if (serial_ns != nullptr && s < serial_ns->size()) serial = (*serial_ns)[s];
      r = evaluate_step(trace.steps[s], a.steps[s], model, serial, robust[s]);
    } catch (const InputError&) {
      throw;
    } catch (const Error& e) {
      throw InputError(a_name, std::nullopt, "step " + std::to_string(s) + ": " + e.what());
    }
    if (s > 0) migrations(trace.steps[s], a.steps[s], trace.steps[s - 1], a.steps[s - 1], r);
    if (s < a.partition_ms.size()) r.partition_ms = a.partition_ms[s];
    tot.tasks += r.tasks;
    tot.cut_edges += r.cut_edges;
    tot.cut_bytes += r.cut_bytes;
    tot.signals += r.signals;
    tot.waits += r.waits;
    tot.reducers += r.reducers;
    tot.transfer_bytes += r.transfer_bytes;
    tot.max_load_ns += r.max_load_ns;
    tot.work_ns += r.work_ns;
    tot.span_ns += r.span_ns;
    tot.host_ns += r.host_ns;
    tot.lower_bound_ns += r.lower_bound_ns;
    tot.makespan_ns += r.makespan_ns;
    tot.migrated_tasks += r.migrated_tasks;
    tot.migrated_bytes += r.migrated_bytes;
    tot.partition_ms += r.partition_ms;
    tot.ping_pong_pairs += r.ping_pong_pairs;
    tot.robust_work_ns += r.robust_work_ns;
    tot.robust_max_load_ns += r.robust_max_load_ns;
    tot.robust_makespan_ns += r.robust_makespan_ns;
    sum_robust_mean_load += static_cast<double>(r.robust_work_ns) / a.k;
    tot.quotient_acyclic = tot.quotient_acyclic && r.quotient_acyclic;
    if (!r.quotient_acyclic) ++rep.cyclic_steps;
    rep.imbalance_max = std::max(rep.imbalance_max, r.imbalance);
    sum_mean_load += static_cast<double>(r.work_ns) / a.k;
    sum_partition_ms += r.partition_ms;
    rep.steps.push_back(r);
  }
  rep.model_terms =
      model::model_terms(model, serial_ns != nullptr && !serial_ns->empty(), tot.host_ns > 0);
  tot.imbalance = sum_mean_load > 0 ? static_cast<double>(tot.max_load_ns) / sum_mean_load : 1.0;
  const double sequential = static_cast<double>(tot.work_ns + tot.host_ns);
  tot.speedup = tot.makespan_ns == 0 ? 1.0 : sequential / static_cast<double>(tot.makespan_ns);
  tot.robust_imbalance = sum_robust_mean_load > 0
                             ? static_cast<double>(tot.robust_max_load_ns) / sum_robust_mean_load
                             : 1.0;
  tot.robust_speedup = tot.robust_makespan_ns == 0
                           ? 1.0
                           : static_cast<double>(tot.robust_work_ns + tot.host_ns) /
                                 static_cast<double>(tot.robust_makespan_ns);
  const double with_partitioning = static_cast<double>(tot.makespan_ns) + sum_partition_ms * 1e6;
  rep.speedup_with_partitioning = with_partitioning <= 0 ? 1.0 : sequential / with_partitioning;
  return rep;
}

QuotientGraph step_quotient(const StepGraph& g, const Assignment& a) {
  const model::Schedule s =
      model::simulate(g, a, model::CostModel::ideal());  // checks that `a` fits `g`
  QuotientGraph q = quotient_graph(g, a);
  std::vector<QuotientEdge> edges;  // every (from, to) in order: q.edges merged with the waits
  std::size_t i = 0;
  for (ProcId from = 0; from < a.k; ++from)
    for (ProcId to = 0; to < a.k; ++to) {
      const std::uint64_t n = s.waits_between[static_cast<std::size_t>(from) * a.k + to];
      if (i < q.edges.size() && q.edges[i].from == from && q.edges[i].to == to) {
        edges.push_back(q.edges[i++]);
        edges.back().signals = n;
      } else if (n > 0) {
        edges.push_back({from, to, 0, 0, 0, n});
      }
    }
  q.edges = std::move(edges);
  return q;
}

std::string evaluate_files(const std::string& trace, const std::string& assignment,
                           const model::CostModel& model, const model::SerialWork& serial,
                           bool json) {
  const Trace t = read_trace(trace);
  const TraceAssignment as = load_assignment(assignment, t, trace);
  const std::vector<std::uint64_t> per_step = serial.per_step(t.steps.size());
  const Report rep = evaluate(t, as, model, assignment, per_step.empty() ? nullptr : &per_step);
  return json ? report_json(rep) + "\n" : report_text(rep);
}

}  // namespace tgraph::partition
