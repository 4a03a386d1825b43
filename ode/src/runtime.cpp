// SPDX-License-Identifier: MIT
// ODE's threading interface on tgraph's threads (runtime.hpp). Semantics of the interface as
// ode/threading.h documents them: a call starts when its dependency count is zero; while it
// runs it may add dependencies to itself (sub-calls releasing it); it completes when it has
// returned and those have completed, which writes its summary fault, signals its wait and
// releases its releasee (whose completion may follow in turn).
#include "runtime.hpp"

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string_view>

#include "tgraph/replay/observer.hpp"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define TGRAPH_ODE_PAUSE() _mm_pause()
#else
#define TGRAPH_ODE_PAUSE() ((void)0)
#endif

namespace tgraph::ode::detail {
namespace {

using replay::now_ns;  // the steady clock of every timeline

/// A segment's time stamp: the time-stamp counter where there is one (a quarter of a clock
/// read on this VM; constant and synchronised across cores when the kernel's clocksource is
/// tsc), converted to ns per step against the steady clock (StepLog::ns_per_tick).
std::int64_t stamp() {
#if defined(__x86_64__) || defined(__i386__)
  return static_cast<std::int64_t>(__rdtsc());
#else
  return now_ns();
#endif
}

/// Test-and-test-and-set lock for the deques and the pool (held for a few instructions).
class SpinLock {
 public:
  void lock() {
    // acquire: the holder's writes before its unlock (release) are seen.
    while (flag_.exchange(true, std::memory_order_acquire))
      while (flag_.load(std::memory_order_relaxed)) TGRAPH_ODE_PAUSE();
  }
  void unlock() { flag_.store(false, std::memory_order_release); }

 private:
  std::atomic<bool> flag_{false};
};

std::uint64_t fnv1a(std::string_view s) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h | 1;  // never 0 (0 marks a name slot not ready)
}

std::uint64_t mix(std::uint64_t h, std::uint64_t v) {
  h ^= v + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
  return h;
}

constexpr std::uint32_t kNoRecord = CallRecord::kNone;
/// The name 0.16.2 posts its island jobs under (util.cpp, dxProcessIslands).
constexpr const char* kIslandJobs = "World Islands Stepping Start";
constexpr int kBatch = 64;  // calls moved between a slot's free list and the shared pool

}  // namespace

struct Call {
  dThreadedCallFunction* function = nullptr;
  void* context = nullptr;
  dcallindex_t instance = 0;
  const char* name = nullptr;
  // Dependencies before the start; 1 + sub-calls while running. acq_rel on every change: a
  // releaser's writes (its fault, its results) are seen by whoever takes the count to zero.
  std::atomic<std::intptr_t> count{0};
  // Set (relaxed) before the function runs; read after a release's acq_rel decrement, which
  // the call's own post of that releaser (a deque push, release) precedes.
  std::atomic<bool> started{false};
  // Set before the count decrement that releases it (release), read after it (acquire).
  std::atomic<int> fault{0};
  Call* releasee = nullptr;
  Wait* wait = nullptr;
  int* fault_out = nullptr;
  Call* prev = nullptr;
  Call* next = nullptr;
  std::uint32_t record = kNoRecord;
  std::uint32_t home = 0;
  // Stable key (recording, placement): from the poster's key and its post count.
  std::uint64_t key = 0;
  std::uint32_t posts = 0;  // posts this call made so far (its own thread only)
  bool root = false;        // posted by the stepping thread's own code, not by a call
  // Recording: the order number its first segment must exceed (its poster's segment's, its
  // releasers' last segments'); raised by fetch_max before the release that may start it.
  std::atomic<std::uint64_t> ready_seq{0};
};

namespace {
// Raises `a` to at least `v`. relaxed: published by the release (acq_rel count decrement, or
// the wait's signal) that follows it.
void raise_to(std::atomic<std::uint64_t>& a, std::uint64_t v) {
  std::uint64_t cur = a.load(std::memory_order_relaxed);
  while (cur < v && !a.compare_exchange_weak(cur, v, std::memory_order_relaxed)) {
  }
}
}  // namespace

struct Wait {
  // release on signal, acquire on the waiter's check: the call's fault and results are seen.
  std::atomic<std::uint32_t> signalled{0};
  std::uint32_t id = 0;
  std::uint32_t generation = 0;       // recording: one datum per use
  std::atomic<std::uint64_t> seq{0};  // recording: the signalling segments' largest order number
};

