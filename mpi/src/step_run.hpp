// SPDX-License-Identifier: MIT
// One step of the distributed replay on one rank (replay.cpp drives it step by step): the
// rank's threads run their processors' programs, a communication engine posts persistent
// requests and polls them (OpenMPI has no asynchronous progress here: waiting threads drive
// it), a watchdog names what a stuck rank waits for. Private to tgraph::mpi.
#pragma once

#include <mpi.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "tgraph/mpi/replay.hpp"
#include "tgraph/replay/executor.hpp"

namespace tgraph::mpi {

// The clock the replay reports: the real one, or SMPI's simulated one.
inline std::int64_t now_ns() {
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

// Polls of a waiting thread before it yields between polls (each a lock and an MPI_Test:
// 0.1-0.2 us here, so about 100 us; a rank sharing its core with another one waits for
// that one's time slice, milliseconds, either way).
constexpr std::uint32_t kPollsBeforeYield = 1000;

// A lowered structure + assignment with its channels and persistent requests.
struct Plan {
  StepGraph structure;
  std::vector<ProcId> proc;
  std::uint64_t hash = 0;
  ExecGraph exec;
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

// One step on one rank.
class StepRun {
 public:
  StepRun(Plan& plan, const StepSchedule& s, RankWorkload& w, std::uint32_t me,
          const Layout& layout, std::optional<std::uint32_t> drop);

  // Runs the step on this rank: entering sends, threads, completion of every send.
  Counters run(std::int64_t watchdog_ns);

  const Traffic& measured() const { return measured_; }

 private:
  void make_request(std::uint32_t c);

  // The threads' counters added up, with the rank's own.
  Counters sum(const std::vector<Counters>& counters) const;

  // For the watchdog (none in an SMPI build, whose clock calls would cost simulated time).
  void progress();

  // Completes what MPI has finished; `block`: waits until at least one request completes
  // (the single-threaded SMPI rank, which has nothing else to do). Caller holds mu_.
  void poll(bool block = false);
  // Tests channel c's request alone when it is in flight: a waiting thread does not scan
  // every request of the plan (an SMPI rank tests them all, as poll()). Caller holds mu_.
  void test_channel(std::uint32_t c);
  // What a completed request on channel c means: a send's buffer is free, a datum version
  // arrived, a loop decision is known (then the next receive on c starts). Holds mu_.
  void complete(std::uint32_t c);
  void start_receive(std::uint32_t c);

  // Installs message m when it arrived and this rank's older readers are done. Holds mu_.
  bool try_install(std::uint32_t m);

  // Waits until channel c's previous message has left (its buffer is free again); `lock`
  // holds mu_, released while yielding.
  void wait_channel_free(std::unique_lock<std::mutex>& lock, std::uint32_t c);

  // Sends message m (the producing instance has run; its datum is not being written).
  void send(std::uint32_t m);

  void send_decision(std::uint32_t k, bool stop);

  bool ready(const Wait& w);

  std::string describe(const Wait& w, const Instance* for_inst) const;

  // A thread whose next item is not ready (its `polls`-th try) polls again at once for the
  // first kPollsBeforeYield tries, then lets the others run between tries; a single-threaded
  // (SMPI) rank blocks in MPI until one of its requests completes.
  void idle(std::uint32_t& polls);

  void set_waiting(std::uint32_t slot, std::string what);

  [[noreturn]] void stuck(std::int64_t watchdog_ns);

  void wait_for(const Wait& w, const Instance* inst, std::uint32_t slot, Counters& c);

  void work(ProcId p, std::uint32_t slot, Counters& c);

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
  std::vector<bool> sending_, receiving_;           // by channel: a request in flight
  std::vector<std::uint32_t> decision_channel_;      // by decision: its channel to this rank
                                                     // (kNone: decided on this rank)
  std::vector<int> indices_;
  std::int64_t received_ = 0, decisions_received_ = 0, decision_latency_ns_ = 0;
  Traffic measured_;
  std::atomic<std::uint64_t> progress_{0};  // relaxed: counts progress for the watchdog
  std::mutex waiting_mu_;
  std::vector<std::string> waiting_;
};

}  // namespace tgraph::mpi
