// SPDX-License-Identifier: MIT
// The distributed replay: per step a schedule (schedule.cpp), threads that run it, and one
// communication engine per rank that posts persistent requests and polls them (OpenMPI has
// no asynchronous progress here: waiting threads drive it).
//
// Built with SimGrid's smpicxx (TGRAPH_SMPI, scripts/smpi-build) the same schedule runs on
// the simulated platform of `smpirun`: SMPI gives MPI_THREAD_SINGLE and charges simulated
// time only to MPI calls and to explicit executions, so each rank runs its one processor's
// program on the main thread, blocks in MPI_Waitsome where the threads would poll, charges
// each task's recorded cost as flops on its host (1 flop per ns, the cost model of
// `tgraph platform` and of `tgraph simulate --engine simgrid`) and reads the simulated clock.
#include "tgraph/mpi/replay.hpp"

#include <mpi.h>
#include <sched.h>
#ifdef TGRAPH_SMPI
#include <smpi/smpi.h>
#endif

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <unordered_map>

#include "tgraph/graph/error.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/observer.hpp"

namespace tgraph::mpi {

void RankWorkload::set_step(const StepGraph& step) {
  step_ = &step;
  uncosted_ = step;
  for (Task& t : uncosted_.tasks) t.cost_ns = 0;
  inner_.set_step(uncosted_);
}

void RankWorkload::run(const replay::TaskRun& r) {
  const std::int64_t t0 = replay::now_ns();
  inner_.run(r);
  if (r.origin == kNoTask || step_ == nullptr) return;
#ifdef TGRAPH_SMPI
  // The data pass above is real work that SMPI does not time (smpirun
  // --cfg=smpi/simulate-computation:no); the task's recorded cost is what the host executes.
  (void)t0;
  const double flops = static_cast<double>(step_->tasks[r.origin].cost_ns) * scale_;
  if (flops > 0) smpi_execute_flops(flops);
  return;
#endif
  const double left = static_cast<double>(step_->tasks[r.origin].cost_ns) * scale_ -
                      static_cast<double>(replay::now_ns() - t0);
  if (left <= 0) return;
  const double rate = replay::SyntheticWorkload::calibration().spin_iterations_per_ns;
  volatile std::uint64_t sink =
      replay::spin_iterations(static_cast<std::uint64_t>(left * rate), r.origin + 1);
  (void)sink;
}

void RankWorkload::run_host(const StepGraph& step) {
#ifdef TGRAPH_SMPI
  if (step.host_ns > 0) smpi_execute_flops(static_cast<double>(step.host_ns) * scale_);
#else
  inner_.run_host(step);
#endif
}

std::span<std::uint64_t> RankWorkload::mutable_words(DatumId d) {
  const auto w = inner_.words(d);
  // The buffer is this workload's own, allocated non-const (SyntheticWorkload::first_touch).
  return {const_cast<std::uint64_t*>(w.data()), w.size()};
}

std::uint64_t datum_hash(DatumId d, std::span<const std::uint64_t> words) {
  std::uint64_t h =
      1469598103934665603ull ^ (static_cast<std::uint64_t>(d) * 0x9e3779b97f4a7c15ull);
  for (std::uint64_t w : words) h = (h ^ w) * 1099511628211ull;
  return h ^ (h >> 29);
}

namespace {

// The clock the replay reports: the real one, or SMPI's simulated one.
std::int64_t now_ns() {
#ifdef TGRAPH_SMPI
  return static_cast<std::int64_t>(MPI_Wtime() * 1e9);
#else
  return replay::now_ns();
#endif
}

// Whether this build runs every rank's work on its main thread (SMPI).
#ifdef TGRAPH_SMPI
constexpr bool kSingleThreaded = true;
#else
constexpr bool kSingleThreaded = false;
#endif

// Plans (lowered structure + assignment, channels, persistent requests) kept at once.
constexpr std::size_t kMaxPlans = 16;

// A lowered structure + assignment with its channels and persistent requests.
struct Plan {
  StepGraph structure;
  std::vector<ProcId> proc;
  std::uint64_t hash = 0;
  replay::ExecGraph exec;
  ChannelTable channels;
  std::vector<MPI_Request> requests;                // by channel (MPI_REQUEST_NULL: not ours)
  std::vector<std::vector<std::uint64_t>> buffers;  // by channel
  ~Plan() {
    for (MPI_Request& r : requests)
      if (r != MPI_REQUEST_NULL) MPI_Request_free(&r);
  }
};

// What one rank's threads counted in one step.
struct Counters {
  std::int64_t local_wait_ns = 0, message_wait_ns = 0, decision_wait_ns = 0;
  std::int64_t received = 0, hidden = 0, decisions_received = 0, decision_latency_ns = 0;
};
constexpr int kCounters = 7;

// One step on one rank.
class StepRun {
 public:
  StepRun(Plan& plan, const StepSchedule& s, RankWorkload& w, std::uint32_t me,
          const Layout& layout, std::optional<std::uint32_t> drop)
      : plan_(plan),
        s_(s),
        w_(w),
        me_(me),
        layout_(layout),
        drop_(drop),
        done_(new std::atomic<std::uint8_t>[s.instances.size()]),
        arrived_(new std::atomic<std::uint8_t>[s.messages.size()]),
        installed_(new std::atomic<std::uint8_t>[s.messages.size()]),
        checked_(new std::atomic<std::uint8_t>[s.messages.size()]),
        decided_(new std::atomic<std::int8_t>[s.decisions.size()]),
        measured_(layout.ranks) {
    for (std::size_t i = 0; i < s.instances.size(); ++i)
      done_[i].store(0, std::memory_order_relaxed);
    for (std::size_t i = 0; i < s.messages.size(); ++i) {
      arrived_[i].store(0, std::memory_order_relaxed);
      installed_[i].store(0, std::memory_order_relaxed);
      checked_[i].store(0, std::memory_order_relaxed);
    }
    for (std::size_t i = 0; i < s.decisions.size(); ++i)
      decided_[i].store(-1, std::memory_order_relaxed);
    const std::size_t nc = plan.channels.channels().size();
    plan.requests.resize(nc, MPI_REQUEST_NULL);
    plan.buffers.resize(nc);
    queue_.assign(nc, {});
    next_.assign(nc, 0);
    sending_.assign(nc, false);
    for (std::uint32_t m = 0; m < s.messages.size(); ++m)
      if (s.messages[m].to == me) queue_[s.messages[m].channel].push_back(m);
    for (std::uint32_t k = 0; k < s.decisions.size(); ++k)
      for (std::size_t j = 0; j < s.decisions[k].to.size(); ++j)
        if (s.decisions[k].to[j] == me) queue_[s.decisions[k].channels[j]].push_back(k);
    for (std::uint32_t c = 0; c < nc; ++c) make_request(c);
  }

