// SPDX-License-Identifier: MIT
// ODE's threading interface (ode/threading.h) on tgraph's threads: K slots, slot 0 the
// thread that steps the world (it serves inside wait_call), slots 1..K-1 workers. Calls come
// from a preallocated pool; a ready call goes to a slot's deque (its own under work stealing,
// its placement under the partition policy); an idle thread pops its own deque's newest,
// then steals the oldest of the others', spins, and parks on a futex.
#pragma once

#include <ode/ode.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <thread>
#include <unordered_map>
#include <vector>

namespace tgraph::ode::detail {

struct Call;
struct Wait;
struct Slot;

/// A segment of a call (or of the world step's own code on the stepping thread) between two
/// of its posts, alters or waits: one task of the recorded graph.
struct SegmentRecord {
  std::uint64_t seq = 0;            ///< order number: larger than every segment it follows
  std::uint32_t call = 0;           ///< CallRecord id
  std::uint32_t seg = 0;            ///< index within the call
  std::int64_t start = 0, end = 0;  ///< stamps (StepLog::ns_per_tick)
  std::uint32_t access_begin = 0, access_count = 0;  ///< into the slot's accesses
  bool last = false;                                 ///< the call's last segment
};
/// What a segment declares besides its call's own order: a release or a wait.
struct AccessRecord {
  enum Kind : std::uint8_t { kRelease = 0, kSignal = 1, kWaitRead = 2 };
  Kind kind = kRelease;
  std::uint32_t a = 0;  ///< kRelease: the releasee's call id; else the wait's id
  std::uint32_t b = 0;  ///< kSignal, kWaitRead: the wait's generation
};
/// One posted call (or the world step's own code: poster_call = kNone).
struct CallRecord {
  static constexpr std::uint32_t kNone = 0xffffffffu;
  std::uint32_t id = 0;
  const char* name = nullptr;
  std::uint32_t instance = 0;
  std::uint64_t key = 0;  ///< stable key: the poster's key, its post count, name, instance
  std::uint32_t poster_call = kNone;  ///< the segment whose post made it
  std::uint32_t poster_seg = 0;
  bool released = false;  ///< posted with dependencies: waits for releases
};
/// The stable key of a call's `seg`-th segment (the recorded task's key).
inline std::uint64_t segment_key(std::uint64_t call_key, std::uint32_t seg) {
  return call_key ^ ((static_cast<std::uint64_t>(seg) + 1) * 0x9e3779b97f4a7c15ull);
}

/// What one thread recorded in a step.
struct SlotLog {
  std::vector<SegmentRecord> segments;
  std::vector<AccessRecord> accesses;  ///< segments' ranges point here
  std::vector<CallRecord> calls;
};

/// What one step recorded: each thread's own part (moved out of the threads, not copied).
struct StepLog {
  std::vector<SlotLog> slots;
  const char* entry = "";    ///< dWorldQuickStep or dWorldStep
  std::int64_t host_ns = 0;  ///< collision before the step
  double ns_per_tick = 1.0;  ///< segments' stamps to ns
};

/// The runtime's knobs.
struct RuntimeOptions {
  std::uint32_t threads = 2;
  /// The thread count ODE is told (retrieve_thread_count; 0: threads): ODE posts as many
  /// instances of a stage as it is told, so a larger count on fewer threads measures what
  /// ODE's K-thread algorithm costs without K threads.
  std::uint32_t advertised_threads = 0;
  bool placed = false;  ///< partition policy: calls go to their key's slot
  /// Islands policy: an idle thread steals only the calls the stepping thread's own code
  /// posted (ODE's island jobs); a call posted by a running call stays on its poster's
  /// thread (a stage's instances run one after another there).
  bool steal_root_only = false;
  /// Serial island stepping: ODE is told K threads when it sizes a step's memory (K island
  /// arenas) and 1 when it plans the step (one island job, each island stepped by its
  /// single-threaded stepper, ODE self-threaded's algorithm); the runtime then posts K - 1
  /// more island jobs beside ODE's, so K threads step whole islands side by side. What later
  /// ODE offers as `island_stepping_max_threads` (dWorldSetSteppingThreadingParameters, not
  /// in 0.16.2), made from 0.16.2's own step: it queries the thread count exactly twice
  /// (sizing, then planning) before it posts its island jobs; a step that queried otherwise
  /// runs as ODE planned it, its jobs not multiplied, and serial_islands_refused() says so.
  bool serial_islands = false;
  std::int64_t spin_ns = 50'000;
  double watchdog_s = 60.0;
};

/// Counters of the runtime (relaxed; read between steps).
struct RuntimeCounters {
  std::uint64_t calls = 0, steals = 0, parks = 0;
};

/// The implementation behind dThreadingFunctionsInfo. One world steps through it at a time.
class Runtime {
 public:
  explicit Runtime(const RuntimeOptions& options);
  ~Runtime();
  Runtime(const Runtime&) = delete;
  Runtime& operator=(const Runtime&) = delete;

  /// The function table and implementation pointer ODE is given.
  const dThreadingFunctionsInfo* functions() const;
  dThreadingImplementationID id();
  std::uint32_t threads() const { return threads_; }

