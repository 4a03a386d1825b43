// SPDX-License-Identifier: MIT
#include "background_partitioner.hpp"

#include <pthread.h>
#include <sched.h>

#include <chrono>
#include <utility>

#include "tgraph/replay/observer.hpp"

namespace tgraph::measure::detail {

BackgroundPartitioner::BackgroundPartitioner(const partition::StepPartitioner& partitioner,
                                             bool threaded)
    : partitioner_(partitioner) {
  if (threaded) thread_ = std::thread([this] { loop(); });
}

BackgroundPartitioner::~BackgroundPartitioner() {
  if (thread_.joinable()) {
    stop_.store(true, std::memory_order_release);
    submitted_.fetch_add(1, std::memory_order_release);
    submitted_.notify_one();
    thread_.join();
  }
  delete queued_.exchange(nullptr, std::memory_order_acquire);
  delete done_.exchange(nullptr, std::memory_order_acquire);
}

BackgroundPartitioner::Done BackgroundPartitioner::run(const Job& job) const {
  const std::int64_t t0 = replay::now_ns();
  Done d;
  d.graph = job.graph;
  try {
    d.assignment = partitioner_(*job.graph, job.k, job.prev_graph.get(), job.prev.get());
  } catch (...) {
    d.error = std::current_exception();
  }
  d.partition_ns = replay::now_ns() - t0;
  return d;
}

void BackgroundPartitioner::submit(Job job) {
  if (!thread_.joinable()) {
    delete done_.exchange(new Done(run(job)), std::memory_order_acq_rel);
    return;
  }
  // A job the helper has not taken yet is replaced (and freed here).
  delete queued_.exchange(new Job(std::move(job)), std::memory_order_acq_rel);
  // release: the helper that sees the new count sees the job.
  submitted_.fetch_add(1, std::memory_order_release);
  submitted_.notify_one();
}

bool BackgroundPartitioner::busy() const {
  // The helper sets running_ before it takes a job and clears it after publishing the
  // result, so a job is always seen in one of the two places (acquire: pairs with them).
  return running_.load(std::memory_order_acquire) ||
         queued_.load(std::memory_order_acquire) != nullptr;
}

std::optional<BackgroundPartitioner::Done> BackgroundPartitioner::take() {
  // acquire: the result's contents, written before the helper's exchange.
  std::unique_ptr<Done> d(done_.exchange(nullptr, std::memory_order_acq_rel));
  if (!d) return std::nullopt;
  if (d->error) std::rethrow_exception(d->error);
  return std::move(*d);
}

void BackgroundPartitioner::drain() const {
  while (busy()) std::this_thread::sleep_for(std::chrono::microseconds(100));
}

void BackgroundPartitioner::loop() {
  // SCHED_IDLE: runs only on cycles no other thread of the machine wants (Linux; where it is
  // refused, the thread keeps the default policy).
  sched_param none{};
  pthread_setschedparam(pthread_self(), SCHED_IDLE, &none);
  std::uint32_t seen = 0;
  for (;;) {
    submitted_.wait(seen, std::memory_order_acquire);
    seen = submitted_.load(std::memory_order_acquire);
    if (stop_.load(std::memory_order_acquire)) break;
    for (;;) {
      running_.store(true, std::memory_order_release);
      std::unique_ptr<Job> job(queued_.exchange(nullptr, std::memory_order_acq_rel));
      if (!job) {
        running_.store(false, std::memory_order_release);
        break;
      }
      Done* d = new Done(run(*job));
      delete done_.exchange(d, std::memory_order_acq_rel);  // an untaken older result
      running_.store(false, std::memory_order_release);
      if (stop_.load(std::memory_order_acquire)) return;
    }
  }
}

}  // namespace tgraph::measure::detail