  // Runs the step on this rank: entering sends, threads, completion of every send.
  Counters run(std::int64_t watchdog_ns) {
    last_progress_.store(now_ns(), std::memory_order_relaxed);
    {
      std::lock_guard lock(mu_);
      for (std::uint32_t c = 0; c < queue_.size(); ++c)
        if (!queue_[c].empty()) MPI_Start(&plan_.requests[c]);
    }
    for (std::uint32_t m : s_.entering)
      if (s_.messages[m].from == me_) send(m);
    const std::uint32_t T = layout_.threads_per_rank;
    waiting_.assign(T + 1, std::string());
    std::vector<Counters> counters(T);
    if constexpr (kSingleThreaded) {
      // SMPI: the rank's only processor on this thread; SimGrid itself reports a deadlock.
      work(me_ * T, 0, counters[0]);
      for (;;) {
        std::lock_guard lock(mu_);
        if (std::none_of(sending_.begin(), sending_.end(), [](bool b) { return b; })) break;
        poll(true);
      }
      return sum(counters);
    }
    std::vector<std::thread> threads;
    bool running = true;  // guarded by stop_mu
    std::mutex stop_mu;
    std::condition_variable stop_cv;
    std::thread watchdog([&] {
      std::unique_lock lock(stop_mu);
      while (running) {
        stop_cv.wait_for(lock, std::chrono::milliseconds(20));
        if (running && watchdog_ns > 0 &&
            now_ns() - last_progress_.load(std::memory_order_relaxed) > watchdog_ns)
          stuck(watchdog_ns);
      }
    });
    for (std::uint32_t t = 0; t < T; ++t)
      threads.emplace_back(
          [this, t, &counters] { work(me_ * layout_.threads_per_rank + t, t, counters[t]); });
    for (auto& th : threads) th.join();
    set_waiting(T, "the completion of its sends");
    for (;;) {
      std::unique_lock lock(mu_);
      poll();
      if (std::none_of(sending_.begin(), sending_.end(), [](bool b) { return b; })) break;
      lock.unlock();
      sched_yield();
    }
    {
      std::lock_guard lock(stop_mu);
      running = false;
    }
    stop_cv.notify_one();
    watchdog.join();
    return sum(counters);
  }