struct Frame {
  std::uint32_t call = 0;
  std::uint32_t seg = 0;
  std::uint64_t seq = 0;
  std::int64_t start_ns = 0;
  std::uint32_t access_begin = 0;
  bool open = false;
};

struct alignas(64) Slot {
  std::uint32_t index = 0;
  SpinLock lock;
  Call* head = nullptr;  // newest
  Call* tail = nullptr;  // oldest
  // Written under the lock; read without it (relaxed) only to skip an empty deque. roots:
  // how many of its calls the stepping thread's own code posted (Call::root).
  std::atomic<std::uint32_t> size{0}, roots{0};
  // Watchdog: the call running here and how many calls started here (relaxed: a sample).
  std::atomic<const char*> running{nullptr};
  std::atomic<dcallindex_t> running_instance{0};
  std::atomic<std::uint64_t> generation{0};
  // Counters (relaxed; the slot's own thread writes them, read between steps).
  std::atomic<std::uint64_t> calls{0}, steals{0}, parks{0};
  // The call running here (null: the stepping thread's own code) and the posts of the
  // stepping thread's own code this step: the posted calls' keys.
  Call* current = nullptr;
  std::uint32_t root_posts = 0;
  // Call names' hashes by address (direct-mapped; the names are static strings).
  const char* hash_name[64] = {};
  std::uint64_t hash_value[64] = {};
  // Recording (the slot's own thread only, between begin_step and end_step).
  std::uint64_t clock = 0;  // the last order number given here
  std::vector<Frame> frames;
  std::vector<SegmentRecord> segments;
  std::vector<AccessRecord> accesses;
  std::vector<CallRecord> records;
  std::uint32_t next_record = 0;
  std::vector<SlotLog> spare;  // reserve_logs: the next steps' room, pages already written
  // The slot's own free calls (its thread only): no shared line per post and completion.
  Call* free = nullptr;
  int free_count = 0;

