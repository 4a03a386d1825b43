// SPDX-License-Identifier: MIT
// Verifying declared accesses: a task body run between checksums of the state, and run again
// from the same state with its undeclared data perturbed (--verify-accesses).
#pragma once

#include <cstdint>
#include <limits>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "tgraph/graph/step_graph.hpp"

namespace tgraph {

/// What a task was seen doing to a datum beyond its declaration.
enum class AccessFound : std::uint8_t {
  kWrite = 0,  ///< its bytes changed across the task, which declares it R or not at all
  kRead = 1,   ///< the task's written data changed when this undeclared datum was perturbed
};

/// "write" or "read".
std::string_view to_string(AccessFound found);

/// One wrong declaration (`access_findings` in the JSON of --verify-accesses).
struct AccessFinding {
  std::string task;      ///< the task's key: "kind of object" (task_label)
  std::string datum;     ///< the datum's name
  AccessFound found = AccessFound::kWrite;
  std::string declared;  ///< how the task declares the datum: "R", or "none"
  friend bool operator==(const AccessFinding&, const AccessFinding&) = default;
};

/// "task direction of tile(2,3) wrote tile(2,3).p, declared R" or "task matvec of tile(1,1)
/// read tile(0,1).p, declared none".
std::string to_string(const AccessFinding& f);

/// A task's key as findings name it: "kind of object", "kind" for a task without object,
/// with " #n" for its n-th occurrence (n > 0) of that kind on that object in the step.
std::string task_label(std::string_view kind, std::string_view object, std::uint32_t occurrence);
/// The same for task `t` of `g` (its occurrence counted over the tasks before it).
std::string task_label(const StepGraph& g, TaskId t);

/// A non-owning reference to a callable `void()` (the body under check).
class BodyRef {
 public:
  template <class F>
  BodyRef(F& f)  // NOLINT: implicit, as a function_ref
      : obj_(const_cast<void*>(static_cast<const void*>(&f))),
        call_([](void* o) { (*static_cast<F*>(o))(); }) {}
  void operator()() const { call_(obj_); }

 private:
  void* obj_;
  void (*call_)(void*);
};

/// Runs task bodies between checksums of the state and finds the data they write or read
/// without declaring it.
///
/// The state is one region of storage per datum (set_storage). For each run():
/// - **writes**: every region is checksummed before and after the body; a region that
///   changed and that the task does not declare W, RW or CW is a write finding. Seen: any
///   change of the bytes. Not seen: a write that leaves the bytes as they were, a datum
///   without storage, memory that is no datum's storage.
/// - **reads** (`check_reads`, for tasks whose written data all have storage, as cost passes
///   need): the written data are put back as they were before the body, the regions the task
///   does not declare are perturbed (see perturb()), the body runs again, and its written
///   data are compared with the first run's. A difference means the task read some of them:
///   bisecting the set names each datum read. Seen: a read of a datum holding normal
///   doubles whose value reaches the task's written data. Not seen: reads of integers,
///   flags, floats below the double's range and doubles equal to zero (never perturbed),
///   reads whose value does not change the result (a comparison that goes the same way),
///   reads of data without storage. Afterwards the state is what the first run left, bit
///   for bit. A body whose result changes between two runs from the same, unperturbed state
///   is reported as a read of "(state outside the declared data)".
///
/// Not thread-safe: a caller running tasks on several threads serialises run() (lock()).
///
///   AccessChecker check;
///   for (DatumId d = 0; d < data.size(); ++d) check.set_storage(d, ptr[d], data[d].bytes);
///   check.sync();
///   std::vector<AccessChecker::Found> found;
///   check.run(accesses_of_task, body, true, found);
class AccessChecker {
 public:
  /// One finding of one run, by datum id (`declared`: nullopt when not declared).
  struct Found {
    DatumId datum = 0;
    AccessFound found = AccessFound::kWrite;
    std::optional<AccessMode> declared;
  };
  /// The datum of a read finding of a body whose result changed between two runs from the
  /// same, unperturbed state: it reads something outside the declared data.
  static constexpr DatumId kOutsideState = std::numeric_limits<DatumId>::max();
  /// What the checks cost.
  struct Counts {
    std::uint64_t runs = 0;          ///< task runs checked
    std::uint64_t reruns = 0;        ///< extra runs of bodies for the read check
    std::uint64_t reads_unchecked = 0;  ///< runs writing a datum without storage (no rerun)
  };