  const Traffic& measured() const { return measured_; }

 private:
  void make_request(std::uint32_t c) {
    if (plan_.requests[c] != MPI_REQUEST_NULL) return;
    const Channel& ch = plan_.channels.channels()[c];
    if (ch.from != me_ && ch.to != me_) return;
    auto& buf = plan_.buffers[c];
    buf.assign((ch.bytes + 7) / 8, 0);
    const int count = static_cast<int>(ch.bytes);
    const int tag = static_cast<int>(c);
    if (ch.from == me_)
      MPI_Send_init(buf.data(), count, MPI_BYTE, static_cast<int>(ch.to), tag, MPI_COMM_WORLD,
                    &plan_.requests[c]);
    else
      MPI_Recv_init(buf.data(), count, MPI_BYTE, static_cast<int>(ch.from), tag, MPI_COMM_WORLD,
                    &plan_.requests[c]);
  }

  // The threads' counters added up, with the rank's own.
  Counters sum(const std::vector<Counters>& counters) const {
    Counters total;
    for (const Counters& c : counters) {
      total.local_wait_ns += c.local_wait_ns;
      total.message_wait_ns += c.message_wait_ns;
      total.decision_wait_ns += c.decision_wait_ns;
      total.hidden += c.hidden;
    }
    total.received = received_;
    total.decisions_received = decisions_received_;
    total.decision_latency_ns = decision_latency_ns_;
    return total;
  }

  // For the watchdog (none in an SMPI build, whose clock calls would cost simulated time).
  void progress() {
    if constexpr (!kSingleThreaded) last_progress_.store(now_ns(), std::memory_order_relaxed);
  }

  // Completes what MPI has finished; `block`: waits until at least one request completes
  // (the single-threaded SMPI rank, which has nothing else to do). Caller holds mu_.
  void poll(bool block = false) {
    const int n = static_cast<int>(plan_.requests.size());
    if (n == 0 && !block) return;
    indices_.resize(plan_.requests.size());
    int out = 0;
    if (block)
      MPI_Waitsome(n, plan_.requests.data(), &out, indices_.data(), MPI_STATUSES_IGNORE);
    else
      MPI_Testsome(n, plan_.requests.data(), &out, indices_.data(), MPI_STATUSES_IGNORE);
    if (out == MPI_UNDEFINED) {
      if (block) throw std::logic_error("a rank waits with no message in flight");
      return;
    }
    for (int i = 0; i < out; ++i) {
      const auto c = static_cast<std::uint32_t>(indices_[i]);
      const Channel& ch = plan_.channels.channels()[c];
      if (ch.from == me_) {
        sending_[c] = false;
        continue;
      }
      const std::uint32_t use = queue_[c][next_[c]];
      if (ch.decision) {
        const auto& buf = plan_.buffers[c];
        decided_[use].store(buf[0] != 0 ? 1 : 0, std::memory_order_release);
        ++decisions_received_;
        decision_latency_ns_ += now_ns() - static_cast<std::int64_t>(buf[1]);
        if (++next_[c] < queue_[c].size()) MPI_Start(&plan_.requests[c]);
      } else {
        arrived_[use].store(1, std::memory_order_relaxed);
        ++received_;
      }
      progress();
    }
  }

