// SPDX-License-Identifier: MIT
// Synthetic task bodies for replaying traces: each task spins for its recorded cost while
// reading and writing buffers of its data's recorded sizes.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "tgraph/graph/lowering.hpp"
#include "tgraph/replay/workload.hpp"

namespace tgraph::replay {

/// Speed of this machine for the synthetic bodies, measured once per process.
struct SyntheticCalibration {
  double spin_iterations_per_ns = 0;  ///< iterations of the busy loop per nanosecond
  double touch_ns_per_byte = 0;       ///< reading + writing data already in cache
};

/// Options of the synthetic bodies.
struct SyntheticOptions {
  double cost_scale = 1.0;                      ///< multiplies every recorded cost
  bool touch = true;                            ///< read/write the data buffers
  std::uint64_t max_datum_bytes = 64ull << 20;  ///< larger data are touched only this far
  /// In-cache touch rate (ns per byte) that sizes a short task's partial pass (below);
  /// default: this process's calibration. Processes that must touch the same words (the
  /// ranks of an MPI replay and its sequential reference) share one value.
  std::optional<double> fraction_ns_per_byte = std::nullopt;
  /// Spin for the rest of the recorded cost after the data pass (false: the caller does,
  /// e.g. by the clock).
  bool spin = true;
};

/// Bodies that cost what the trace recorded and move the memory the data would.
///
/// A task reads every word of its R/RW data (or, when its recorded cost is shorter than that
/// pass at in-cache speed, the leading fraction of each datum that fits in its cost), then
/// writes its W/RW/CW data (W: overwrite,
/// RW: combine, CW: add), with values derived from what it read, so that the final buffer
/// contents depend on the order the dataflow graph prescribes (and CW sums are exact
/// integers: any reduction order gives the same bits). It then spins for its recorded cost
/// minus the time the memory pass takes at the rate in use (calibrate_touch's stream, or
/// set_touch_ns_per_byte: what the passes took where the sequential program ran them) and
/// the spin offset: running away from its data costs the real cache misses on top. Buffers
/// are allocated and first touched by the thread that first uses them in the plan
/// (Workload::first_touch).
///
///   SyntheticWorkload w;
///   w.set_step(trace.steps[s]);       // costs and loop iterations of that step
///   executor->run_step(trace.steps[s], &assignment, w);
class SyntheticWorkload : public Workload {
 public:
  explicit SyntheticWorkload(SyntheticOptions options = {});
  ~SyntheticWorkload() override;

  /// The original step whose costs and iteration counts the next run uses (kept by pointer).
  void set_step(const StepGraph& step) { step_ = &step; }

  void bind(const ExecGraph& exec) override;
  bool needs_touch(DatumId d) const override;
  void first_touch(DatumId d) override;
  void run(const TaskRun& r) override;
  bool stop_after(LoopId loop, std::uint32_t iteration) override;
  /// The recorded iterations of the step set by set_step (nullopt before set_step).
  std::optional<std::uint32_t> known_iterations(LoopId loop) const override;

  /// Words of exec datum `d` (empty before first touch).
  std::span<const std::uint64_t> words(DatumId d) const;
  /// Bytes currently allocated for data.
  std::uint64_t allocated_bytes() const;

  /// The calibration in use (measured on first call, about 20 ms).
  static const SyntheticCalibration& calibration();
  /// Measures the memory pass at a working set of `bytes` (the step's data: beyond the
  /// caches it costs more per byte) and uses that from now on, so that a task run where
  /// the sequential program ran it costs its recorded time; returns the ns per byte.
  double calibrate_touch(std::uint64_t bytes);
  /// Touch cost per byte in use.
  double touch_ns_per_byte() const { return touch_ns_per_byte_; }
  /// Uses `ns_per_byte` from now on to size the spin after each data pass (what
  /// calibrate_touch sets; the rate of the bodies' own passes timed with time_bodies, as
  /// measure::replay_trace does).
  void set_touch_ns_per_byte(double ns_per_byte) { touch_ns_per_byte_ = ns_per_byte; }
  /// Spin after the data pass (SyntheticOptions::spin) from now on, or not.
  void set_spin(bool on) { options_.spin = on; }
  /// Taken off every task's spin from now on (ns; negative: added): what a body costs over
  /// its pass and its spin (the calls, the loop's start), measured where it runs.
  void set_spin_offset_ns(double ns) { spin_offset_ns_ = ns; }
  /// What the bodies run while time_bodies(true) took, summed.
  struct BodyTimes {
    std::uint64_t tasks = 0;
    double body_ns = 0;   ///< each body's wall time: its data pass and its spin
    double cost_ns = 0;   ///< their recorded costs (x cost_scale)
    double bytes = 0;     ///< the bytes their data passes touched
  };
  /// While on, each task body is timed and summed (BodyTimes); on again starts new sums.
  void time_bodies(bool on);
  const BodyTimes& timed() const { return timed_; }
  /// Runs step `g`'s host time (StepGraph::host_ns: the engine's serial work outside the
  /// graph, before the step's tasks) on the calling thread as a calibrated spin, scaled like
  /// the task costs; returns the wall time it took (ns).
  std::int64_t run_host(const StepGraph& g) const;

 private:
  struct Buffer;
  SyntheticOptions options_;
  const StepGraph* step_ = nullptr;
  std::vector<std::unique_ptr<Buffer>> buffers_;  // by exec datum
  std::vector<std::uint64_t> want_words_;         // by exec datum
  std::vector<bool> is_temp_;                     // by exec datum
  double touch_ns_per_byte_ = 0;
  double spin_offset_ns_ = 0;
  bool timing_ = false;
  BodyTimes timed_;
  // Busy loop for `ns` nanoseconds at the calibrated rate (nothing when ns <= 0).
  static void spin_ns(double ns, std::uint64_t seed);
};

/// Busy loop of `iterations` dependent multiply-adds; returns a value to keep it alive.
std::uint64_t spin_iterations(std::uint64_t iterations, std::uint64_t seed);

}  // namespace tgraph::replay
