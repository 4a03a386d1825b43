// SPDX-License-Identifier: MIT
// Costs of synchronisation and data transfer that the schedule simulator charges.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace tgraph::model {

/// One point of a curve measured against the number of busy processors.
struct ThreadsPoint {
  std::uint32_t threads = 1;
  double value = 0;  ///< inflation: a factor (1 = no slow-down); reduction: ns
  friend bool operator==(const ThreadsPoint&, const ThreadsPoint&) = default;
};

/// What takes a busy thread's core from it (interrupts, other processes, a VM's hypervisor)
/// on one CPU while K threads are busy: the share of wall time lost in gaps of at least
/// kInterruptionGapNs, and the gaps' lengths.
struct ThreadInterruptions {
  double lost = 0;                 ///< share of wall time lost, in [0, 0.5]
  std::vector<double> lengths_ns;  ///< quantiles of the gaps' lengths (empty: none seen)
  friend bool operator==(const ThreadInterruptions&, const ThreadInterruptions&) = default;
};
/// The interruptions measured with `threads` threads busy at once, thread p on the p-th CPU.
struct InterruptionsPoint {
  std::uint32_t threads = 1;
  std::vector<ThreadInterruptions> cpus;
  friend bool operator==(const InterruptionsPoint&, const InterruptionsPoint&) = default;
};
/// The shortest gap between two clock readings of a spinning thread that counts as an
/// interruption: shorter ones (a timer tick's handler) slow every task alike and are in
/// the captured costs; longer ones are what the capture's outlier trim leaves out.
inline constexpr double kInterruptionGapNs = 5'000.0;

/// The executor's default spin before a waiting thread parks (replay::kDefaultSpinNs, which
/// the model cannot see: the modules are siblings; measure passes the executor's own).
inline constexpr double kDefaultSpinBudgetNs = 50'000.0;

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
  /// simulated platform (`tgraph platform`, the SimGrid engine of `tgraph simulate`). Calibration
  /// files without "mpi_latency_ns" get the default, 1500 ns (`mpirun -np 2 tgraph-mpi calibrate`
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
  /// Hand-off to a thread that has parked (futex wake-up, `park_wake_ns` of `tgraph
  /// calibrate`): a dependency whose waiting processor sat idle longer than spin_budget_ns
  /// arrives park_wake_ns after its source ends instead of sync_latency_ns. 0: term off
  /// (calibration files written before it was measured).
  double park_wake_ns = 0.0;
  /// How long a waiting thread spins before it parks (the executor's ExecOptions::spin_ns).
  double spin_budget_ns = kDefaultSpinBudgetNs;
  /// The bodies' slow-down against the number of busy processors (`inflation` of `tgraph
  /// calibrate`: K copies of a memory-touching body at once against one), sorted by threads;
  /// empty: term off. Between points linear, below the first 1, beyond the last the last.
  /// With inflation_ns_per_byte it scales a task's memory share only (below).
  std::vector<ThreadsPoint> inflation;
  /// The same for a body that only computes (`compute_inflation`: K copies of a register
  /// multiply-add chain against one: a lower clock when many cores are busy, a core's other
  /// hardware thread), which scales the rest of a task's cost; empty: 1.
  std::vector<ThreadsPoint> compute_inflation;
  /// Time per byte of the memory-touching body alone (`inflation_ns_per_byte`): a task's
  /// memory share is min(its cost, the bytes of the data it accesses x this), inflated by
  /// `inflation`, the rest by `compute_inflation`. 0 (files without it): the whole cost is
  /// scaled by `inflation`, as a memory-bound body.
  double inflation_ns_per_byte = 0.0;
  /// A cross-processor reduction's hand-off against the processors taking part (`reduction`
  /// of `tgraph calibrate`, ns; measured, reported, not charged by the simulator).
  std::vector<ThreadsPoint> reduction;
  /// The partition executor's own time per task instance against its number of threads
  /// (`executor_overhead` of `tgraph calibrate`, ns: a step of independent tasks on K
  /// threads against the same bodies run by the sequential executor), charged by the
  /// built-in simulator to every instance of a K-processor assignment on top of
  /// task_overhead_ns; sorted by threads, empty: term off. None at one processor (the
  /// sequential engine has no executor), linear between points, beyond the last the last.
  std::vector<ThreadsPoint> executor_overhead;
  /// Interruptions of busy threads against the number of busy threads (`interruptions` of
  /// `tgraph calibrate`), sorted by threads; empty: term off. The built-in simulator
  /// interrupts each processor's tasks at random (a seeded stream per processor: the same
  /// graph gives the same schedule) so that it loses `lost` of its time in gaps drawn from
  /// `lengths_ns`; a task that starts inside a gap starts at its end.
  std::vector<InterruptionsPoint> interruptions;

  /// Processor p's interruptions at k busy processors: the point of the most threads at
  /// most k (else the first), its CPU p modulo its CPUs; nullptr when there are none (no
  /// curve, or nothing lost).
  const ThreadInterruptions* interruptions_at(std::uint32_t k, std::uint32_t p) const;
  /// The inflation factor at `busy` processors busy at once (1 when the curve is empty).
  double inflation_at(double busy) const;
  /// compute_inflation's factor at `busy` processors busy at once (1 when it is empty).
  double compute_inflation_at(double busy) const;
  /// The factor a task of `cost_ns` accessing `bytes` bytes is scaled by at `busy`
  /// processors busy at once: memory share x inflation_at + the rest x compute_inflation_at,
  /// over the cost (inflation_at alone without inflation_ns_per_byte).
  double task_inflation(double busy, double cost_ns, double bytes) const;
  /// The executor's time per task instance at `k` processors (0 at k <= 1 or when the curve
  /// is empty).
  double executor_overhead_at(std::uint32_t k) const;

  /// Zero synchronisation and transfer cost: pure precedence and load.
  static CostModel ideal();
  /// Constants used when no calibration file is given (see docs/partitioning.md).
  static CostModel defaults();
};