  // Installs message m when it arrived and this rank's older readers are done. Holds mu_.
  bool try_install(std::uint32_t m) {
    if (installed_[m].load(std::memory_order_acquire)) return true;
    if (!arrived_[m].load(std::memory_order_relaxed)) poll();
    if (!arrived_[m].load(std::memory_order_relaxed)) return false;
    const Message& msg = s_.messages[m];
    for (std::uint32_t h : msg.hazards)
      if (!done_[h].load(std::memory_order_acquire)) return false;
    const auto dst = w_.mutable_words(msg.datum);
    const auto& buf = plan_.buffers[msg.channel];
    std::copy_n(buf.begin(), std::min(dst.size(), buf.size()), dst.begin());
    // release: the words written above are visible to whoever sees installed_.
    installed_[m].store(1, std::memory_order_release);
    const std::uint32_t c = msg.channel;
    if (++next_[c] < queue_[c].size()) MPI_Start(&plan_.requests[c]);
    progress();
    return true;
  }

  // Waits until channel c's previous message has left (its buffer is free again); `lock`
  // holds mu_, released while yielding.
  void wait_channel_free(std::unique_lock<std::mutex>& lock, std::uint32_t c) {
    while (sending_[c]) {
      if constexpr (kSingleThreaded) {
        poll(true);
        continue;
      }
      poll();
      lock.unlock();
      sched_yield();
      lock.lock();
    }
  }

  // Sends message m (the producing instance has run; its datum is not being written).
  void send(std::uint32_t m) {
    if (drop_ && *drop_ == m) return;
    const Message& msg = s_.messages[m];
    const std::uint32_t c = msg.channel;
    std::unique_lock lock(mu_);
    wait_channel_free(lock, c);
    auto& buf = plan_.buffers[c];
    const auto src = w_.mutable_words(msg.datum);
    std::fill(buf.begin(), buf.end(), 0);
    std::copy_n(src.begin(), std::min(src.size(), buf.size()), buf.begin());
    if (msg.zero_after_send) std::fill(src.begin(), src.end(), 0);
    MPI_Start(&plan_.requests[c]);
    sending_[c] = true;
    measured_.messages[me_ * layout_.ranks + msg.to] += 1;
    measured_.bytes[me_ * layout_.ranks + msg.to] += msg.bytes;
    if (msg.source == kNone) {
      measured_.entering_messages += 1;
      measured_.entering_bytes += msg.bytes;
    }
  }

  void send_decision(std::uint32_t k, bool stop) {
    const Decision& d = s_.decisions[k];
    std::unique_lock lock(mu_);
    for (std::size_t j = 0; j < d.to.size(); ++j) {
      const std::uint32_t c = d.channels[j];
      wait_channel_free(lock, c);
      auto& buf = plan_.buffers[c];
      buf[0] = stop ? 1 : 0;
      buf[1] = static_cast<std::uint64_t>(now_ns());
      MPI_Start(&plan_.requests[c]);
      sending_[c] = true;
      measured_.decisions[me_ * layout_.ranks + d.to[j]] += 1;
    }
  }

  bool ready(const Wait& w) {
    switch (w.kind) {
      case WaitKind::kInstance:
        return done_[w.index].load(std::memory_order_acquire) != 0;
      case WaitKind::kMessage: {
        if (installed_[w.index].load(std::memory_order_acquire)) return true;
        std::lock_guard lock(mu_);
        return try_install(w.index);
      }
      case WaitKind::kDecision: {
        if (decided_[w.index].load(std::memory_order_acquire) >= 0) return true;
        std::lock_guard lock(mu_);
        poll();
        return decided_[w.index].load(std::memory_order_acquire) >= 0;
      }
    }
    return false;
  }

