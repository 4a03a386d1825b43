// SPDX-License-Identifier: MIT
// A trace's steps replayed across MPI ranks (`tgraph-mpi replay`): each rank runs its
// processors' tasks on threads with replay's synthetic bodies, datum versions travel as MPI
// messages on persistent channels, loop decisions go to the ranks that run the loop.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/mpi/schedule.hpp"
#include "tgraph/replay/synthetic.hpp"

namespace tgraph::mpi {

/// Replay's synthetic bodies with the data pass made independent of the process's own
/// calibration (SyntheticWorkload sizes a short task's pass from it, and every rank is its
/// own process): a task passes over the part of its data that the in-cache touch rate
/// `touch_ns_per_byte` (one value for every rank: rank 0's, broadcast) lets fit in its
/// recorded cost, as the threaded replay's bodies do, then spins by the clock until that
/// cost has passed since the task began. The distributed run and the sequential reference
/// both use it.
class RankWorkload : public replay::Workload {
 public:
  explicit RankWorkload(double touch_ns_per_byte) : inner_(options(touch_ns_per_byte)) {}
  /// The step the next run replays (kept by pointer).
  void set_step(const StepGraph& step);
  void bind(const ExecGraph& exec) override { inner_.bind(exec); }
  bool needs_touch(DatumId d) const override { return inner_.needs_touch(d); }
  void first_touch(DatumId d) override { inner_.first_touch(d); }
  void run(const replay::TaskRun& r) override;
  /// The step's serial host work (spun; charged to the simulated host in an SMPI build).
  void run_host(const StepGraph& step);
  bool stop_after(LoopId loop, std::uint32_t iteration) override {
    return inner_.stop_after(loop, iteration);
  }
  std::optional<std::uint32_t> known_iterations(LoopId loop) const override {
    return inner_.known_iterations(loop);
  }
  /// Words of exec datum d (empty before first touch).
  std::span<const std::uint64_t> words(DatumId d) const { return inner_.words(d); }
  /// The same words, to receive a version into (the buffer belongs to this workload).
  std::span<std::uint64_t> mutable_words(DatumId d);

 private:
  static replay::SyntheticOptions options(double touch_ns_per_byte);
  replay::SyntheticWorkload inner_;
  const StepGraph* step_ = nullptr;
  double scale_ = 1.0;
};

/// A checksum of data [0, n) of `w`: the sum of one hash per datum (order-free, so ranks can
/// add their parts).
std::uint64_t datum_hash(DatumId d, std::span<const std::uint64_t> words);

/// Who runs the graph across the ranks.
enum class MpiPolicy : std::uint8_t {
  /// tgraph's own schedule: persistent channels per (datum version, receiving rank), threads
  /// that poll, reductions summed in processor order.
  kPartition,
  /// The peer: StarPU-MPI (starpu_mpi_task_insert on every rank, the task on its processor's
  /// rank and worker, each datum owned by the rank of its first writer in the step,
  /// starpu_mpi_data_migrate when that changes). Built when pkg-config starpumpi-1.3 is found.
  kStarpuMpi,
};

/// Options of a distributed replay.
struct MpiReplayOptions {
  MpiPolicy policy = MpiPolicy::kPartition;
  std::uint32_t threads_per_rank = 1;
  std::optional<std::uint32_t> steps;  ///< first N steps (default all)
  bool check = false;                  ///< also run the sequential replay on rank 0, compare
  /// Each step's serial host work (StepGraph::host_ns) runs on rank 0 before any task, every
  /// rank waiting for it (a barrier), as in `tgraph replay` and both simulators; the
  /// sequential reference then includes it too.
  bool host_work = false;
  double watchdog_s = 60;              ///< no progress this long: name the wait, MPI_Abort(1)
  /// Testing only: this message (index in the first step's schedule) is never sent, so its
  /// receiver waits until the watchdog fires.
  std::optional<std::uint32_t> test_drop_message;
};

/// What one step cost (on rank 0: every rank's figures added up).
struct MpiStepResult {
  std::int64_t wall_ns = 0;
  Traffic measured, predicted;
  std::int64_t local_wait_ns = 0;     ///< threads blocked on tasks of their own rank
  std::int64_t message_wait_ns = 0;   ///< threads blocked on datum versions from other ranks
  std::int64_t decision_wait_ns = 0;  ///< threads blocked on loop decisions from other ranks
  std::uint64_t received = 0;         ///< datum versions received
  std::uint64_t hidden = 0;           ///< of them, arrived before a thread needed them
  std::uint64_t decisions_received = 0;
  std::int64_t decision_latency_ns = 0;  ///< sum over received decisions: made -> known here
  std::uint64_t migrated_bytes = 0;      ///< entering bytes when the step was repartitioned
  bool repartitioned = false;            ///< a task of the previous step (same stable key) moved
  std::int64_t sequential_ns = 0;        ///< rank 0's sequential replay of the step (with check)
};

/// The whole run (meaningful on rank 0).
struct MpiReplayResult {
  MpiPolicy policy = MpiPolicy::kPartition;
  std::uint32_t ranks = 1, threads_per_rank = 1;
  /// Whether `measured` counts messages and loop decisions: not under StarPU-MPI, which
  /// reports bytes per destination only (STARPU_COMM_STATS).
  bool messages_counted() const { return policy != MpiPolicy::kStarpuMpi; }
  std::vector<MpiStepResult> steps;
  std::optional<bool> identical;  ///< with check
  std::uint64_t checksum = 0, sequential_checksum = 0;
  std::int64_t wall_ns = 0, sequential_ns = 0;
};

/// Replays `trace` under `assignment` (K = ranks x threads_per_rank) on MPI_COMM_WORLD.
/// Every rank calls it with the same arguments.
MpiReplayResult replay_distributed(const Trace& trace, const TraceAssignment& assignment,
                                   const MpiReplayOptions& options);

/// Whether this build has `MpiPolicy::kStarpuMpi`.
bool have_starpu_mpi();

/// The result as one JSON object (keys in docs/distributed.md).
std::string to_json(const MpiReplayResult& r, const std::string& trace_name);
/// The result as text.
std::string to_text(const MpiReplayResult& r, const std::string& trace_name);

}  // namespace tgraph::mpi