/// Default calibration file: $XDG_CONFIG_HOME/tgraph/calibration.json, else
/// ~/.config/tgraph/calibration.json.
std::string default_calibration_path();
/// Reads a calibration file (save_calibration's); throws InputError naming the file for
/// unreadable or malformed content.
CostModel load_calibration(const std::string& path);
/// Parses a calibration file's text (at most 1 MiB, JSON nested at most 64 deep); `name`
/// names it in errors.
CostModel parse_calibration(std::string_view text, const std::string& name);
/// The model the command line uses: `model` "ideal" -> CostModel::ideal(); else the file
/// `calibration` if given, else the default calibration file if present, else defaults().
CostModel select_cost_model(const std::string& model, const std::string& calibration);

/// The main thread's serial work per step that a live run measured: per_step[].record_ns +
/// partition_ns + prepare_ns of a live run's JSON report (measure's to_json of a scene run:
/// recording, the wait for partitioning, plan preparation). Throws InputError naming the file.
std::vector<std::uint64_t> load_serial_work(const std::string& path);
/// The serial work of each of a trace's `steps` steps: `serial_ns` for every step when
/// given, else the first `steps` of load_serial_work(live) (an OptionError of the field
/// "live" when the run has fewer), else none (empty).
std::vector<std::uint64_t> serial_work(const std::string& live,
                                       std::optional<std::uint64_t> serial_ns, std::size_t steps);

/// The main thread's serial work per step that a simulation charges instead of the trace's
/// host time: a live run's measure (`live`) or the same for every step (`serial_ns`).
struct SerialWork {
  std::string live;                        ///< a live run's JSON report (load_serial_work)
  std::optional<std::uint64_t> serial_ns;  ///< ns before every step's tasks
  /// serial_work(live, serial_ns, steps): per step of a `steps`-step trace; empty for neither.
  std::vector<std::uint64_t> per_step(std::size_t steps) const;
};

/// How one measurement of measure_calibration spread over its samples.
struct Spread {
  double min = 0, median = 0, max = 0;
  friend bool operator==(const Spread&, const Spread&) = default;
};
/// The spread of one point of a curve against the number of threads.
struct CurveSpread {
  std::uint32_t threads = 1;
  Spread spread;
  friend bool operator==(const CurveSpread&, const CurveSpread&) = default;
};
/// The spread (min, median, max) of `samples`; all zero for none.
Spread spread_of(std::vector<double> samples);