  std::string describe(const Wait& w, const Instance* for_inst) const {
    std::ostringstream o;
    const StepGraph& g = plan_.exec.graph;
    if (for_inst != nullptr)
      o << "task " << for_inst->task << " (" << g.kinds[g.tasks[for_inst->task].kind]
        << ") iteration " << for_inst->iteration << " waits for ";
    switch (w.kind) {
      case WaitKind::kInstance: {
        const Instance& i = s_.instances[w.index];
        o << "task " << i.task << " iteration " << i.iteration << " on this rank";
        break;
      }
      case WaitKind::kMessage: {
        const Message& m = s_.messages[w.index];
        o << "datum " << m.datum << " (" << g.data[m.datum].name << ") from rank " << m.from;
        break;
      }
      case WaitKind::kDecision: {
        const Decision& d = s_.decisions[w.index];
        o << "the decision of loop " << d.loop << " iteration " << d.iteration << " from rank "
          << d.from;
        break;
      }
    }
    return o.str();
  }

  // A thread whose next item is not ready lets the others run; a single-threaded (SMPI) rank
  // blocks in MPI until one of its requests completes.
  void idle() {
    if constexpr (kSingleThreaded) {
      std::lock_guard lock(mu_);
      poll(true);
    } else {
      sched_yield();
    }
  }

  void set_waiting(std::uint32_t slot, std::string what) {
    std::lock_guard lock(waiting_mu_);
    waiting_[slot] = std::move(what);
  }

  [[noreturn]] void stuck(std::int64_t watchdog_ns) {
    std::string what;
    {
      std::lock_guard lock(waiting_mu_);
      for (std::uint32_t t = 0; t < waiting_.size(); ++t)
        if (!waiting_[t].empty()) {
          what += what.empty() ? "" : "; ";
          what += (t < layout_.threads_per_rank ? "thread " + std::to_string(t) + ": " : "main: ") +
                  waiting_[t];
        }
    }
    std::fprintf(stderr, "tgraph-mpi: watchdog: rank %u made no progress for %.1f s: %s\n", me_,
                 static_cast<double>(watchdog_ns) / 1e9,
                 what.empty() ? "(running a task)" : what.c_str());
    std::fflush(stderr);
    MPI_Abort(MPI_COMM_WORLD, 1);
    std::abort();
  }

  void wait_for(const Wait& w, const Instance* inst, std::uint32_t slot, Counters& c) {
    if (ready(w)) {
      if (w.kind == WaitKind::kMessage && !checked_[w.index].exchange(1)) ++c.hidden;
      return;
    }
    if (w.kind == WaitKind::kMessage) checked_[w.index].store(1);
    const std::int64_t t0 = now_ns();
    set_waiting(slot, describe(w, inst));
    while (!ready(w)) idle();
    set_waiting(slot, {});
    const std::int64_t dt = now_ns() - t0;
    switch (w.kind) {
      case WaitKind::kInstance:
        c.local_wait_ns += dt;
        break;
      case WaitKind::kMessage:
        c.message_wait_ns += dt;
        break;
      case WaitKind::kDecision:
        c.decision_wait_ns += dt;
        break;
    }
  }

