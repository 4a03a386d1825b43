// SPDX-License-Identifier: MIT
// Internal: spin-then-park waiting on 64-bit counters, thread pinning.
#pragma once

#include "tgraph/replay/executor.hpp"

#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>

#if defined(__x86_64__) || defined(__i386__)
#include <x86intrin.h>
#endif

#include "tgraph/replay/observer.hpp"

namespace tgraph::replay::detail {

/// The clock of waits: the time-stamp counter where there is one (rdtsc: about 10 ns a read
/// on this project's VM against 24 for steady_clock through the vDSO; a blocked wait reads
/// it twice, the second time on the critical path of the hand-off), now_ns() elsewhere.
inline std::int64_t wait_ticks() {
#if defined(__x86_64__) || defined(__i386__)
  return static_cast<std::int64_t>(__rdtsc());
#else
  return now_ns();
#endif
}

/// Nanoseconds per wait_ticks() tick: measured once per process against steady_clock
/// (about 2 ms, the first time it is asked); 1 where the ticks are now_ns().
double wait_tick_ns();

// kLongSpinNs (executor.hpp): how long a wait spins at most while the thread it waits for
// runs (Parking::wait with an `awake` test): beyond spin_ns, and only where every thread has
// a core of its own.

/// A 64-bit counter alone on its cache line.
struct alignas(64) PaddedCounter {
  std::atomic<std::uint64_t> v{0};
};

/// Whether this process can use membarrier(MEMBARRIER_CMD_PRIVATE_EXPEDITED) (registered on
/// the first call); false where the kernel or a seccomp filter refuses it.
bool asymmetric_fence_available();
/// A full memory barrier on every running thread of this process (membarrier); only where
/// asymmetric_fence_available().
void asymmetric_heavy_fence();

/// Spin-then-park waiting shared by the threads of one executor.
///
/// Protocol (Dekker): a waiter that is about to sleep increments `parked` (seq_cst) and then
/// re-reads the counter (seq_cst); a signaller stores the counter and then reads `parked`.
/// Each side needs its store ordered before its load. Where the process may use
/// membarrier and the threads have a core each, the fence is asymmetric: the signaller,
/// on every hand-off, only stores (release) and keeps the compiler from moving its load above
/// the store, and the waiter, once per sleep, runs asymmetric_heavy_fence() between its
/// increment and its re-read, a full barrier on every running thread. Then either the
/// signaller's store was before that barrier on its core (the waiter's re-read sees the
/// value and does not sleep) or its load of `parked` was after it (it sees the waiter and
/// notifies). Elsewhere the signaller's store and load are seq_cst (an xchg on x86: about
/// 10 ns more per hand-off on this project's VM, replay_bench BM_Handoff); in the single
/// total order of seq_cst operations the same either/or holds. std::atomic::wait itself
/// never misses a notify that follows its value check.
class Parking {
 public:
  /// Oversubscribed threads (more than cores) park often: each sleep's heavy fence would
  /// interrupt every core, so they keep the symmetric fence.
  /// `long_spin_ns`: how long a wait spins at most while awake() (kLongSpinNs).
  explicit Parking(std::int64_t spin_ns, bool oversubscribed,
                   std::int64_t long_spin_ns = kLongSpinNs)
      : tick_ns_(wait_tick_ns()),
        spin_ticks_(static_cast<std::int64_t>(static_cast<double>(spin_ns) / tick_ns_)),
        long_ticks_(spin_ns <= 0 || oversubscribed
                        ? 0
                        : static_cast<std::int64_t>(static_cast<double>(long_spin_ns) / tick_ns_)),
        oversubscribed_(oversubscribed),
        asymmetric_(!oversubscribed && asymmetric_fence_available()) {}

  /// Publishes `value` into `c` and wakes sleepers if any.
  void signal(std::atomic<std::uint64_t>& c, std::uint64_t value) {
    if (asymmetric_) {
      // release: the writer's data is visible to whoever acquires `value`. The store ->
      // load order of the Dekker pair is the sleeper's heavy fence's (class comment); the
      // signal fence keeps the compiler from hoisting the load above the store.
      c.store(value, std::memory_order_release);
      std::atomic_signal_fence(std::memory_order_seq_cst);
      // relaxed: ordered by the fences above and the sleeper's heavy fence.
      if (parked_.load(std::memory_order_relaxed) != 0) c.notify_all();
      return;
    }
    // seq_cst: orders this store before the load of parked_ below (see class comment);
    // it is also a release, so the writer's data is visible to whoever acquires `value`.
    c.store(value, std::memory_order_seq_cst);
    // seq_cst: the other half of the Dekker pair.
    if (parked_.load(std::memory_order_seq_cst) != 0) c.notify_all();
  }

  /// Wakes every sleeper of `c` after a change of its value made by the caller.
  void wake(std::atomic<std::uint64_t>& c) { c.notify_all(); }

  /// Changes `c` (adds 2^31, staying within its epoch) and wakes every sleeper (abort).
  void poke(std::atomic<std::uint64_t>& c) {
    // seq_cst: ordered after the abort flag the woken waiters then read.
    c.fetch_add(1ull << 31, std::memory_order_seq_cst);
    c.notify_all();
  }

  /// Waits until ok(c) or `abort` is set; returns the last value read and whether it slept.
  /// `waited_ns` receives the time spent (0 when ok at once).
  template <class Ok>
  std::uint64_t wait(std::atomic<std::uint64_t>& c, Ok ok, const std::atomic<bool>& abort,
                     bool& parked, std::int64_t& waited_ns) {
    return wait(c, ok, abort, parked, waited_ns, [] { return false; }, [] { return false; },
                nullptr);
  }