  /// Recording of the calls between begin_step and end_step (stepping thread, between steps).
  void set_recording(bool on) { recording_.store(on, std::memory_order_relaxed); }
  bool recording() const { return recording_.load(std::memory_order_relaxed); }
  /// Before a world step: the root of the calls' keys and, when recording, opens the world
  /// step's own segment named `entry` on the stepping thread.
  void begin_step(const char* entry);
  /// After it: closes that segment; when recording, the step's log (else an empty one).
  StepLog end_step();
  /// Recording: `steps` logs of each thread with room for `segments`, `accesses` and `calls`
  /// records, written once here (their pages faulted in now, not in the steps); end_step
  /// hands the next one to each thread while they last.
  void reserve_logs(std::uint32_t steps, std::size_t segments, std::size_t accesses,
                    std::size_t calls);
  /// Partition policy: the slot of each call, by its first segment's key (segment_key).
  void set_placement(std::unordered_map<std::uint64_t, std::uint32_t> placement);
  RuntimeCounters counters() const;

  // The interface's functions (ode/threading.h), called through functions().
  dMutexGroupID alloc_mutex_group(dmutexindex_t count);
  void free_mutex_group(dMutexGroupID group);
  void lock(dMutexGroupID group, dmutexindex_t index);
  void unlock(dMutexGroupID group, dmutexindex_t index);
  dCallWaitID alloc_wait();
  void reset_wait(dCallWaitID wait);
  void free_wait(dCallWaitID wait);
  void post(int* out_summary_fault, dCallReleaseeID* out_post_releasee,
            ddependencycount_t dependencies, dCallReleaseeID dependent_releasee,
            dCallWaitID call_wait, dThreadedCallFunction* function, void* context,
            dcallindex_t instance, const char* name);
  void alter(dCallReleaseeID releasee, ddependencychange_t change);
  void wait(int* out_wait_status, dCallWaitID wait, const dThreadedWaitTime* timeout,
            const char* name);
  unsigned thread_count();
  /// Serial island stepping: the number of world steps whose thread-count queries did not
  /// follow 0.16.2's pattern (their island jobs were not multiplied).
  std::uint64_t serial_islands_refused() const { return serial_refused_; }
  int preallocate(ddependencycount_t calls);

 private:
  Slot& my_slot();
  Call* allocate_call(Slot& slot);
  void free_call(Call* call, Slot& slot);
  void make_ready(Call* call, Slot& slot);
  Call* find_work(Slot& slot);
  /// Work `self`'s thread may take: its own calls, or the calls it may steal.
  bool any_work(const Slot& self) const;
  void run(Call* call, Slot& slot);
  void complete(Call* call, Slot& slot);
  void signal(Wait* wait);
  void wake();
  void park(Slot& slot, const std::atomic<std::uint32_t>* done);
  void worker(std::uint32_t index);
  void watchdog();
  std::uint64_t call_key(Slot& slot, const char* name, dcallindex_t instance);
  // Recording: the segment open on `slot` ends here (split at a post, alter or wait).
  void split(Slot& slot);
  bool take_spare(Slot& slot);  // the slot's logs become its next spare room's, if any
  void open_segment(Slot& slot, std::uint32_t call, std::uint32_t seg, std::uint64_t after,
                    std::int64_t start_ns);
  void close_segment(Slot& slot, bool last, std::int64_t end_ns);

  std::uint32_t threads_;
  std::uint32_t advertised_;
  bool placed_;
  bool steal_root_only_;
  bool serial_islands_;
  // Serial island stepping, per world step (the stepping thread's, but thread_count may be
  // queried from a running call): the queries made since begin_step, whether ODE's island
  // jobs were multiplied, and whether a world step is under way.
  std::atomic<std::uint32_t> step_queries_{0};
  bool jobs_multiplied_ = false;
  bool in_step_ = false;
  std::uint64_t serial_refused_ = 0;
  std::int64_t spin_ns_;
  double watchdog_s_;
  dThreadingFunctionsInfo functions_{};
  std::vector<std::unique_ptr<Slot>> slots_;
  std::vector<std::thread> workers_;
  std::thread watchdog_thread_;
  std::atomic<bool> stop_{false};
  // Parking: a thread without work registers in sleepers_ and waits on epoch_; whoever makes
  // work (a ready call, a signalled wait) bumps epoch_ when someone sleeps.
  std::atomic<std::uint32_t> epoch_{0};
  std::atomic<std::uint32_t> sleepers_{0};
  std::atomic<bool> recording_{false};
  std::atomic<std::uint32_t> wait_ids_{0};
  // The call pool (free list under a spin lock; grown by preallocate or when empty).
  struct Pool;
  std::unique_ptr<Pool> pool_;
  std::int64_t first_ns_ = 0, first_tick_ = 0;  ///< the first step's clock and stamp
  std::uint64_t root_key_ = 0;  ///< the world step's entry: the root of the calls' keys
  std::unordered_map<std::uint64_t, std::uint32_t> placement_;
};

}  // namespace tgraph::ode::detail
