// SPDX-License-Identifier: MIT
#include "run_common.hpp"

#include <algorithm>
#include <chrono>
#include <string>
#include <thread>

#include "tgraph/graph/error.hpp"
#include "tgraph/replay/executor.hpp"

namespace tgraph::mpi {

Layout checked_layout(const Trace& trace, const TraceAssignment& assignment,
                      const MpiReplayOptions& options, std::size_t& steps) {
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  Layout layout{static_cast<std::uint32_t>(size), options.threads_per_rank};
  if (kSingleThreaded && layout.threads_per_rank != 1)
    throw OptionError("threads_per_rank", "an SMPI build runs one processor per rank (found " +
                                              std::to_string(layout.threads_per_rank) + ")");
  if (assignment.k != layout.processors())
    throw OptionError("threads_per_rank",
                      "ranks x {threads_per_rank} = " + std::to_string(layout.processors()) +
                          " but the assignment has " + std::to_string(assignment.k) +
                          " processors");
  steps = std::min<std::size_t>(trace.steps.size(), options.steps.value_or(trace.steps.size()));
  if (assignment.steps.size() < steps)
    throw UsageError("the assignment has fewer steps than the trace");
  return layout;
}

Assignment step_assignment(const Trace& trace, const TraceAssignment& assignment,
                           std::size_t si, const Layout& layout) {
  Assignment a = assignment.steps[si];
  if (std::string why = validate(trace.steps[si], a, layout.processors()); !why.empty())
    throw UsageError("step " + std::to_string(si) + ": " + why);
  a.order.clear();
  return a;
}

Plan& PlanCache::get(const StepGraph& step, const Assignment& a, bool& created) {
  const std::uint64_t hash = step.structural_hash();
  created = false;
  for (auto& p : plans_)
    if (p->hash == hash && p->proc == a.proc && p->structure.same_structure(step)) return *p;
  // Between steps no request is active, so freeing a plan's requests is safe.
  if (plans_.size() >= kMaxPlans) {
    const auto victim = std::find_if(plans_.begin(), plans_.end(),
                                     [&](const auto& q) { return q.get() != bound; });
    if (victim != plans_.end()) plans_.erase(victim);
  }
  auto p = std::make_unique<Plan>();
  p->structure = step;
  p->proc = a.proc;
  p->hash = hash;
  p->exec = lower(step, &a, CwMode::kReduce, ReduceScope::kPerProcessor);
  created = true;
  plans_.push_back(std::move(p));
  return *plans_.back();
}

bool RepartitionWatch::moved(const StepGraph& step, const Assignment& a) {
  bool moved = false;
  std::unordered_map<StableKey, ProcId> owner;
  for (TaskId t = 0; t < step.tasks.size(); ++t) {
    owner[step.tasks[t].key] = a.proc[t];
    const auto it = previous_.find(step.tasks[t].key);
    moved = moved || (it != previous_.end() && it->second != a.proc[t]);
  }
  previous_ = std::move(owner);
  return moved;
}

PreparedStep prepare_step(const Trace& trace, const TraceAssignment& assignment, std::size_t si,
                          const Layout& layout, PlanCache& plans, RankWorkload& w,
                          Holders& holders, RepartitionWatch& watch) {
  const StepGraph& step = trace.steps[si];
  const Assignment a = step_assignment(trace, assignment, si, layout);
  bool created = false;
  PreparedStep p;
  p.plan = &plans.get(step, a, created);
  w.set_step(step);
  const std::size_t known = holders.has.size() / layout.ranks;
  holders.grow(std::max(known, step.data.size()), known);
  p.rebound = p.plan != plans.bound;
  if (p.rebound) {
    w.bind(p.plan->exec);
    plans.bound = p.plan;
  }
  for (DatumId d = 0; d < p.plan->exec.graph.data.size(); ++d)
    if (w.needs_touch(d)) {
      w.first_touch(d);
      if (d < step.data.size())
        for (std::uint32_t r = 0; r < layout.ranks; ++r) holders.has[d * layout.ranks + r] = 1;
    }
  p.schedule = schedule_step(p.plan->exec, step, layout, holders, p.plan->channels);
  p.repartitioned = watch.moved(step, a);
  return p;
}

std::int64_t start_step(const StepGraph& step, const MpiReplayOptions& options, RankWorkload& w) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Barrier(MPI_COMM_WORLD);
  const std::int64_t t0 = now_ns();
  if (options.host_work) {
    if (rank == 0) w.run_host(step);
    MPI_Barrier(MPI_COMM_WORLD);
  }
  return t0;
}

void sum_to_root(std::vector<std::uint64_t>& v) {
  std::vector<std::uint64_t> out(v.size(), 0);
  MPI_Reduce(v.data(), out.data(), static_cast<int>(v.size()), MPI_UINT64_T, MPI_SUM, 0,
             MPI_COMM_WORLD);
  v = std::move(out);
}

void quiet_barrier() {
  if constexpr (kSingleThreaded) {
    MPI_Barrier(MPI_COMM_WORLD);
    return;
  }
  MPI_Request r;
  MPI_Ibarrier(MPI_COMM_WORLD, &r);
  int flag = 0;
  for (;;) {
    MPI_Test(&r, &flag, MPI_STATUS_IGNORE);
    if (flag) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

double shared_touch_rate() {
  double touch_ns_per_byte = replay::SyntheticWorkload::calibration().touch_ns_per_byte;
  MPI_Bcast(&touch_ns_per_byte, 1, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  return touch_ns_per_byte;
}

void sequential_reference(const Trace& trace, std::size_t steps, const MpiReplayOptions& options,
                          double touch_ns_per_byte, MpiReplayResult& result) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0) {
    auto seq = replay::make_executor(replay::Policy::kSequential, {});
    RankWorkload sw(touch_ns_per_byte);
    for (std::size_t si = 0; si < steps; ++si) {
      sw.set_step(trace.steps[si]);
      const std::int64_t t0 = now_ns();
      if (options.host_work) sw.run_host(trace.steps[si]);
      seq->run_step(trace.steps[si], nullptr, sw);
      result.steps[si].sequential_ns = now_ns() - t0;
      result.sequential_ns += result.steps[si].sequential_ns;
    }
    const std::size_t n_orig = steps > 0 ? trace.steps[steps - 1].data.size() : 0;
    std::uint64_t h = 0;
    for (DatumId d = 0; d < n_orig; ++d) h += datum_hash(d, sw.words(d));
    result.sequential_checksum = h;
    if (options.check) result.identical = h == result.checksum;
  }
  quiet_barrier();
}

}  // namespace tgraph::mpi