  /// The same, calling idle() while it spins (before each round of checks): idle() returns
  /// true when it did useful work (the partition executor runs a stolen task); the spin
  /// budget then starts again, and the time idle() worked is not counted in `waited_ns`.
  /// Past the spin budget it spins on, up to kLongSpinNs, while awake() (the thread it
  /// waits for runs: a hand-off from a running thread costs no wake-up) where every thread
  /// has a core (not oversubscribed, spin_ns > 0). `sleeping` (optional): the caller's flag,
  /// 1 while it sleeps, which other threads' awake() read.
  template <class Ok, class Idle, class Awake>
  std::uint64_t wait(std::atomic<std::uint64_t>& c, Ok ok, const std::atomic<bool>& abort,
                     bool& parked, std::int64_t& waited_ns, Idle idle, Awake awake,
                     std::atomic<std::uint32_t>* sleeping) {
    parked = false;
    waited_ns = 0;
    // acquire: pairs with the signaller's store so its data writes are visible after.
    std::uint64_t v = c.load(std::memory_order_acquire);
    if (ok(v)) return v;
    const std::int64_t t_start = wait_ticks();
    std::int64_t t0 = t_start, worked = 0;
    std::int64_t t = t0;
    // (t < t0: the thread moved to a core whose counter is behind; it parks rather than
    // spin for as long as the counters differ.)
    while (t >= t0 && (t - t0 < spin_ticks_ || (t - t0 < long_ticks_ && awake()))) {
      if (idle()) {
        const std::int64_t t1 = wait_ticks();
        worked += t1 - t;
        t0 = t = t1;
        v = c.load(std::memory_order_acquire);  // acquire: as above
        // relaxed: as in the loop below.
        if (ok(v) || abort.load(std::memory_order_relaxed)) {
          waited_ns = elapsed_ns(t_start, worked);
          return v;
        }
        continue;
      }
      for (int i = 0; i < 64; ++i) {
        if (oversubscribed_) {
          std::this_thread::yield();
        } else {
          cpu_relax();
        }
        v = c.load(std::memory_order_acquire);  // acquire: as above
        // relaxed: abort is only a hint to stop; no data is read because of it.
        if (ok(v) || abort.load(std::memory_order_relaxed)) {
          waited_ns = elapsed_ns(t_start, worked);
          return v;
        }
      }
      t = wait_ticks();
    }
    parked = true;
    // relaxed: a hint for other waiters' awake() (spin or park), nothing is read through it.
    if (sleeping != nullptr) sleeping->store(1, std::memory_order_relaxed);
    // seq_cst: Dekker with signal() (class comment).
    parked_.fetch_add(1, std::memory_order_seq_cst);
    if (asymmetric_) asymmetric_heavy_fence();  // the signallers' half of their fence
    for (;;) {
      v = c.load(std::memory_order_seq_cst);                      // seq_cst: Dekker with signal()
      if (ok(v) || abort.load(std::memory_order_seq_cst)) break;  // seq_cst: Dekker with abort
      c.wait(v, std::memory_order_acquire);                       // acquire: as the loads above
    }
    // relaxed: only signallers read it, and a stale non-zero value costs one notify.
    parked_.fetch_sub(1, std::memory_order_relaxed);
    if (sleeping != nullptr) sleeping->store(0, std::memory_order_relaxed);  // relaxed: as above
    waited_ns = elapsed_ns(t_start, worked);
    return v;
  }

  /// Number of sleeping waiters (for abort).
  std::uint32_t parked() const { return parked_.load(std::memory_order_seq_cst); }

 private:
  // Nanoseconds since wait_ticks() read t0 (0 if the ticks went back: a thread that is not
  // pinned may move to a core whose counter is behind).
  // `worked`: ticks of that spent in idle() work, not counted.
  std::int64_t elapsed_ns(std::int64_t t0, std::int64_t worked = 0) const {
    const std::int64_t d = wait_ticks() - t0 - worked;
    return d > 0 ? static_cast<std::int64_t>(static_cast<double>(d) * tick_ns_) : 0;
  }

  double tick_ns_;
  std::int64_t spin_ticks_;
  std::int64_t long_ticks_;  // 0: no spinning past spin_ticks_
  bool oversubscribed_;
  bool asymmetric_;
  alignas(64) std::atomic<std::uint32_t> parked_{0};
};

/// Binds the calling thread to thread slot p's processing unit; returns false if hwloc
/// cannot (never fails the run).
bool pin_current_thread(std::uint32_t p);
/// Restores the calling thread's binding saved by save_binding().
struct SavedBinding {
  void* set = nullptr;
  ~SavedBinding();
};
/// Saves the calling thread's current binding.
void save_binding(SavedBinding& s);
void restore_binding(SavedBinding& s);

/// The calling thread's binding before an executor first pinned it (as thread 0), restored
/// when the executor is destroyed.
class MainThreadBinding {
 public:
  MainThreadBinding() = default;
  ~MainThreadBinding() {
    if (saved_) restore_binding(binding_);
  }
  MainThreadBinding(const MainThreadBinding&) = delete;
  MainThreadBinding& operator=(const MainThreadBinding&) = delete;
  /// Saves the calling thread's binding the first time; later calls do nothing.
  void save_once() {
    if (saved_) return;
    saved_ = true;
    save_binding(binding_);
  }

 private:
  bool saved_ = false;
  SavedBinding binding_;
};

/// Number of processing units.
unsigned hardware_pus();

}  // namespace tgraph::replay::detail
