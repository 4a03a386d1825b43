// SPDX-License-Identifier: MIT
// Discrete-event simulation of a partitioned step: what its makespan would be.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/step_graph.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/model/cost_model.hpp"

namespace tgraph::model {

/// A simulated schedule. Task instances are numbered task by task: instance
/// `first_instance[t] + i` is iteration i of task t (i < g.runs(t)).
struct Schedule {
  std::uint64_t makespan_ns = 0;
  /// Per processor: its instances' time (cost, per-task overheads, transfers and the
  /// interruptions that fell inside them).
  std::vector<std::uint64_t> busy_ns;
  /// Per processor: the bodies' time as a live run's clock around each body sees it (each
  /// instance's cost, inflated when the model inflates it, and the interruptions inside
  /// it), without the per-task overheads and transfers that busy_ns adds.
  std::vector<std::uint64_t> body_ns;
  /// The instances' costs alone (inflated), summed by task kind (indexed by KindId of the
  /// step's kinds).
  std::vector<std::uint64_t> kind_body_ns;
  std::vector<std::uint64_t> finish_ns;  ///< per processor: end of its last task
  std::uint64_t signals = 0;  ///< datum versions (and loop decisions) sent to other processors
  std::uint64_t waits = 0;    ///< (version, receiving processor) pairs
  /// k x k, [from * k + to]: the waits of processor `to` for versions sent by `from`
  /// (summed: `waits`); what the report's quotient graph calls the signals from -> to.
  std::vector<std::uint64_t> waits_between;
  std::uint64_t transfer_bytes = 0;           ///< bytes read from another processor's writes
  std::vector<std::uint64_t> first_instance;  ///< per task, plus the total at the end
  std::vector<std::uint64_t> start_ns;        ///< per instance
  std::vector<std::uint64_t> end_ns;          ///< per instance
};

/// Simulates step `g` (edges derived) under assignment `a`:
///
/// * the step starts with its serial work on processor 0 (the calling thread), which every
///   processor waits for: `serial_ns` when given (the main thread's work between steps as a
///   live run measured it: recording, the wait for partitioning, plan preparation), else
///   the host time (StepGraph::host_ns: the engine's serial work outside the graph);
/// * a processor that waited longer than `model.spin_budget_ns` (for the serial work, a
///   dependency from another processor or a loop decision) has parked: the hand-off that
///   ends the wait costs `park_wake_ns` instead of `sync_latency_ns` (when park_wake_ns > 0);
/// * with an inflation curve (and k >= 2), the step is simulated twice: each instance's cost
///   is then scaled by `model.inflation_at(b)`, b the time-weighted mean number of
///   instances running at once during it in the first schedule (itself included);
/// * every processor runs its tasks one after the other, in `a.order[p]` or program order;
/// * a task starts when its processor is free and every dependency (intra-step edges;
///   loop-carried edges from the previous iteration) has finished, plus
///   `sync_latency_ns` when the source ran on another processor;
/// * the first task on a processor that reads a datum version written elsewhere also pays
///   `bytes x per_byte_ns`;
/// * with `model.interruptions`, each processor is interrupted at random (a stream seeded
///   by the processor and the step's size) by gaps of the measured lengths, so that it
///   loses the measured share of its time: a gap under way delays a task's start, one
///   that begins while it runs lengthens it, one that ends while the processor waits
///   costs nothing;
/// * a loop body is run by every processor holding some of its tasks (loop control
///   replicated, paper section 3.3): iteration i+1 starts, and the loop is left, only once
///   the break task of iteration i is known (plus latency if it ran elsewhere);
///   a processor's loop tasks form one block placed where its first loop task appears.
///
/// Throws tgraph::Error when `a` does not fit `g` or its order deadlocks.
Schedule simulate(const StepGraph& g, const Assignment& a, const CostModel& model,
                  std::optional<std::uint64_t> serial_ns = std::nullopt);

/// The simulated makespan of every step of `trace` under `a` (one per step), what `tgraph
/// replay` reports as predicted; `serial_ns` (when not null) the serial work per step.
std::vector<std::uint64_t> predicted_makespans(
    const Trace& trace, const TraceAssignment& a, const CostModel& model,
    const std::vector<std::uint64_t>* serial_ns = nullptr);

/// The terms a prediction with `model` charges (`model_terms` in the JSON of `tgraph evaluate`
/// and `tgraph simulate`): "sync_latency", "per_byte" (not with the ideal model),
/// "task_overhead", "executor_overhead", "park_wake", "interruptions", "inflation",
/// "compute_inflation", "memory_share" when the model has them, then
/// "serial_main_thread" when the serial work per step was given, else "host_time" when
/// the trace has host time.
std::vector<std::string> model_terms(const CostModel& model, bool serial_given, bool host_time);

}  // namespace tgraph::model
