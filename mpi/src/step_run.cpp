// SPDX-License-Identifier: MIT
// One step of the distributed replay on one rank (step_run.hpp).
#include "step_run.hpp"

#include <sched.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "tgraph/replay/observer.hpp"

namespace tgraph::mpi {

StepRun::StepRun(Plan& plan, const StepSchedule& s, RankWorkload& w, std::uint32_t me,
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
  receiving_.assign(nc, false);
  decision_channel_.assign(s.decisions.size(), kNone);
  for (std::uint32_t m = 0; m < s.messages.size(); ++m)
    if (s.messages[m].to == me) queue_[s.messages[m].channel].push_back(m);
  for (std::uint32_t k = 0; k < s.decisions.size(); ++k)
    for (std::size_t j = 0; j < s.decisions[k].to.size(); ++j)
      if (s.decisions[k].to[j] == me) {
        queue_[s.decisions[k].channels[j]].push_back(k);
        decision_channel_[k] = s.decisions[k].channels[j];
      }
  for (std::uint32_t c = 0; c < nc; ++c) make_request(c);
}

Counters StepRun::run(std::int64_t watchdog_ns) {
  {
    std::lock_guard lock(mu_);
    for (std::uint32_t c = 0; c < queue_.size(); ++c)
      if (!queue_[c].empty()) start_receive(c);
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
    std::uint64_t seen = progress_.load(std::memory_order_relaxed);
    std::int64_t since = now_ns();
    while (running) {
      stop_cv.wait_for(lock, std::chrono::milliseconds(20));
      const std::uint64_t now_seen = progress_.load(std::memory_order_relaxed);
      if (now_seen != seen) {
        seen = now_seen;
        since = now_ns();
      } else if (running && watchdog_ns > 0 && now_ns() - since > watchdog_ns) {
        stuck(watchdog_ns);
      }
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

void StepRun::make_request(std::uint32_t c) {
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

Counters StepRun::sum(const std::vector<Counters>& counters) const {
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

void StepRun::progress() {
  // No clock read per task: the watchdog sees the count change. Threads may overwrite each
  // other's increment; the count still moves, which is all the watchdog asks.
  if constexpr (!kSingleThreaded)
    progress_.store(progress_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
}

void StepRun::start_receive(std::uint32_t c) {
  MPI_Start(&plan_.requests[c]);
  receiving_[c] = true;
}

void StepRun::complete(std::uint32_t c) {
  const Channel& ch = plan_.channels.channels()[c];
  if (ch.from == me_) {
    sending_[c] = false;
    return;
  }
  receiving_[c] = false;
  const std::uint32_t use = queue_[c][next_[c]];
  if (ch.decision) {
    const auto& buf = plan_.buffers[c];
    decided_[use].store(buf[0] != 0 ? 1 : 0, std::memory_order_release);
    ++decisions_received_;
    decision_latency_ns_ += now_ns() - static_cast<std::int64_t>(buf[1]);
    if (++next_[c] < queue_[c].size()) start_receive(c);
  } else {
    arrived_[use].store(1, std::memory_order_relaxed);
    ++received_;
  }
  progress();
}

void StepRun::poll(bool block) {
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
  for (int i = 0; i < out; ++i) complete(static_cast<std::uint32_t>(indices_[i]));
}

void StepRun::test_channel(std::uint32_t c) {
  if constexpr (kSingleThreaded) {
    poll();
    return;
  }
  // An inactive persistent request tests as complete: only one in flight is tested.
  if (!sending_[c] && !receiving_[c]) return;
  int flag = 0;
  MPI_Test(&plan_.requests[c], &flag, MPI_STATUS_IGNORE);
  if (flag != 0) complete(c);
}

bool StepRun::try_install(std::uint32_t m) {
  if (installed_[m].load(std::memory_order_acquire)) return true;
  const Message& msg = s_.messages[m];
  if (!arrived_[m].load(std::memory_order_relaxed)) test_channel(msg.channel);
  if (!arrived_[m].load(std::memory_order_relaxed)) return false;
  for (std::uint32_t h : msg.hazards)
    if (!done_[h].load(std::memory_order_acquire)) return false;
  const auto dst = w_.mutable_words(msg.datum);
  const auto& buf = plan_.buffers[msg.channel];
  std::copy_n(buf.begin(), std::min(dst.size(), buf.size()), dst.begin());
  // release: the words written above are visible to whoever sees installed_.
  installed_[m].store(1, std::memory_order_release);
  const std::uint32_t c = msg.channel;
  if (++next_[c] < queue_[c].size()) start_receive(c);
  progress();
  return true;
}

void StepRun::wait_channel_free(std::unique_lock<std::mutex>& lock, std::uint32_t c) {
  while (sending_[c]) {
    if constexpr (kSingleThreaded) {
      poll(true);
      continue;
    }
    test_channel(c);
    if (!sending_[c]) break;
    lock.unlock();
    sched_yield();
    lock.lock();
  }
}

void StepRun::send(std::uint32_t m) {
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

void StepRun::send_decision(std::uint32_t k, bool stop) {
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

bool StepRun::ready(const Wait& w) {
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
      // A decision made on this rank (another thread of it) comes through decided_ alone.
      const std::uint32_t c = decision_channel_[w.index];
      if (c == kNone) return false;
      std::lock_guard lock(mu_);
      test_channel(c);
      return decided_[w.index].load(std::memory_order_acquire) >= 0;
    }
  }
  return false;
}

std::string StepRun::describe(const Wait& w, const Instance* for_inst) const {
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

void StepRun::idle(std::uint32_t& polls) {
  if constexpr (kSingleThreaded) {
    std::lock_guard lock(mu_);
    poll(true);
  } else if (++polls <= kPollsBeforeYield) {
    // The next poll at once: a yield is a system call, and this thread usually has its core.
    replay::cpu_relax();
  } else {
    sched_yield();  // a long wait: let a rank or thread sharing this core run
  }
}

void StepRun::set_waiting(std::uint32_t slot, std::string what) {
  std::lock_guard lock(waiting_mu_);
  waiting_[slot] = std::move(what);
}

void StepRun::stuck(std::int64_t watchdog_ns) {
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

void StepRun::wait_for(const Wait& w, const Instance* inst, std::uint32_t slot, Counters& c) {
  if (ready(w)) {
    if (w.kind == WaitKind::kMessage && !checked_[w.index].exchange(1)) ++c.hidden;
    return;
  }
  if (w.kind == WaitKind::kMessage) checked_[w.index].store(1);
  const std::int64_t t0 = now_ns();
  set_waiting(slot, describe(w, inst));
  std::uint32_t polls = 0;
  while (!ready(w)) idle(polls);
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

void StepRun::work(ProcId p, std::uint32_t slot, Counters& c) {
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

}  // namespace tgraph::mpi
