// SPDX-License-Identifier: MIT
#include "tgraph/replay/program_workload.hpp"

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/lowering.hpp"

namespace tgraph::replay {

ProgramWorkload::ProgramWorkload(std::span<const std::function<void()>> bodies,
                                 std::span<const std::function<bool()>> conditions,
                                 std::span<const Accumulator* const> accumulators) {
  set_program(bodies, conditions, accumulators);
}

void ProgramWorkload::set_program(std::span<const std::function<void()>> bodies,
                                  std::span<const std::function<bool()>> conditions,
                                  std::span<const Accumulator* const> accumulators) {
  bodies_ = bodies;
  conditions_ = conditions;
  accumulators_ = accumulators;
  reducible_.resize(accumulators.size());
  for (std::size_t d = 0; d < accumulators.size(); ++d) reducible_[d] = accumulators[d] != nullptr;
}

void ProgramWorkload::bind(const ExecGraph& exec) {
  exec_ = &exec;
  const std::size_t nd = exec.graph.data.size();
  temps_.assign(nd, nullptr);
  redirected_.assign(exec.graph.tasks.size(), 0);
  for (TaskId t = 0; t < exec.graph.tasks.size(); ++t)
    for (const Access& a : exec.graph.accesses_of(t))
      if (exec.datum_origin[a.datum] != a.datum && exec.origin[t] != kNoTask) redirected_[t] = 1;
}

bool ProgramWorkload::needs_touch(DatumId d) const {
  return exec_ != nullptr && d < temps_.size() && exec_->datum_origin[d] != d && !temps_[d];
}

void ProgramWorkload::first_touch(DatumId d) {
  const DatumId origin = exec_->datum_origin[d];
  const Accumulator* acc = origin < accumulators_.size() ? accumulators_[origin] : nullptr;
  if (acc == nullptr)
    throw UsageError("live run: datum '" + exec_->graph.data[origin].name +
                     "' was lowered to temporaries but has no accumulator");
  temps_[d] = acc->make_zero();  // on the thread that owns the temporary
}

void ProgramWorkload::checked_run(const TaskRun& r) {
  const ExecGraph& x = *r.exec;
  if (r.origin == kNoTask || redirected_[r.task])
    throw UsageError("live run: verifying accesses needs cumulative writes serialised "
                     "(CwMode::kSerialize), not lowered to temporaries and reducers");
  const auto& body = bodies_[r.origin];
  if (!body) return;
  const std::span<const Access> acc = x.graph.accesses_of(r.task);
  const bool reads = r.iteration < 2 || r.iteration % 8 == 0;
  std::vector<AccessChecker::Found> found;
  {
    std::unique_lock<std::mutex> lock = checker_->lock();  // one body at a time
    auto run = [&body] { body(); };
    checker_->run(acc, BodyRef(run), reads, found);
  }
  for (const AccessChecker::Found& f : found)
    findings_->add(finding(task_label(x.graph, r.task), f, x.graph.data));
}

bool ProgramWorkload::checked_stop_after(LoopId loop) {
  const ExecGraph& x = *exec_;
  bool stop = false;
  std::vector<AccessChecker::Found> found;
  {
    std::unique_lock<std::mutex> lock = checker_->lock();
    const Access acc{x.graph.loops[loop].condition, AccessMode::R};
    auto evaluate = [this, loop, &stop] { stop = conditions_[loop](); };
    checker_->run({&acc, 1}, BodyRef(evaluate), false, found);
  }
  for (const AccessChecker::Found& f : found)
    findings_->add(finding("loop.break of loop " + std::to_string(loop), f, x.graph.data));
  return stop;
}

void ProgramWorkload::run(const TaskRun& r) {
  if (checker_ != nullptr) [[unlikely]] {
    checked_run(r);
    return;
  }
  const ExecGraph& x = *r.exec;
  if (r.origin == kNoTask) {  // a reducer: target += temps, in the lowering's order
    const Reduction& red = x.reductions[x.reduction[r.task]];
    const Accumulator* acc = accumulators_[red.target];
    for (DatumId t : red.temps) acc->add_and_clear(acc->target, temps_[t].get());
    return;
  }
  const auto& body = bodies_[r.origin];
  if (!body) return;
  if (!redirected_[r.task]) {
    body();
    return;
  }
  // At most a handful of CW accesses per task: redirect them for the body's duration.
  Redirect redirects[16];
  std::size_t n = 0;
  for (const Access& a : x.graph.accesses_of(r.task)) {
    const DatumId origin = x.datum_origin[a.datum];
    if (origin == a.datum || n == 16) continue;
    redirects[n++] =
        Redirect{accumulators_[origin]->target, temps_[x.datum_on(a.datum, r.thread)].get()};
  }
  RedirectScope scope({redirects, n});
  body();
}

bool ProgramWorkload::stop_after(LoopId loop, std::uint32_t) {
  if (checker_ != nullptr) [[unlikely]]
    return checked_stop_after(loop);
  return conditions_[loop]();
}

}  // namespace tgraph::replay
