// SPDX-License-Identifier: MIT
// `tgraph-mpi calibrate`: MPI latency and bandwidth between two local ranks, added to the
// calibration file that `tgraph calibrate` writes (its optional inter-node fields).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace tgraph::mpi {

/// What a ping-pong between ranks 0 and 1 measured.
struct MpiLink {
  double latency_ns = 0;            ///< one-way time of a small message (median over batches)
  double per_byte_ns = 0;           ///< extra one-way time per byte of a large message (median)
  int rounds = 0;                   ///< small round trips measured
  std::uint64_t message_bytes = 0;  ///< size of the large message
  /// The MPI replay's own time per task instance beyond its recorded cost (0: not measured;
  /// then the file's "task_overhead_ns" is left as it was).
  double task_overhead_ns = 0;
  /// The MPI replay's time per message on each side (sender and receiver), beyond the
  /// instances' own (none: not measured; the file's "mpi_message_overhead_ns" left as it
  /// was). Written even when 0: a loaded machine can measure no difference.
  std::optional<double> message_overhead_ns;
};

/// Ping-pong between ranks 0 and 1 of MPI_COMM_WORLD (other ranks wait); every rank calls
/// it, the result is rank 0's. Throws UsageError with fewer than 2 ranks.
MpiLink measure_mpi_link(int rounds = 4000, std::uint64_t message_bytes = 1 << 20,
                         int repeats = 15);

/// The MPI replay's own time per task instance (ns): every rank replays, through
/// replay_distributed() with one thread per rank, a chain of `tasks` tasks of `cost_ns` each
/// on a datum of its own (no message), `steps` times; rank 0's median over the steps after
/// the first of (wall - tasks x cost_ns) / tasks. Every rank calls it; the result is rank 0's.
double measure_task_overhead(std::uint32_t tasks = 20000, std::uint64_t cost_ns = 300,
                             int steps = 6);

/// The MPI replay's processor time per message and side (ns, LogP's o): every rank r
/// replays, with one thread per rank, steps of n tasks that each write an 8-byte datum, then
/// n tasks that each read one of rank r - 1's (each rank sends and receives n messages),
/// for n = `messages` / 4 and n = `messages`, `steps` steps each, 5 times; from rank 0's
/// median step times, the median slope per message less two task instances
/// (`task_overhead_ns` each), halved.
/// Every rank calls it; the result is rank 0's. Throws UsageError with fewer than 2 ranks.
double measure_message_overhead(double task_overhead_ns, std::uint32_t messages = 256,
                                int steps = 16);

/// The calibration file `text` (named `name` in errors; what `tgraph calibrate` wrote) with
/// "mpi_latency_ns" and "mpi_per_byte_ns" set from `link` (and "mpi_calibration" saying how),
/// "task_overhead_ns" and "mpi_message_overhead_ns" when `link` measured them, every other key
/// kept. Throws InputError naming `name` when `text` is not a calibration.
std::string with_mpi_link(std::string_view text, const std::string& name, const MpiLink& link);

}  // namespace tgraph::mpi