  void work(ProcId p, std::uint32_t slot, Counters& c) {
    try {
      for (const ProgramItem& item : s_.programs[p]) {
        if (item.decision) {
          wait_for(Wait{WaitKind::kDecision, item.index}, nullptr, slot, c);
          const bool stop = decided_[item.index].load(std::memory_order_acquire) == 1;
          if (stop != s_.decisions[item.index].stop)
            throw std::logic_error("a loop decision differs from the recorded iteration count");
          continue;
        }
        const Instance& inst = s_.instances[item.index];
        for (const Wait& w : inst.waits) wait_for(w, &inst, slot, c);
        replay::TaskRun r;
        r.exec = &plan_.exec;
        r.task = inst.task;
        r.origin = plan_.exec.origin[inst.task];
        r.iteration = inst.iteration;
        r.thread = slot;
        w_.run(r);
        for (std::uint32_t m : inst.sends) send(m);
        if (inst.decision != kNone) {
          const Decision& d = s_.decisions[inst.decision];
          const bool stop = w_.stop_after(d.loop, d.iteration);
          if (stop != d.stop)
            throw std::logic_error("the workload's loop condition differs from its recorded count");
          // release: the decision is published after the task's writes.
          decided_[inst.decision].store(stop ? 1 : 0, std::memory_order_release);
          send_decision(inst.decision, stop);
        }
        // release: readers of done_ see the instance's writes.
        done_[item.index].store(1, std::memory_order_release);
        progress();
      }
    } catch (const std::exception& e) {
      std::fprintf(stderr, "tgraph-mpi: rank %u: %s\n", me_, e.what());
      std::fflush(stderr);
      MPI_Abort(MPI_COMM_WORLD, 1);
    }
  }

