// SPDX-License-Identifier: MIT
// Internal: a live run's partitioner on a thread of its own, so that no step waits for it.
#pragma once

#include <atomic>
#include <cstdint>
#include <exception>
#include <memory>
#include <optional>
#include <thread>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/step_graph.hpp"
#include "tgraph/partition/strategy.hpp"

namespace tgraph::measure::detail {

/// Runs a StepPartitioner on one helper thread (scheduled SCHED_IDLE: it takes the cycles
/// the step's threads leave, never a core from them), one job at a time; a job submitted
/// while another waits replaces it. Without a thread (`threaded` false) a job runs inside
/// submit(), on the caller's time. The partitioner is only ever called by one thread at a
/// time, so stateful strategies (sticky) keep their state.
///
/// The caller's side takes no lock: jobs and results pass through atomic pointers and the
/// helper sleeps on an atomic counter, so a helper descheduled at any point (SCHED_IDLE on
/// busy cores) never holds up a step (a mutex held by it would: priority inversion).
///
///   BackgroundPartitioner bg(partitioner, true);
///   bg.submit({graph, prev_graph, prev_assignment, k});
///   ... steps run ...
///   if (auto done = bg.take()) use(done->assignment);
class BackgroundPartitioner {
 public:
  /// What to partition: the graphs are snapshots nobody changes while the job holds them.
  struct Job {
    std::shared_ptr<const StepGraph> graph;
    std::shared_ptr<const StepGraph> prev_graph;  ///< null: partition afresh
    std::shared_ptr<const Assignment> prev;       ///< with prev_graph
    std::uint32_t k = 1;
  };
  /// A finished job.
  struct Done {
    Assignment assignment;
    std::shared_ptr<const StepGraph> graph;  ///< the graph it partitions
    std::int64_t partition_ns = 0;           ///< the partitioner's own time
    std::exception_ptr error;                ///< what the partitioner threw
  };

  BackgroundPartitioner(const partition::StepPartitioner& partitioner, bool threaded);
  ~BackgroundPartitioner();
  BackgroundPartitioner(const BackgroundPartitioner&) = delete;
  BackgroundPartitioner& operator=(const BackgroundPartitioner&) = delete;

  /// Queues `job` (replacing one not started yet); without a thread, runs it now.
  void submit(Job job);
  /// True while a job is queued or running.
  bool busy() const;
  /// The result of the last finished job, once (rethrows the partitioner's exception).
  std::optional<Done> take();
  /// Waits for the queued and running jobs to finish.
  void drain() const;

 private:
  void loop();
  Done run(const Job& job) const;

  const partition::StepPartitioner& partitioner_;
  // Owned pointers handed over by exchange: the caller stores jobs and takes results, the
  // helper the reverse; acq_rel on each exchange publishes the object with the pointer.
  std::atomic<Job*> queued_{nullptr};
  std::atomic<Done*> done_{nullptr};
  std::atomic<bool> running_{false};  ///< set before the helper takes a job, cleared after
  std::atomic<std::uint32_t> submitted_{0};  ///< the helper sleeps while it is unchanged
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace tgraph::measure::detail
