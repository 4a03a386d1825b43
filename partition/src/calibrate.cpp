// SPDX-License-Identifier: MIT
// `tgraph calibrate`: signal/wait latency and cross-core transfer cost of this machine.
#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <thread>
#include <vector>

#include "tgraph/partition/cost_model.hpp"

namespace tgraph::partition {

namespace {

using Clock = std::chrono::steady_clock;

std::vector<int> allowed_cpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  std::vector<int> cpus;
  if (sched_getaffinity(0, sizeof(set), &set) != 0) return cpus;
  for (int c = 0; c < CPU_SETSIZE; ++c)
    if (CPU_ISSET(c, &set)) cpus.push_back(c);
  return cpus;
}

void pin(std::thread& t, int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  pthread_setaffinity_np(t.native_handle(), sizeof(set), &set);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

struct alignas(64) Flag {
  std::atomic<std::uint64_t> value{0};
};

// Round trips of a counter between two spinning threads; returns the median one-way time.
double measure_latency(int cpu_a, int cpu_b, int rounds) {
  Flag ping;
  constexpr int kBlock = 500;
  const int blocks = std::max(1, rounds / kBlock);
  std::vector<double> per_block;
  std::thread b([&] {
    for (std::uint64_t i = 0; i < static_cast<std::uint64_t>(blocks) * kBlock; ++i) {
      // acquire/release pairs order nothing else here; relaxed would do, but the handoff
      // measured is the one real signal/wait code performs (release store, acquire load).
      while (ping.value.load(std::memory_order_acquire) != 2 * i + 1) {
      }
      ping.value.store(2 * i + 2, std::memory_order_release);
    }
  });
  pin(b, cpu_b);
  std::thread a([&] {
    std::uint64_t i = 0;
    for (int blk = 0; blk < blocks; ++blk) {
      const auto t0 = Clock::now();
      for (int r = 0; r < kBlock; ++r, ++i) {
        ping.value.store(2 * i + 1, std::memory_order_release);
        while (ping.value.load(std::memory_order_acquire) != 2 * i + 2) {
        }
      }
      const auto t1 = Clock::now();
      per_block.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count() / kBlock / 2);
    }
  });
  pin(a, cpu_a);
  a.join();
  b.join();
  return median(per_block);
}

// Thread A writes a buffer then signals; thread B reads it (remote) and reads it again
// (local). The difference per byte is the transfer cost.
double measure_per_byte(int cpu_a, int cpu_b, std::size_t bytes, int repeats) {
  const std::size_t words = std::max<std::size_t>(bytes / 8, 1);
  std::vector<std::uint64_t> buf(words, 0);
  Flag go, done;
  std::vector<double> per_byte;
  std::uint64_t sink = 0;
  std::thread b([&] {
    for (int r = 0; r < repeats; ++r) {
      // acquire: B must see A's writes of the buffer.
      while (go.value.load(std::memory_order_acquire) != static_cast<std::uint64_t>(r + 1)) {
      }
      std::uint64_t s = 0;
      const auto t0 = Clock::now();
      for (std::size_t i = 0; i < words; ++i) s += buf[i];
      const auto t1 = Clock::now();
      for (std::size_t i = 0; i < words; ++i) s += buf[i];
      const auto t2 = Clock::now();
      sink += s;
      const double remote = std::chrono::duration<double, std::nano>(t1 - t0).count();
      const double local = std::chrono::duration<double, std::nano>(t2 - t1).count();
      per_byte.push_back(std::max(0.0, remote - local) / static_cast<double>(words * 8));
      // release: A may overwrite the buffer only after B has read it.
      done.value.store(static_cast<std::uint64_t>(r + 1), std::memory_order_release);
    }
  });
  pin(b, cpu_b);
  std::thread a([&] {
    for (int r = 0; r < repeats; ++r) {
      for (std::size_t i = 0; i < words; ++i) buf[i] = i * 2654435761u + static_cast<std::uint64_t>(r);
      go.value.store(static_cast<std::uint64_t>(r + 1), std::memory_order_release);
      while (done.value.load(std::memory_order_acquire) != static_cast<std::uint64_t>(r + 1)) {
      }
    }
  });
  pin(a, cpu_a);
  a.join();
  b.join();
  volatile std::uint64_t keep = sink;
  (void)keep;
  return median(per_byte);
}

}  // namespace

Calibration measure_calibration(const CalibrateOptions& options) {
  const std::vector<int> cpus = allowed_cpus();
  if (cpus.size() < 2)
    throw std::runtime_error("calibrate: needs two CPUs, this process may use " +
                             std::to_string(cpus.size()));
  Calibration c;
  c.cpu_a = cpus[0];
  c.cpu_b = cpus[1];
  c.rounds = std::max(options.rounds, 500);
  c.buffer_bytes = options.buffer_bytes;
  c.sync_latency_ns = measure_latency(c.cpu_a, c.cpu_b, c.rounds);
  c.per_byte_ns = measure_per_byte(c.cpu_a, c.cpu_b, options.buffer_bytes, std::max(options.repeats, 1));
  return c;
}

}  // namespace tgraph::partition
