// SPDX-License-Identifier: MIT
// Costs of synchronisation and data transfer that the schedule simulator charges.
#pragma once

#include <string>
#include <string_view>

namespace tgraph::partition {

/// What a cross-processor dependency costs in a simulated schedule.
///
///   CostModel m = CostModel::defaults();           // or load_calibration("calib.json")
///   Schedule s = simulate(graph, assignment, m);
struct CostModel {
  /// One-way signal -> wait latency between two cores (ns), added to every dependency
  /// whose source runs on another processor.
  double sync_latency_ns = 100.0;
  /// Cost per byte (ns) of reading data last written on another processor, charged to the
  /// reading processor once per datum version.
  double per_byte_ns = 0.05;
  /// Where the constants come from ("default", "ideal" or the calibration file's path).
  std::string source = "default";
  /// One-way MPI message latency between two nodes (ns): the inter-node links of a
  /// simulated platform (`tgraph platform`, `simulate --engine simgrid`). Calibration files
  /// without "mpi_latency_ns" get the default, 1500 ns (`mpirun -np 2 tgraph-mpi calibrate`
  /// measures it between local ranks).
  double mpi_latency_ns = 1500.0;
  /// Cost per byte (ns) of an MPI message between two nodes (1 / bandwidth): default 0.08
  /// (12.5 GB/s, a 100 Gb/s InfiniBand EDR link), from "mpi_per_byte_ns" when present.
  double mpi_per_byte_ns = 0.08;
  /// Time the runtime itself spends per task instance beyond the instance's recorded cost
  /// (dispatching it, its bookkeeping, the body's clock), charged to the instance's
  /// processor by both simulation engines. 0 unless the calibration file has
  /// "task_overhead_ns" (`mpirun -np 2 tgraph-mpi calibrate` measures the MPI replay's).
  double task_overhead_ns = 0.0;
  /// Processor time one MPI message between two nodes costs on each side (LogP's o:
  /// posting and completing the send, matching and installing the receive), charged by the
  /// SimGrid engine to the sending instance and to the receiving processor's next instance,
  /// per datum version and loop decision sent to another node. 0 unless the calibration
  /// file has "mpi_message_overhead_ns" (`mpirun -np 2 tgraph-mpi calibrate` measures the
  /// MPI replay's).
  double mpi_message_overhead_ns = 0.0;

  /// Zero synchronisation and transfer cost: pure precedence and load.
  static CostModel ideal();
  /// Constants used when no calibration file is given (see docs/partitioning.md).
  static CostModel defaults();
};

/// Default calibration file: $XDG_CONFIG_HOME/tgraph/calibration.json, else
/// ~/.config/tgraph/calibration.json.
std::string default_calibration_path();
/// Reads a calibration file written by `tgraph calibrate`; throws InputError naming the
/// file for unreadable or malformed content.
CostModel load_calibration(const std::string& path);
/// Parses a calibration file's text (at most 1 MiB, JSON nested at most 64 deep); `name`
/// names it in errors.
CostModel parse_calibration(std::string_view text, const std::string& name);
/// The model the command line uses: `model` "ideal" -> CostModel::ideal(); else the file
/// `calibration` if given, else the default calibration file if present, else defaults().
CostModel select_cost_model(const std::string& model, const std::string& calibration);

/// What `tgraph calibrate` measured.
struct Calibration {
  double sync_latency_ns = 0;   ///< median one-way handoff by spinning on an atomic
  double per_byte_ns = 0;       ///< extra cost per byte of reading data written on the other core
  int cpu_a = 0, cpu_b = 1;     ///< the two CPUs the threads were pinned to
  int rounds = 0;               ///< handoffs measured
  std::size_t buffer_bytes = 0; ///< buffer size of the transfer measurement
};

/// Options of measure_calibration().
struct CalibrateOptions {
  int rounds = 20000;                 ///< ping-pong round trips
  std::size_t buffer_bytes = 1 << 18; ///< transferred buffer (fits a private L2)
  int repeats = 15;                   ///< transfer measurements (median taken)
};

/// Measures this machine with two threads pinned to two different CPUs; throws
/// std::runtime_error (a failure of the work, not a tgraph::Error about the input) when the
/// calling thread may use fewer than two CPUs.
Calibration measure_calibration(const CalibrateOptions& options = {});
/// The calibration file's JSON text.
std::string calibration_json(const Calibration& c);
/// Writes calibration_json(c) to `path` atomically (default_calibration_path() when empty),
/// creating its folder; returns the path written.
std::string save_calibration(const Calibration& c, const std::string& path = "");
/// `tgraph calibrate`'s report of a saved calibration: one JSON object, or two lines.
std::string calibration_report(const Calibration& c, const std::string& path, bool json);

}  // namespace tgraph::partition
