// SPDX-License-Identifier: MIT
// The state of an engine as named byte regions: snapshots and their bit-for-bit comparison
// (the check of a live run).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "tgraph/graph/step_graph.hpp"
#include "tgraph/replay/observer.hpp"

namespace tgraph::measure {

/// One named piece of state (a datum's storage).
struct StateRegion {
  StateRegion() = default;
  /// `{name, ptr, bytes}` as before the writer was added (braces keep working).
  StateRegion(std::string n, const void* p, std::uint64_t b)
      : name(std::move(n)), ptr(p), bytes(b) {}
  /// first_write: kNotWritten when unknown or not written.
  static constexpr std::uint32_t kNotWritten = 0xffffffffu;
  std::string name;
  const void* ptr = nullptr;
  std::uint64_t bytes = 0;
  /// Position in the engine's last recorded step of the first task that writes it
  /// (set_write_order), the order in which compare() looks for the first difference.
  std::uint32_t first_write = kNotWritten;
  /// The task that last wrote it in that step (task_label: "kind of object"); empty when
  /// unknown or not written.
  std::string writer;
};

/// Sets each region's first_write and writer from `g`, the engine's last recorded step
/// (regions matched to `g`'s data by name); the regions keep their order. compare() then
/// names the datum whose bytes differ first in program order of the writes.
void set_write_order(std::vector<StateRegion>& regions, const StepGraph& g);

/// A copy of the bytes of some regions.
struct StateSnapshot {
  std::vector<std::string> names;
  std::vector<std::vector<std::uint8_t>> bytes;
  std::vector<std::string> writers;         ///< StateRegion::writer, by region
  std::vector<std::uint32_t> first_writes;  ///< StateRegion::first_write, by region
};

/// Copies the regions' bytes.
StateSnapshot snapshot(std::span<const StateRegion> regions);

/// First difference between two snapshots of the same regions.
struct StateDifference {
  StateDifference() = default;
  StateDifference(std::string d, std::uint64_t o, std::uint64_t n, std::string w = {})
      : datum(std::move(d)), offset(o), differing_bytes(n), writer(std::move(w)) {}
  std::string datum;                  ///< name of the first differing region
  std::uint64_t offset = 0;           ///< first differing byte in it
  std::uint64_t differing_bytes = 0;  ///< in that region
  std::string writer;                 ///< the task that last wrote it (empty: unknown)
};

/// nullopt when equal bit for bit. `actual`'s regions are taken in the order of their first
/// write (set_write_order; unwritten ones after, in their order) and found in `expected` by
/// name (the k-th of a repeated name with the k-th): the first difference is the datum whose
/// bytes differ first in program order of the writes; a region missing from either side
/// differs.
std::optional<StateDifference> compare(const StateSnapshot& expected, const StateSnapshot& actual);
/// "first differing datum <datum> (byte <offset>, <differing_bytes> bytes differ), last
/// written by task <writer>".
std::string to_string(const StateDifference& d);

/// How far apart the values of two snapshots of the same regions are (matched by name as
/// compare() matches them). A region whose size is a multiple of 8 bytes is read as IEEE
/// binary64 values (what the engines in the tree store: positions, velocities, forces,
/// solver vectors and scalars); any other region (a flag, a count) is compared bit for bit.
struct ValueDifference {
  double max_abs_diff = 0;  ///< largest |a - b| over every value
  /// Largest over the data of max|a - b| / max|b|, the datum's largest difference relative to
  /// its largest magnitude (max over a and b; the norm-wise relative difference in the
  /// infinity norm, which a value near zero does not blow up).
  double max_rel_diff = 0;
  std::string max_abs_datum;  ///< the datum of max_abs_diff (empty: none differs)
  std::string max_rel_datum;  ///< the datum of max_rel_diff
  std::uint64_t differing_values = 0;  ///< values (doubles) not bit-identical
  /// Why the values cannot be within rounding whatever their distance (empty: they can): a
  /// region not read as doubles whose bytes differ, a NaN or infinity on one side only, a
  /// region on one side only or of another size.
  std::string incomparable;
};

/// By datum name: the largest magnitude of its values after any task that wrote it (a
/// MagnitudeObserver's), the magnitudes involved in computing it.
using Magnitudes = std::unordered_map<std::string, double>;

/// The values of `actual` against those of `expected` (see ValueDifference). With
/// `involved`, a datum's max_rel_diff is relative to the larger of its largest magnitude and
/// its magnitude in `involved`: a value made small by cancellation (a converged residual
/// r = b - A x) is measured against the magnitudes it was computed from.
ValueDifference compare_values(const StateSnapshot& expected, const StateSnapshot& actual,
                               const Magnitudes* involved = nullptr);

/// Watches a sequential executor that runs CW writes in place (ReduceScope::kNone): after
/// each task instance, the largest magnitude of each datum it wrote whose storage `regions`
/// gives (matched by name, read as doubles when a multiple of 8 bytes), kept as the largest
/// over the run. Single-threaded use only.
class MagnitudeObserver final : public replay::Observer {
 public:
  /// `regions`: called at each step's start for the storage of the state (it may move).
  explicit MagnitudeObserver(std::function<std::vector<StateRegion>()> regions)
      : regions_(std::move(regions)) {}
  void on_step_begin(const ExecGraph& exec, std::uint32_t threads,
                     std::int64_t t_ns) override;
  void on_end(std::uint32_t thread, TaskId task, std::uint32_t iteration,
              std::int64_t t_ns) override;
  const Magnitudes& magnitudes() const { return magnitudes_; }

 private:
  std::function<std::vector<StateRegion>()> regions_;
  const ExecGraph* exec_ = nullptr;
  std::vector<const StateRegion*> by_datum_;  // exec datum -> its region (nullptr: none)
  std::vector<StateRegion> current_;
  Magnitudes magnitudes_;
};

/// The unit roundoff of IEEE binary64, 2^-53.
inline constexpr double kUnitRoundoff = 0x1p-53;

/// The relative bound of a reduction order change (docs/instrumenting.md, "What the check
/// compares with"): a sum of n terms taken in two orders differs by at most
/// 2 gamma(n-1) = 2 (n-1) u / (1 - (n-1) u) of the sum of their magnitudes (Higham, Accuracy
/// and Stability of Numerical Algorithms, 2nd ed., section 4.2); `rounds` such reductions in
/// sequence, each feeding the next, add up to first order:
/// rounds x 2 gamma(n-1). `longest_reduction`: terms of the longest reduction whose order
/// may differ (its writers and the initial value).
double reduction_order_bound(std::uint64_t longest_reduction, std::uint64_t rounds);

/// The most terms one reduction of `g` sums: over the data, 1 (the initial value) + the
/// tasks that write it CW. 1 when nothing is written CW.
std::uint64_t longest_reduction(const StepGraph& g);

}  // namespace tgraph::measure