  Plan& plan_;
  const StepSchedule& s_;
  RankWorkload& w_;
  std::uint32_t me_;
  Layout layout_;
  std::optional<std::uint32_t> drop_;
  // done_: release by the thread that ran the instance, acquire by waiters (its writes).
  std::unique_ptr<std::atomic<std::uint8_t>[]> done_;
  // arrived_: written and read under mu_ (relaxed is enough; the lock orders).
  std::unique_ptr<std::atomic<std::uint8_t>[]> arrived_;
  // installed_: release after the copy into the rank's datum, acquire by its readers.
  std::unique_ptr<std::atomic<std::uint8_t>[]> installed_;
  // checked_: only counts the versions that arrived before anyone waited (a statistic).
  std::unique_ptr<std::atomic<std::uint8_t>[]> checked_;
  // decided_: release by whoever learnt the decision, acquire by the threads it lets go on.
  std::unique_ptr<std::atomic<std::int8_t>[]> decided_;
  std::mutex mu_;                                  // MPI calls and the channel state below
  std::vector<std::vector<std::uint32_t>> queue_;  // by channel: this rank's receives in order
  std::vector<std::size_t> next_;
  std::vector<bool> sending_;
  std::vector<int> indices_;
  std::int64_t received_ = 0, decisions_received_ = 0, decision_latency_ns_ = 0;
  Traffic measured_;
  std::atomic<std::int64_t> last_progress_{0};  // relaxed: only the watchdog's estimate
  std::mutex waiting_mu_;
  std::vector<std::string> waiting_;
};

void sum_to_root(std::vector<std::uint64_t>& v) {
  std::vector<std::uint64_t> out(v.size(), 0);
  MPI_Reduce(v.data(), out.data(), static_cast<int>(v.size()), MPI_UINT64_T, MPI_SUM, 0,
             MPI_COMM_WORLD);
  v = std::move(out);
}

// Waits at a barrier without spinning (ranks idle while rank 0 runs the sequential replay).
void quiet_barrier() {
  if constexpr (kSingleThreaded) {
    MPI_Barrier(MPI_COMM_WORLD);
    return;
  }
  MPI_Request r;
  MPI_Ibarrier(MPI_COMM_WORLD, &r);
  int flag = 0;
  for (;;) {
    MPI_Test(&r, &flag, MPI_STATUS_IGNORE);
    if (flag) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

}  // namespace

MpiReplayResult replay_distributed(const Trace& trace, const TraceAssignment& assignment,
                                   const MpiReplayOptions& options) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const auto me = static_cast<std::uint32_t>(rank);
  Layout layout{static_cast<std::uint32_t>(size), options.threads_per_rank};
  if (kSingleThreaded && layout.threads_per_rank != 1)
    throw UsageError("--threads-per-rank: an SMPI build runs one processor per rank (found " +
                     std::to_string(layout.threads_per_rank) + ")");
  if (assignment.k != layout.processors())
    throw UsageError(
        "the assignment has " + std::to_string(assignment.k) +
        " processors; ranks x --threads-per-rank = " + std::to_string(layout.processors()));
  const std::size_t steps =
      std::min<std::size_t>(trace.steps.size(), options.steps.value_or(trace.steps.size()));
  if (assignment.steps.size() < steps)
    throw UsageError("the assignment has fewer steps than the trace");

  MpiReplayResult result;
  result.ranks = layout.ranks;
  result.threads_per_rank = layout.threads_per_rank;
  RankWorkload w;
  std::vector<std::unique_ptr<Plan>> plans;
  Plan* bound = nullptr;
  Holders holders = everywhere(0, layout.ranks);
  // The previous step's processor of each task, by stable key (a repartition moves a task
  // that both steps have; a new structure alone is not one).
  std::unordered_map<StableKey, ProcId> previous_owner;
  for (std::size_t si = 0; si < steps; ++si) {
    const StepGraph& step = trace.steps[si];
    Assignment a = assignment.steps[si];
    if (std::string why = validate(step, a, layout.processors()); !why.empty())
      throw UsageError("step " + std::to_string(si) + ": " + why);
    a.order.clear();  // each processor runs its tasks in program order
    const std::uint64_t hash = step.structural_hash();
    Plan* plan = nullptr;
    for (auto& p : plans)
      if (p->hash == hash && p->proc == a.proc && p->structure.same_structure(step)) plan = p.get();
    if (plan == nullptr) {
      // At most kMaxPlans kept (every rank evicts the same ones: they see the same steps);
      // between steps no request is active, so freeing a plan's requests is safe.
      if (plans.size() >= kMaxPlans) {
        const auto victim = std::find_if(plans.begin(), plans.end(),
                                         [&](const auto& q) { return q.get() != bound; });
        if (victim != plans.end()) plans.erase(victim);
      }
      auto p = std::make_unique<Plan>();
      p->structure = step;
      p->proc = a.proc;
      p->hash = hash;
      p->exec =
          replay::lower(step, &a, replay::CwMode::kReduce, replay::ReduceScope::kPerProcessor);
      plan = p.get();
      plans.push_back(std::move(p));
    }
    w.set_step(step);
    const std::size_t known = holders.has.size() / layout.ranks;
    holders.grow(std::max(known, step.data.size()), known);
    if (plan != bound) {
      w.bind(plan->exec);
      bound = plan;
    }
    for (DatumId d = 0; d < plan->exec.graph.data.size(); ++d)
      if (w.needs_touch(d)) {
        w.first_touch(d);
        if (d < step.data.size())
          for (std::uint32_t r = 0; r < layout.ranks; ++r) holders.has[d * layout.ranks + r] = 1;
      }
    const std::optional<std::uint32_t> drop = si == 0 ? options.test_drop_message : std::nullopt;
    StepSchedule s = schedule_step(plan->exec, step, layout, holders, plan->channels);
    MpiStepResult sr;
    sr.predicted = s.traffic;
    std::unordered_map<StableKey, ProcId> owner;
    for (TaskId t = 0; t < step.tasks.size(); ++t) {
      owner[step.tasks[t].key] = a.proc[t];
      const auto it = previous_owner.find(step.tasks[t].key);
      sr.repartitioned =
          sr.repartitioned || (it != previous_owner.end() && it->second != a.proc[t]);
    }
    previous_owner = std::move(owner);
    MPI_Barrier(MPI_COMM_WORLD);
    const std::int64_t t0 = now_ns();
    if (options.host_work) {
      if (me == 0) w.run_host(step);
      MPI_Barrier(MPI_COMM_WORLD);
    }
    StepRun run(*plan, s, w, me, layout, drop);
    const Counters c = run.run(static_cast<std::int64_t>(options.watchdog_s * 1e9));
    // SMPI's clock is one simulated clock for every rank: the step ends when the last rank's
    // work ends, before the counters' reduction below (3 R^2 words through a tree: 0.38 ms
    // at 64 ranks on a 4 x 16 platform, time the simulator does not model). With a real MPI
    // (one clock per process) the step ends on rank 0 after that reduction.
    std::int64_t last_end = 0;
    if constexpr (kSingleThreaded) {
      const std::int64_t end = now_ns();
      MPI_Reduce(&end, &last_end, 1, MPI_INT64_T, MPI_MAX, 0, MPI_COMM_WORLD);
    }
    std::vector<std::uint64_t> sums = {static_cast<std::uint64_t>(c.local_wait_ns),
                                       static_cast<std::uint64_t>(c.message_wait_ns),
                                       static_cast<std::uint64_t>(c.decision_wait_ns),
                                       static_cast<std::uint64_t>(c.received),
                                       static_cast<std::uint64_t>(c.hidden),
                                       static_cast<std::uint64_t>(c.decisions_received),
                                       static_cast<std::uint64_t>(c.decision_latency_ns)};
    static_assert(kCounters == 7);
    const Traffic& m = run.measured();
    sums.insert(sums.end(), m.messages.begin(), m.messages.end());
    sums.insert(sums.end(), m.bytes.begin(), m.bytes.end());
    sums.insert(sums.end(), m.decisions.begin(), m.decisions.end());
    sums.push_back(m.entering_messages);
    sums.push_back(m.entering_bytes);
    sum_to_root(sums);
    sr.wall_ns = (kSingleThreaded ? last_end : now_ns()) - t0;
    holders = s.holders_after;
    if (me != 0) continue;
    sr.local_wait_ns = static_cast<std::int64_t>(sums[0]);
    sr.message_wait_ns = static_cast<std::int64_t>(sums[1]);
    sr.decision_wait_ns = static_cast<std::int64_t>(sums[2]);
    sr.received = sums[3];
    sr.hidden = sums[4];
    sr.decisions_received = sums[5];
    sr.decision_latency_ns = static_cast<std::int64_t>(sums[6]);
    const std::size_t R2 = static_cast<std::size_t>(layout.ranks) * layout.ranks;
    sr.measured = Traffic(layout.ranks);
    for (std::size_t i = 0; i < R2; ++i) {
      sr.measured.messages[i] = sums[kCounters + i];
      sr.measured.bytes[i] = sums[kCounters + R2 + i];
      sr.measured.decisions[i] = sums[kCounters + 2 * R2 + i];
    }
    sr.measured.entering_messages = sums[kCounters + 3 * R2];
    sr.measured.entering_bytes = sums[kCounters + 3 * R2 + 1];
    sr.migrated_bytes = sr.repartitioned ? sr.measured.entering_bytes : 0;
    result.wall_ns += sr.wall_ns;
    result.steps.push_back(std::move(sr));
  }

  // The checksum: each original datum from the lowest rank holding its latest version.
  const std::size_t n_orig = steps > 0 ? trace.steps[steps - 1].data.size() : 0;
  std::uint64_t part = 0;
  for (DatumId d = 0; d < n_orig; ++d)
    if (holders.first(d) == me) part += datum_hash(d, w.words(d));
  std::vector<std::uint64_t> sum = {part};
  sum_to_root(sum);
  result.checksum = sum[0];

  {  // the sequential replay of the same steps and bodies, on rank 0 (speed-up and check)
    if (me == 0) {
      auto seq = replay::make_executor(replay::Policy::kSequential, {});
      RankWorkload sw;
      for (std::size_t si = 0; si < steps; ++si) {
        sw.set_step(trace.steps[si]);
        const std::int64_t t0 = now_ns();
        if (options.host_work) sw.run_host(trace.steps[si]);
        seq->run_step(trace.steps[si], nullptr, sw);
        result.steps[si].sequential_ns = now_ns() - t0;
        result.sequential_ns += result.steps[si].sequential_ns;
      }
      std::uint64_t h = 0;
      for (DatumId d = 0; d < n_orig; ++d) h += datum_hash(d, sw.words(d));
      result.sequential_checksum = h;
      if (options.check) result.identical = h == result.checksum;
    }
    quiet_barrier();
  }
  return result;
}

}  // namespace tgraph::mpi