  void push_front(Call* c) {
    lock.lock();
    c->prev = nullptr;
    c->next = head;
    if (head)
      head->prev = c;
    else
      tail = c;
    head = c;
    size.store(size.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
    if (c->root) roots.store(roots.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
    lock.unlock();
  }
  Call* pop_front() {
    if (size.load(std::memory_order_relaxed) == 0) return nullptr;
    lock.lock();
    Call* c = head;
    if (c) unlink(c);
    lock.unlock();
    return c;
  }
  Call* pop_back() {
    if (size.load(std::memory_order_relaxed) == 0) return nullptr;
    lock.lock();
    Call* c = tail;
    if (c) unlink(c);
    lock.unlock();
    return c;
  }
  // The oldest call the stepping thread's own code posted (RuntimeOptions::steal_root_only).
  Call* pop_back_root() {
    if (roots.load(std::memory_order_relaxed) == 0) return nullptr;
    lock.lock();
    Call* c = tail;
    while (c && !c->root) c = c->prev;
    if (c) unlink(c);
    lock.unlock();
    return c;
  }
  // Takes `c` out of the deque, wherever it is (under the lock).
  void unlink(const Call* c) {
    (c->prev ? c->prev->next : head) = c->next;
    (c->next ? c->next->prev : tail) = c->prev;
    size.store(size.load(std::memory_order_relaxed) - 1, std::memory_order_relaxed);
    if (c->root) roots.store(roots.load(std::memory_order_relaxed) - 1, std::memory_order_relaxed);
  }
};

struct Runtime::Pool {
  SpinLock lock;
  Call* free = nullptr;
  std::vector<std::unique_ptr<Call[]>> blocks;
  std::size_t total = 0;
  // Under the lock.
  void grow(std::size_t n) {
    auto block = std::make_unique<Call[]>(n);
    for (std::size_t i = 0; i < n; ++i) {
      block[i].next = free;
      free = &block[i];
    }
    blocks.push_back(std::move(block));
    total += n;
  }
};

namespace {

thread_local Runtime* tl_runtime = nullptr;
thread_local std::uint32_t tl_slot = 0;

struct MutexGroup {
  std::unique_ptr<std::mutex[]> mutexes;
};

Runtime* rt(dThreadingImplementationID impl) { return reinterpret_cast<Runtime*>(impl); }

}  // namespace

Runtime::Runtime(const RuntimeOptions& options)
    : threads_(options.threads),
      advertised_(options.advertised_threads ? options.advertised_threads : options.threads),
      placed_(options.placed),
      steal_root_only_(options.steal_root_only),
      serial_islands_(options.serial_islands),
      spin_ns_(options.spin_ns),
      watchdog_s_(options.watchdog_s),
      pool_(std::make_unique<Pool>()) {
  functions_.struct_size = sizeof(dThreadingFunctionsInfo);
  functions_.alloc_mutex_group = [](dThreadingImplementationID impl, dmutexindex_t count,
                                    const char* const*) {
    return rt(impl)->alloc_mutex_group(count);
  };
  functions_.free_mutex_group = [](dThreadingImplementationID impl, dMutexGroupID g) {
    rt(impl)->free_mutex_group(g);
  };
  functions_.lock_group_mutex = [](dThreadingImplementationID impl, dMutexGroupID g,
                                   dmutexindex_t i) { rt(impl)->lock(g, i); };
  functions_.unlock_group_mutex = [](dThreadingImplementationID impl, dMutexGroupID g,
                                     dmutexindex_t i) { rt(impl)->unlock(g, i); };
  functions_.alloc_call_wait = [](dThreadingImplementationID impl) {
    return rt(impl)->alloc_wait();
  };
  functions_.reset_call_wait = [](dThreadingImplementationID impl, dCallWaitID w) {
    rt(impl)->reset_wait(w);
  };
  functions_.free_call_wait = [](dThreadingImplementationID impl, dCallWaitID w) {
    rt(impl)->free_wait(w);
  };
  functions_.post_call = [](dThreadingImplementationID impl, int* fault, dCallReleaseeID* out,
                            ddependencycount_t deps, dCallReleaseeID dependent, dCallWaitID wait,
                            dThreadedCallFunction* fn, void* ctx, dcallindex_t index,
                            const char* name) {
    rt(impl)->post(fault, out, deps, dependent, wait, fn, ctx, index, name);
  };
  functions_.alter_call_dependencies_count = [](dThreadingImplementationID impl, dCallReleaseeID r,
                                                ddependencychange_t change) {
    rt(impl)->alter(r, change);
  };
  functions_.wait_call = [](dThreadingImplementationID impl, int* status, dCallWaitID w,
                            const dThreadedWaitTime* timeout,
                            const char* name) { rt(impl)->wait(status, w, timeout, name); };
  functions_.retrieve_thread_count = [](dThreadingImplementationID impl) {
    return rt(impl)->thread_count();
  };
  functions_.preallocate_resources_for_calls = [](dThreadingImplementationID impl,
                                                  ddependencycount_t n) {
    return rt(impl)->preallocate(n);
  };

  // The workers allocate ODE's per-thread data, which needs ODE initialised (counted: paired
  // with dCloseODE in the destructor).
  dInitODE2(0);
  for (std::uint32_t i = 0; i < threads_; ++i) {
    slots_.push_back(std::make_unique<Slot>());
    slots_.back()->index = i;
  }
  pool_->grow(1024);
  for (std::uint32_t i = 1; i < threads_; ++i) workers_.emplace_back([this, i] { worker(i); });
  if (watchdog_s_ > 0) watchdog_thread_ = std::thread([this] { watchdog(); });
}

Runtime::~Runtime() {
  stop_.store(true, std::memory_order_release);
  epoch_.fetch_add(1, std::memory_order_release);
  epoch_.notify_all();
  for (std::thread& t : workers_) t.join();
  if (watchdog_thread_.joinable()) watchdog_thread_.join();
  dCloseODE();
}

const dThreadingFunctionsInfo* Runtime::functions() const { return &functions_; }
dThreadingImplementationID Runtime::id() {
  return reinterpret_cast<dThreadingImplementationID>(this);
}

Slot& Runtime::my_slot() { return tl_runtime == this ? *slots_[tl_slot] : *slots_[0]; }

Call* Runtime::allocate_call(Slot& slot) {
  if (!slot.free) {
    // The slot's own list is empty: a batch from the shared pool (grown when empty, which
    // preallocate anticipates).
    pool_->lock.lock();
    if (!pool_->free) pool_->grow(pool_->total);
    for (int i = 0; i < kBatch && pool_->free; ++i) {
      Call* c = pool_->free;
      pool_->free = c->next;
      c->next = slot.free;
      slot.free = c;
      ++slot.free_count;
    }
    pool_->lock.unlock();
  }
  Call* c = slot.free;
  slot.free = c->next;
  --slot.free_count;
  return c;
}

void Runtime::free_call(Call* c, Slot& slot) {
  c->next = slot.free;
  slot.free = c;
  if (++slot.free_count < 4 * kBatch) return;
  // Calls posted here and completed elsewhere pile up there: half goes back.
  pool_->lock.lock();
  for (int i = 0; i < 2 * kBatch; ++i) {
    Call* x = slot.free;
    slot.free = x->next;
    x->next = pool_->free;
    pool_->free = x;
    --slot.free_count;
  }
  pool_->lock.unlock();
}

int Runtime::preallocate(ddependencycount_t calls) {
  pool_->lock.lock();
  if (pool_->total < calls * 2) pool_->grow(calls * 2 - pool_->total);
  pool_->lock.unlock();
  return 1;
}

dMutexGroupID Runtime::alloc_mutex_group(dmutexindex_t count) {
  auto* g = new MutexGroup{std::make_unique<std::mutex[]>(count)};
  return reinterpret_cast<dMutexGroupID>(g);
}
void Runtime::free_mutex_group(dMutexGroupID group) { delete reinterpret_cast<MutexGroup*>(group); }
void Runtime::lock(dMutexGroupID group, dmutexindex_t index) {
  reinterpret_cast<MutexGroup*>(group)->mutexes[index].lock();
}
void Runtime::unlock(dMutexGroupID group, dmutexindex_t index) {
  reinterpret_cast<MutexGroup*>(group)->mutexes[index].unlock();
}

dCallWaitID Runtime::alloc_wait() {
  auto* w = new Wait;
  w->id = wait_ids_.fetch_add(1, std::memory_order_relaxed);  // a name only
  return reinterpret_cast<dCallWaitID>(w);
}
void Runtime::reset_wait(dCallWaitID wait) {
  auto* w = reinterpret_cast<Wait*>(wait);
  w->signalled.store(0, std::memory_order_relaxed);  // before the next post that signals it
  w->seq.store(0, std::memory_order_relaxed);
  ++w->generation;
}
void Runtime::free_wait(dCallWaitID wait) { delete reinterpret_cast<Wait*>(wait); }

std::uint64_t Runtime::call_key(Slot& slot, const char* name, dcallindex_t instance) {
  const char* text = name ? name : "(unnamed call)";
  const std::size_t i = (reinterpret_cast<std::uintptr_t>(text) >> 3) % 64;
  if (slot.hash_name[i] != text) {
    slot.hash_name[i] = text;
    slot.hash_value[i] = fnv1a(text);
  }
  // The poster's key and how many posts it made before: the same call tree, the same keys.
  const std::uint64_t parent = slot.current ? mix(slot.current->key, slot.current->posts++)
                                            : mix(root_key_, slot.root_posts++);
  return mix(mix(parent, slot.hash_value[i]), instance);
}

unsigned Runtime::thread_count() {
  if (!serial_islands_ || !in_step_) return advertised_;
  // 0.16.2's world step asks twice before posting its island jobs: first to size the island
  // arenas (K: one per island job), then to plan the step (1: one job, islands stepped by the
  // single-threaded stepper); the LDLT solver's later queries are capped at 1 by the plan.
  return step_queries_.fetch_add(1, std::memory_order_relaxed) == 0 ? advertised_ : 1u;
}

void Runtime::begin_step(const char* entry) {
  root_key_ = fnv1a(entry);
  step_queries_.store(0, std::memory_order_relaxed);
  jobs_multiplied_ = false;
  in_step_ = true;
  if (first_tick_ == 0) {
    first_ns_ = now_ns();
    first_tick_ = stamp();
  }
  my_slot().root_posts = 0;
  if (!recording()) return;
  for (auto& s : slots_) {
    s->segments.clear();
    s->accesses.clear();
    s->records.clear();
    s->frames.clear();
    s->next_record = 0;
  }
  Slot& slot = my_slot();
  CallRecord r;
  r.id = (slot.index << 24) | slot.next_record++;
  r.name = entry;
  r.key = mix(fnv1a(entry), 0);
  slot.records.push_back(r);
  slot.frames.push_back(Frame{});
  open_segment(slot, r.id, 0, 0, stamp());
}

StepLog Runtime::end_step() {
  in_step_ = false;
  StepLog log;
  if (!recording()) return log;
  const std::int64_t ns = now_ns(), tick = stamp();
  log.ns_per_tick =
      tick > first_tick_ && ns > first_ns_
          ? static_cast<double>(ns - first_ns_) / static_cast<double>(tick - first_tick_)
          : 1.0;
  Slot& slot = my_slot();
  if (!slot.frames.empty()) {
    if (slot.frames.back().open) close_segment(slot, true, stamp());
    slot.frames.pop_back();
  }
  for (auto& s : slots_) {
    SlotLog part;
    part.segments.swap(s->segments);
    part.accesses.swap(s->accesses);
    part.calls.swap(s->records);
    if (!take_spare(*s)) {
      // The next step starts with room for as much (one allocation, no regrowth).
      s->segments.reserve(part.segments.size());
      s->accesses.reserve(part.accesses.size());
      s->records.reserve(part.calls.size());
    }
    log.slots.push_back(std::move(part));
  }
  return log;
}

bool Runtime::take_spare(Slot& slot) {
  if (slot.spare.empty()) return false;
  SlotLog& room = slot.spare.back();
  slot.segments = std::move(room.segments);
  slot.accesses = std::move(room.accesses);
  slot.records = std::move(room.calls);
  slot.spare.pop_back();
  return true;
}

void Runtime::reserve_logs(std::uint32_t steps, std::size_t segments, std::size_t accesses,
                           std::size_t calls) {
  // Written once (resize), then emptied: the capacity stays, its pages faulted in.
  const auto written = [](auto& records, std::size_t n) {
    records.resize(n);
    records.clear();
  };
  for (auto& s : slots_) {
    s->spare.assign(steps, SlotLog{});
    for (SlotLog& room : s->spare) {
      written(room.segments, segments);
      written(room.accesses, accesses);
      written(room.calls, calls);
    }
    take_spare(*s);  // the first step's
  }
}

void Runtime::set_placement(std::unordered_map<std::uint64_t, std::uint32_t> placement) {
  placement_ = std::move(placement);
}

RuntimeCounters Runtime::counters() const {
  RuntimeCounters c;
  for (const auto& s : slots_) {
    c.calls += s->calls.load(std::memory_order_relaxed);
    c.steals += s->steals.load(std::memory_order_relaxed);
    c.parks += s->parks.load(std::memory_order_relaxed);
  }
  return c;
}

void Runtime::open_segment(Slot& slot, std::uint32_t call, std::uint32_t seg, std::uint64_t after,
                           std::int64_t start_ns) {
  Frame& f = slot.frames.back();
  f.call = call;
  f.seg = seg;
  // Larger than every segment it follows (on this thread; `after`: its poster's, releasers',
  // signallers'): sorted by it, the segments are in a topological order.
  f.seq = std::max(slot.clock, after) + 1;
  slot.clock = f.seq;
  f.start_ns = start_ns;
  f.access_begin = static_cast<std::uint32_t>(slot.accesses.size());
  f.open = true;
}

void Runtime::close_segment(Slot& slot, bool last, std::int64_t end_ns) {
  Frame& f = slot.frames.back();
  SegmentRecord s;
  s.seq = f.seq;
  s.call = f.call;
  s.seg = f.seg;
  s.start = f.start_ns;
  s.end = end_ns;
  s.access_begin = f.access_begin;
  s.access_count = static_cast<std::uint32_t>(slot.accesses.size()) - f.access_begin;
  s.last = last;
  slot.segments.push_back(s);
  f.open = false;
}

void Runtime::split(Slot& slot) {
  if (slot.frames.empty() || !slot.frames.back().open) return;
  const std::int64_t t = stamp();
  close_segment(slot, false, t);
  const Frame& f = slot.frames.back();
  open_segment(slot, f.call, f.seg + 1, 0, t);
}

void Runtime::post(int* out_summary_fault, dCallReleaseeID* out_post_releasee,
                   ddependencycount_t dependencies, dCallReleaseeID dependent_releasee,
                   dCallWaitID call_wait, dThreadedCallFunction* function, void* context,
                   dcallindex_t instance, const char* name) {
  Slot& slot = my_slot();
  // slot.current first: a running call's post (any thread) reads nothing of the step's own.
  if (serial_islands_ && slot.current == nullptr && in_step_ && !jobs_multiplied_ && name &&
      dependent_releasee && std::strcmp(name, kIslandJobs) == 0) {
    // ODE's one island job, posted by the world step's own code. The group it releases
    // counts K jobs before any of them can complete; the K - 1 added ones step islands with
    // their own arenas (sized for K) and take islands from ODE's counter as its own jobs do.
    jobs_multiplied_ = true;
    if (step_queries_.load(std::memory_order_relaxed) == 2 && instance == 0 && dependencies == 0 &&
        threads_ > 1) {
      alter(dependent_releasee, static_cast<ddependencychange_t>(threads_ - 1));
      for (std::uint32_t i = 1; i < threads_; ++i)
        post(nullptr, nullptr, 0, dependent_releasee, nullptr, function, context, i, name);
    } else if (threads_ > 1) {
      ++serial_refused_;
    }
  }
  Call* c = allocate_call(slot);
  c->function = function;
  c->context = context;
  c->instance = instance;
  c->name = name;
  c->count.store(static_cast<std::intptr_t>(dependencies), std::memory_order_relaxed);
  c->started.store(false, std::memory_order_relaxed);
  c->fault.store(0, std::memory_order_relaxed);
  c->releasee = reinterpret_cast<Call*>(dependent_releasee);
  c->wait = reinterpret_cast<Wait*>(call_wait);
  c->fault_out = out_summary_fault;
  c->home = slot.index;
  c->record = kNoRecord;
  slot.calls.store(slot.calls.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  c->posts = 0;
  c->root = slot.current == nullptr;
  c->ready_seq.store(0, std::memory_order_relaxed);
  const bool rec = recording();
  if (rec || placed_) {
    const std::uint64_t key = call_key(slot, name, instance);
    c->key = key;
    if (placed_) {
      auto it = placement_.find(segment_key(key, 0));
      if (it != placement_.end()) c->home = it->second % threads_;
    }
    if (rec) {
      CallRecord r;
      r.id = (slot.index << 24) | slot.next_record++;
      r.name = name ? name : "(unnamed call)";
      r.instance = static_cast<std::uint32_t>(instance);
      r.key = key;
      r.released = dependencies > 0;
      if (!slot.frames.empty() && slot.frames.back().open) {
        r.poster_call = slot.frames.back().call;
        r.poster_seg = slot.frames.back().seg;
        c->ready_seq.store(slot.frames.back().seq,
                           std::memory_order_relaxed);  // published by the push
        split(slot);  // the part before the post precedes the posted call, the rest does not
      }
      slot.records.push_back(r);
      c->record = r.id;
    }
  }
  if (out_post_releasee) *out_post_releasee = reinterpret_cast<dCallReleaseeID>(c);
  if (dependencies == 0) make_ready(c, slot);
}

void Runtime::alter(dCallReleaseeID releasee, ddependencychange_t change) {
  Call* c = reinterpret_cast<Call*>(releasee);
  Slot& slot = my_slot();
  // A decrement of a call not yet started is a release: the segment up to here precedes it.
  if (change < 0 && recording() && c->record != kNoRecord &&
      !c->started.load(std::memory_order_relaxed) && !slot.frames.empty() &&
      slot.frames.back().open) {
    slot.accesses.push_back({AccessRecord::kRelease, c->record, 0});
    raise_to(c->ready_seq, slot.frames.back().seq);
    split(slot);
  }
  const std::intptr_t left =
      c->count.fetch_add(static_cast<std::intptr_t>(change), std::memory_order_acq_rel) + change;
  if (left == 0 && !c->started.load(std::memory_order_relaxed)) make_ready(c, slot);
}

void Runtime::make_ready(Call* c, Slot& slot) {
  Slot& target = placed_ ? *slots_[c->home] : slot;
  // Read before the push: once pushed, the call may run, complete and be reused elsewhere.
  const bool root = c->root;
  target.push_front(c);
  // Under steal_root_only no other thread may take a call a call posted: none to wake.
  if (!steal_root_only_ || root) wake();
}

void Runtime::wake() {
  // seq_cst fence against a parking thread's seq_cst increment of sleepers_: either it sees
  // the work just published or this thread sees it registered and bumps the epoch.
  std::atomic_thread_fence(std::memory_order_seq_cst);
  if (sleepers_.load(std::memory_order_relaxed) != 0) {
    epoch_.fetch_add(1, std::memory_order_release);
    epoch_.notify_all();
  }
}

bool Runtime::any_work(const Slot& self) const {
  for (const auto& s : slots_) {
    const bool own = s.get() == &self;
    if ((own || !steal_root_only_ ? s->size : s->roots).load(std::memory_order_relaxed) != 0)
      return true;
  }
  return false;
}

Call* Runtime::find_work(Slot& slot) {
  if (Call* c = slot.pop_front()) return c;
  for (std::uint32_t i = 1; i < threads_; ++i) {
    Slot& other = *slots_[(slot.index + i) % threads_];
    if (Call* c = steal_root_only_ ? other.pop_back_root() : other.pop_back()) {
      slot.steals.store(slot.steals.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
      return c;
    }
  }
  return nullptr;
}

void Runtime::run(Call* c, Slot& slot) {
  c->started.store(true, std::memory_order_relaxed);
  c->count.store(1, std::memory_order_relaxed);  // the running call itself
  const char* outer = slot.running.load(std::memory_order_relaxed);
  slot.running_instance.store(c->instance, std::memory_order_relaxed);
  slot.running.store(c->name ? c->name : "(unnamed call)", std::memory_order_relaxed);
  slot.generation.store(slot.generation.load(std::memory_order_relaxed) + 1,
                        std::memory_order_relaxed);
  const bool rec = c->record != kNoRecord && recording();
  if (rec) {
    slot.frames.push_back(Frame{});
    open_segment(slot, c->record, 0, c->ready_seq.load(std::memory_order_relaxed), stamp());
  }
  Call* outer_call = slot.current;
  slot.current = c;
  const int ok = c->function(c->context, c->instance, reinterpret_cast<dCallReleaseeID>(c));
  slot.current = outer_call;
  if (rec) {
    // The last part of the call precedes what its completion releases: its wait, and its
    // releasee, or, when that one already runs (this call is its sub-call), what that one's
    // completion releases in turn.
    const std::uint64_t seq = slot.frames.back().seq;
    for (Call* x = c;;) {
      if (x->wait) {
        slot.accesses.push_back({AccessRecord::kSignal, x->wait->id, x->wait->generation});
        raise_to(x->wait->seq, seq);
      }
      Call* dep = x->releasee;
      if (!dep) break;
      if (!dep->started.load(std::memory_order_relaxed)) {
        if (dep->record != kNoRecord) {
          slot.accesses.push_back({AccessRecord::kRelease, dep->record, 0});
          raise_to(dep->ready_seq, seq);
        }
        break;
      }
      x = dep;
    }
    close_segment(slot, true, stamp());
    slot.frames.pop_back();
  }
  slot.running.store(outer, std::memory_order_relaxed);
  if (!ok) c->fault.store(1, std::memory_order_relaxed);  // published by the decrement below
  if (c->count.fetch_sub(1, std::memory_order_acq_rel) == 1) complete(c, slot);
}

void Runtime::complete(Call* c, Slot& slot) {
  while (true) {
    const int fault = c->fault.load(std::memory_order_relaxed);  // after an acq_rel decrement
    if (c->fault_out) *c->fault_out = fault;
    Wait* w = c->wait;
    Call* dep = c->releasee;
    free_call(c, slot);
    if (w) signal(w);  // after the fault is written: the waiter may read it at once
    if (!dep) return;
    if (fault) dep->fault.store(1, std::memory_order_relaxed);
    if (dep->count.fetch_sub(1, std::memory_order_acq_rel) != 1) return;
    if (!dep->started.load(std::memory_order_relaxed)) {
      make_ready(dep, slot);
      return;
    }
    c = dep;  // it had returned and this was its last sub-call: it completes too
  }
}

void Runtime::signal(Wait* w) {
  w->signalled.store(1, std::memory_order_release);
  wake();
}

void Runtime::park(Slot& slot, const std::atomic<std::uint32_t>* done) {
  const std::uint32_t e = epoch_.load(std::memory_order_acquire);
  sleepers_.fetch_add(1, std::memory_order_seq_cst);  // see wake()
  if (!any_work(slot) && !stop_.load(std::memory_order_acquire) &&
      !(done && done->load(std::memory_order_acquire))) {
    slot.parks.store(slot.parks.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
    epoch_.wait(e, std::memory_order_acquire);
  }
  sleepers_.fetch_sub(1, std::memory_order_relaxed);
}

void Runtime::wait(int* out_wait_status, dCallWaitID call_wait, const dThreadedWaitTime* timeout,
                   const char*) {
  auto* w = reinterpret_cast<Wait*>(call_wait);
  Slot& slot = my_slot();
  const bool rec = recording() && !slot.frames.empty() && slot.frames.back().open;
  if (rec) close_segment(slot, false, stamp());
  const char* outer = slot.running.exchange(nullptr, std::memory_order_relaxed);
  const bool bounded = timeout != nullptr;
  const std::int64_t deadline =
      bounded ? now_ns() + static_cast<std::int64_t>(timeout->wait_sec) * 1'000'000'000 +
                    static_cast<std::int64_t>(timeout->wait_nsec)
              : 0;
  int status = 1;
  while (!w->signalled.load(std::memory_order_acquire)) {
    if (Call* c = find_work(slot)) {
      run(c, slot);
      continue;
    }
    const std::int64_t t0 = now_ns();
    if (bounded && t0 >= deadline) {
      status = 0;
      break;
    }
    bool found = false;
    for (std::uint32_t spins = 0; !found; ++spins) {
      TGRAPH_ODE_PAUSE();
      found = w->signalled.load(std::memory_order_acquire) != 0 || any_work(slot);
      if ((spins & 63) == 63 && now_ns() - t0 > spin_ns_) break;
    }
    if (found) continue;
    if (!bounded) {
      park(slot, &w->signalled);
    } else {
      const std::int64_t left = deadline - now_ns();
      if (left > 0)
        std::this_thread::sleep_for(std::chrono::nanoseconds(std::min<std::int64_t>(left, 50'000)));
    }
  }
  slot.running.store(outer, std::memory_order_relaxed);
  if (rec) {
    const Frame f = slot.frames.back();
    open_segment(slot, f.call, f.seg + 1, status ? w->seq.load(std::memory_order_acquire) : 0,
                 stamp());
    if (status) slot.accesses.push_back({AccessRecord::kWaitRead, w->id, w->generation});
  }
  if (out_wait_status) *out_wait_status = status;
}

void Runtime::worker(std::uint32_t index) {
  tl_runtime = this;
  tl_slot = index;
  dAllocateODEDataForThread(dAllocateMaskAll);
  Slot& slot = *slots_[index];
  while (!stop_.load(std::memory_order_acquire)) {
    if (Call* c = find_work(slot)) {
      run(c, slot);
      continue;
    }
    const std::int64_t t0 = now_ns();
    bool found = false;
    for (std::uint32_t spins = 0; !found; ++spins) {
      TGRAPH_ODE_PAUSE();
      found = any_work(slot) || stop_.load(std::memory_order_relaxed);
      if ((spins & 63) == 63 && now_ns() - t0 > spin_ns_) break;
    }
    if (!found) park(slot, nullptr);
  }
  dCleanupODEAllDataForThread();
  tl_runtime = nullptr;
}

void Runtime::watchdog() {
  using namespace std::chrono;
  const auto period = milliseconds(20);
  std::vector<std::uint64_t> last(threads_, 0);
  std::vector<double> stuck(threads_, 0.0);
  while (!stop_.load(std::memory_order_acquire)) {
    std::this_thread::sleep_for(period);
    for (std::uint32_t i = 0; i < threads_; ++i) {
      Slot& s = *slots_[i];
      const char* name = s.running.load(std::memory_order_relaxed);
      const std::uint64_t g = s.generation.load(std::memory_order_relaxed);
      if (name == nullptr || g != last[i]) {
        last[i] = g;
        stuck[i] = 0;
        continue;
      }
      stuck[i] += duration<double>(period).count();
      if (stuck[i] >= watchdog_s_) {
        std::fprintf(stderr,
                     "tgraph: watchdog: ODE call \"%s\" (instance %zu) on thread %u has not "
                     "returned after %.1f s\n",
                     name,
                     static_cast<std::size_t>(s.running_instance.load(std::memory_order_relaxed)),
                     i, stuck[i]);
        std::fflush(stderr);
        std::_Exit(1);
      }
    }
  }
}

}  // namespace tgraph::ode::detail