/// What measure_calibration measured.
struct Calibration {
  double sync_latency_ns = 0;    ///< median one-way handoff by spinning on an atomic
  double per_byte_ns = 0;        ///< extra cost per byte of reading data written on the other core
  int cpu_a = 0, cpu_b = 1;      ///< the two CPUs the threads were pinned to
  int rounds = 0;                ///< handoffs measured
  std::size_t buffer_bytes = 0;  ///< buffer size of the transfer measurement
  /// Median one-way hand-off to a thread parked in a futex wait, from the waker's clock
  /// reading before its store and FUTEX_WAKE to the sleeper's return.
  double park_wake_ns = 0;
  int park_rounds = 0;  ///< parked hand-offs measured
  /// Slow-down of a memory-touching body run by K pinned threads at once against one
  /// thread alone (per sample, the median over rounds, each one thread alone then K at once,
  /// of the K threads' mean time per pass / alone's; the samples' median, at least 1),
  /// K = 1, 2, 4, ... and the CPUs this process may use.
  std::vector<ThreadsPoint> inflation;
  std::size_t inflation_bytes = 0;  ///< each body's working set
  /// The same for K copies of a body that only computes (a register multiply-add chain).
  std::vector<ThreadsPoint> compute_inflation;
  /// The memory body's time per byte touched when it runs alone (the median over samples of
  /// each sample's median over its rounds): what sizes a task's memory share.
  double inflation_ns_per_byte = 0;
  /// Combine of one partial sum per thread (K threads, each arriving at a counter; the
  /// last sums the partials and publishes; every thread reads the result): median ns per
  /// round, for the same K as `inflation` (K >= 2).
  std::vector<ThreadsPoint> reduction;
  /// The partition executor's own time per task instance at K threads (ns; K = 2, 4, ...
  /// and the CPUs this process may use): measure_calibration leaves it empty,
  /// calibrate_machine fills it from measure's run of the executor.
  std::vector<ThreadsPoint> executor_overhead;
  std::vector<CurveSpread> executor_overhead_spread;  ///< over its samples, per K
  /// K = 1, 2, 4, ... pinned threads each reading the clock in a loop, all at once: per
  /// thread the share of time lost in gaps of at least kInterruptionGapNs and 32 quantiles
  /// of their lengths, pooled over the samples.
  std::vector<InterruptionsPoint> interruptions;
  /// Samples of every measurement (interleaved); each value above is their median, but the
  /// inflation, which is at least 1 (a median below 1 is noise: K copies cannot each run
  /// faster than one alone).
  int samples = 0;
  Spread latency_spread, per_byte_spread, park_wake_spread;  ///< over the samples
  /// Over the samples, per K >= 2: the inflation as measured (before the floor at 1), the
  /// reduction's ns.
  std::vector<CurveSpread> inflation_spread, reduction_spread;
  std::vector<CurveSpread> compute_inflation_spread;  ///< before the floor at 1
  Spread inflation_pass_spread;                       ///< of inflation_ns_per_byte
  double seconds = 0;                                 ///< wall time of the whole measurement
};

/// Options of measure_calibration().
struct CalibrateOptions {
  int rounds = 20000;                  ///< ping-pong round trips
  std::size_t buffer_bytes = 1 << 18;  ///< transferred buffer (fits a private L2)
  int repeats = 15;                    ///< transfer measurements (median taken)
  int park_rounds = 400;               ///< parked hand-offs (each after 30 us asleep)
  /// Working set of each copy of the inflation body: 2 MiB (half read, half read-modify-
  /// written), an engine object's vectors several times over: beyond a core's private L2
  /// on current x86, so that the copies share the last-level cache and memory.
  std::size_t inflation_bytes = std::size_t{2} << 20;
  int inflation_rounds = 7;     ///< rounds per thread count and sample (median taken)
  int reduction_rounds = 2000;  ///< reductions per thread count
  double interruption_ms = 60;  ///< per thread count and sample: the clock loop's length
  /// Times every measurement above is taken, interleaved; the medians are kept and the
  /// spread reported (a VM's figures move by several times from one sample to the next).
  int samples = 15;
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
/// The report of a saved calibration: one JSON object, or two lines.
std::string calibration_report(const Calibration& c, const std::string& path, bool json);

/// `samples` samples of the partition executor's own time per task instance at `threads`
/// threads (ns): what only a module that runs the executor can measure
/// (measure::executor_overhead_samples).
using ExecutorOverheadSampler =
    std::function<std::vector<double>(std::uint32_t threads, std::uint32_t samples)>;

/// measure_calibration(options), with the executor's time per task from `sampler` at the
/// same K as the inflation's (2, 4, ..., the CPUs this process may use; `options.samples`
/// samples each; the median kept, at least 0) in `executor_overhead`.
Calibration calibrate_machine(const CalibrateOptions& options,
                              const ExecutorOverheadSampler& sampler);

/// `tgraph calibrate`: calibrate_machine(options, sampler) saved to `path`
/// (save_calibration), and its report (calibration_report).
std::string calibrate_file(const CalibrateOptions& options, const std::string& path, bool json,
                           const ExecutorOverheadSampler& sampler);

}  // namespace tgraph::model
