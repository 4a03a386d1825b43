// SPDX-License-Identifier: MIT
// The distributed replay: per step a schedule (schedule.cpp), plans kept across steps, and
// one StepRun per rank (step_run.cpp: threads that run the schedule and a communication
// engine that posts persistent requests and polls them; OpenMPI has no asynchronous progress
// here: waiting threads drive it); counters and checks gathered at rank 0.
//
// Built with SimGrid's smpicxx (TGRAPH_SMPI, scripts/smpi-build) the same schedule runs on
// the simulated platform of `smpirun`: SMPI gives MPI_THREAD_SINGLE and charges simulated
// time only to MPI calls and to explicit executions, so each rank runs its one processor's
// program on the main thread, blocks in MPI_Waitsome where the threads would poll, charges
// each task's recorded cost as flops on its host (1 flop per ns, the cost model of
// model::platform_xml, as SimGrid's model::simulate_trace) and reads the simulated
// clock.
#include "tgraph/mpi/replay.hpp"

#include <mpi.h>
#ifdef TGRAPH_SMPI
#include <smpi/smpi.h>
#endif

#include <algorithm>
#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <unordered_map>

#include "tgraph/graph/error.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/observer.hpp"
#include "run_common.hpp"
#include "step_run.hpp"

namespace tgraph::mpi {

replay::SyntheticOptions RankWorkload::options(double touch_ns_per_byte) {
  replay::SyntheticOptions o;
  o.fraction_ns_per_byte = touch_ns_per_byte;
  o.spin = false;  // run() spins to the task's deadline by the clock
  return o;
}

void RankWorkload::set_step(const StepGraph& step) {
  step_ = &step;
  inner_.set_step(step);
}

void RankWorkload::run(const replay::TaskRun& r) {
  const std::int64_t t0 = replay::now_ns();
  inner_.run(r);
  if (r.origin == kNoTask || step_ == nullptr) return;
  const double cost = static_cast<double>(step_->tasks[r.origin].cost_ns) * scale_;
#ifdef TGRAPH_SMPI
  // The data pass above is real work that SMPI does not time (smpirun with the configuration
  // smpi/simulate-computation:no); the task's recorded cost is what the host executes.
  (void)t0;
  if (cost > 0) smpi_execute_flops(cost);
#else
  // By the clock, in slices of at most 1 us at the calibrated rate: a task takes its recorded
  // time (or its data pass, when that is longer) whatever this process's spin rate does
  // meanwhile (another rank's load, a misjudged calibration).
  const std::int64_t deadline = t0 + static_cast<std::int64_t>(cost);
  const double rate = replay::SyntheticWorkload::calibration().spin_iterations_per_ns;
  for (std::int64_t now = replay::now_ns(); now < deadline; now = replay::now_ns()) {
    const double slice = std::min(static_cast<double>(deadline - now), 1000.0);
    volatile std::uint64_t sink =
        replay::spin_iterations(static_cast<std::uint64_t>(slice * rate) + 1, r.origin + 1);
    (void)sink;
  }
#endif
}

void RankWorkload::run_host(const StepGraph& step) {
#ifdef TGRAPH_SMPI
  if (step.host_ns > 0) smpi_execute_flops(static_cast<double>(step.host_ns) * scale_);
#else
  inner_.run_host(step);
#endif
}

std::span<std::uint64_t> RankWorkload::mutable_words(DatumId d) {
  const auto w = inner_.words(d);
  // The buffer is this workload's own, allocated non-const (SyntheticWorkload::first_touch).
  return {const_cast<std::uint64_t*>(w.data()), w.size()};
}

std::uint64_t datum_hash(DatumId d, std::span<const std::uint64_t> words) {
  std::uint64_t h =
      1469598103934665603ull ^ (static_cast<std::uint64_t>(d) * 0x9e3779b97f4a7c15ull);
  for (std::uint64_t w : words) h = (h ^ w) * 1099511628211ull;
  return h ^ (h >> 29);
}

MpiReplayResult replay_distributed(const Trace& trace, const TraceAssignment& assignment,
                                   const MpiReplayOptions& options) {
  if (options.policy == MpiPolicy::kStarpuMpi)
    return replay_starpu_mpi(trace, assignment, options);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const auto me = static_cast<std::uint32_t>(rank);
  std::size_t steps = 0;
  const Layout layout = checked_layout(trace, assignment, options, steps);

  MpiReplayResult result;
  result.ranks = layout.ranks;
  result.threads_per_rank = layout.threads_per_rank;
  const double touch_ns_per_byte = shared_touch_rate();
  RankWorkload w(touch_ns_per_byte);
  PlanCache plans;
  Holders holders = everywhere(0, layout.ranks);
  RepartitionWatch watch;
  for (std::size_t si = 0; si < steps; ++si) {
    const StepGraph& step = trace.steps[si];
    PreparedStep prepared = prepare_step(trace, assignment, si, layout, plans, w, holders, watch);
    Plan* plan = prepared.plan;
    const StepSchedule& s = prepared.schedule;
    const std::optional<std::uint32_t> drop = si == 0 ? options.test_drop_message : std::nullopt;
    MpiStepResult sr;
    sr.predicted = s.traffic;
    sr.repartitioned = prepared.repartitioned;
    const std::int64_t t0 = start_step(step, options, w);
    StepRun run(*plan, s, w, me, layout, drop);
    const Counters c = run.run(static_cast<std::int64_t>(options.watchdog_s * 1e9));
    // SMPI's clock is one simulated clock for every rank: the step ends when the last rank's
    // work ends, before the counters' reduction below (3 R^2 words through a tree: 0.38 ms
    // at 64 ranks on a 4 x 16 platform, time the simulator does not model). With a real MPI
    // (one clock per process) the step ends on rank 0 after that reduction.
    std::int64_t last_end = 0;
    if constexpr (kSingleThreaded) {
      const std::int64_t end = now_ns();
      MPI_Reduce(&end, &last_end, 1, MPI_INT64_T, MPI_MAX, 0, MPI_COMM_WORLD);
    }
    std::vector<std::uint64_t> sums = {static_cast<std::uint64_t>(c.local_wait_ns),
                                       static_cast<std::uint64_t>(c.message_wait_ns),
                                       static_cast<std::uint64_t>(c.decision_wait_ns),
                                       static_cast<std::uint64_t>(c.received),
                                       static_cast<std::uint64_t>(c.hidden),
                                       static_cast<std::uint64_t>(c.decisions_received),
                                       static_cast<std::uint64_t>(c.decision_latency_ns)};
    static_assert(kCounters == 7);
    const Traffic& m = run.measured();
    sums.insert(sums.end(), m.messages.begin(), m.messages.end());
    sums.insert(sums.end(), m.bytes.begin(), m.bytes.end());
    sums.insert(sums.end(), m.decisions.begin(), m.decisions.end());
    sums.push_back(m.entering_messages);
    sums.push_back(m.entering_bytes);
    sum_to_root(sums);
    sr.wall_ns = (kSingleThreaded ? last_end : now_ns()) - t0;
    holders = s.holders_after;
    if (me != 0) continue;
    sr.local_wait_ns = static_cast<std::int64_t>(sums[0]);
    sr.message_wait_ns = static_cast<std::int64_t>(sums[1]);
    sr.decision_wait_ns = static_cast<std::int64_t>(sums[2]);
    sr.received = sums[3];
    sr.hidden = sums[4];
    sr.decisions_received = sums[5];
    sr.decision_latency_ns = static_cast<std::int64_t>(sums[6]);
    const std::size_t R2 = static_cast<std::size_t>(layout.ranks) * layout.ranks;
    sr.measured = Traffic(layout.ranks);
    for (std::size_t i = 0; i < R2; ++i) {
      sr.measured.messages[i] = sums[kCounters + i];
      sr.measured.bytes[i] = sums[kCounters + R2 + i];
      sr.measured.decisions[i] = sums[kCounters + 2 * R2 + i];
    }
    sr.measured.entering_messages = sums[kCounters + 3 * R2];
    sr.measured.entering_bytes = sums[kCounters + 3 * R2 + 1];
    sr.migrated_bytes = sr.repartitioned ? sr.measured.entering_bytes : 0;
    result.wall_ns += sr.wall_ns;
    result.steps.push_back(std::move(sr));
  }

  // The checksum: each original datum from the lowest rank holding its latest version.
  const std::size_t n_orig = steps > 0 ? trace.steps[steps - 1].data.size() : 0;
  std::uint64_t part = 0;
  for (DatumId d = 0; d < n_orig; ++d)
    if (holders.first(d) == me) part += datum_hash(d, w.words(d));
  std::vector<std::uint64_t> sum = {part};
  sum_to_root(sum);
  result.checksum = sum[0];

  sequential_reference(trace, steps, options, touch_ns_per_byte, result);
  return result;
}

}  // namespace tgraph::mpi