  /// Datum `d`'s storage (nullptr: none, the datum is not checked). Call sync() after.
  void set_storage(DatumId d, void* ptr, std::uint64_t bytes);
  /// Forgets every region.
  void clear_storage();
  /// Whether datum `d` has storage here.
  bool has_storage(DatumId d) const { return d < regions_.size() && regions_[d].ptr != nullptr; }
  /// Checksums every region again (after code outside task bodies changed the state).
  void sync();
  /// Checksums datum `d`'s region again.
  void sync(DatumId d);
  /// Runs `body`, the body of a task declaring `acc`, under the checks above and appends
  /// what it found to `out`. An exception of the body's first run leaves the checker to be
  /// sync()ed and propagates.
  void run(std::span<const Access> acc, BodyRef body, bool check_reads, std::vector<Found>& out);
  /// The mutex a caller running tasks on several threads holds around run().
  std::unique_lock<std::mutex> lock() { return std::unique_lock<std::mutex>(mutex_); }
  const Counts& counts() const { return counts_; }

  /// Flips bit 40 (a relative change of 2^-12) of every 8-byte word of the region that holds
  /// a normal double (exponent field neither 0 nor all ones), leaving zeros, integers below
  /// 2^52, NaNs and infinities as they are; applied twice it restores the bytes.
  static void perturb(void* ptr, std::uint64_t bytes);
  /// 64-bit checksum of `bytes` bytes at `ptr`: any change of one 8-byte word changes it.
  static std::uint64_t checksum(const void* ptr, std::uint64_t bytes);

 private:
  struct Region {
    void* ptr = nullptr;
    std::uint64_t bytes = 0;
    std::uint64_t sum = 0;  // checksum at the last sync or run
  };
  // Written data's bytes (the declared-writable and the changed regions), concatenated.
  void save(const std::vector<DatumId>& ds, std::vector<unsigned char>& into) const;
  void restore(const std::vector<DatumId>& ds, const std::vector<unsigned char>& from);
  bool same(const std::vector<DatumId>& ds, const std::vector<unsigned char>& as) const;
  // Runs the body again from `before` with `perturbed` perturbed; true when its written data
  // differ from `after` (or it threw).
  bool differs_with(BodyRef body, const std::vector<DatumId>& outputs,
                    const std::vector<unsigned char>& before,
                    const std::vector<unsigned char>& after, std::span<const DatumId> perturbed);
  // Bisects `set` (every datum of it perturbed at once makes a difference) for the data read.
  void find_reads(BodyRef body, const std::vector<DatumId>& outputs,
                  const std::vector<unsigned char>& before, const std::vector<unsigned char>& after,
                  std::span<const DatumId> set, std::vector<DatumId>& read);

  std::vector<Region> regions_;  // by datum
  std::mutex mutex_;
  Counts counts_;
  std::vector<std::optional<AccessMode>> declared_;  // by datum, for the task under check
};

/// `f`, found running `task`, as a finding naming its datum from `data` (kOutsideState:
/// "(state outside the declared data)").
AccessFinding finding(std::string task, const AccessChecker::Found& f, std::span<const Datum> data);

/// The findings of a verification, deduplicated by (task, datum, found), in the order first
/// seen; safe to add to from several threads.
class AccessFindings {
 public:
  void add(AccessFinding f);
  /// The findings so far.
  std::vector<AccessFinding> list() const;
  bool empty() const;

 private:
  mutable std::mutex mutex_;
  std::vector<AccessFinding> list_;
};

}  // namespace tgraph
