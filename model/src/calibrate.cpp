// SPDX-License-Identifier: MIT
// `tgraph calibrate`: hand-off latencies (spinning and parked), cross-core transfer cost,
// the bodies' slow-down against the busy cores and a reduction's cost of this machine.
#include <linux/futex.h>
#include <pthread.h>
#include <sched.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <thread>
#include <vector>

#include "tgraph/model/cost_model.hpp"

namespace tgraph::model {

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
      for (std::size_t i = 0; i < words; ++i)
        buf[i] = i * 2654435761u + static_cast<std::uint64_t>(r);
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

// One-way hand-offs to a parked thread: B sleeps in futex(FUTEX_WAIT) on a word (the
// kernel call under the executors' parked waits, without std::atomic::wait's spinning
// first); A waits 30 us (B is asleep by then), reads the clock, stores the word and calls
// futex(FUTEX_WAKE); B reads the clock when the call returns. Median of B's time - A's.
double measure_park_wake(int cpu_a, int cpu_b, int rounds) {
  alignas(64) std::atomic<std::uint32_t> word{0};
  Flag ack;
  std::vector<std::int64_t> sent(static_cast<std::size_t>(rounds)),
      woke(static_cast<std::size_t>(rounds));
  auto ns = [] {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch())
        .count();
  };
  std::thread b([&] {
    for (int i = 0; i < rounds; ++i) {
      const auto want = static_cast<std::uint32_t>(i + 1);
      // acquire: A's clock reading before its store is visible after.
      for (std::uint32_t v = word.load(std::memory_order_acquire); v != want;
           v = word.load(std::memory_order_acquire))
        syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(&word), FUTEX_WAIT_PRIVATE, v, nullptr,
                nullptr, 0);
      woke[static_cast<std::size_t>(i)] = ns();
      // release: B's reading is visible to A once it sees the acknowledgement.
      ack.value.store(static_cast<std::uint64_t>(i + 1), std::memory_order_release);
    }
  });
  pin(b, cpu_b);
  std::thread a([&] {
    for (int i = 0; i < rounds; ++i) {
      // acquire: pairs with B's acknowledgement.
      while (ack.value.load(std::memory_order_acquire) != static_cast<std::uint64_t>(i)) {
      }
      const std::int64_t until = ns() + 30'000;
      while (ns() < until) {
      }
      sent[static_cast<std::size_t>(i)] = ns();
      word.store(static_cast<std::uint32_t>(i + 1), std::memory_order_release);  // release: above
      syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(&word), FUTEX_WAKE_PRIVATE, 1, nullptr,
              nullptr, 0);
    }
  });
  pin(a, cpu_a);
  a.join();
  b.join();
  std::vector<double> d;
  for (int i = 0; i < rounds; ++i)
    d.push_back(
        static_cast<double>(woke[static_cast<std::size_t>(i)] - sent[static_cast<std::size_t>(i)]));
  return median(d);
}

// A spin barrier for `n` threads that can be used round after round.
class SpinBarrier {
 public:
  explicit SpinBarrier(std::uint64_t n) : n_(n) {}
  void arrive_and_wait() {
    // relaxed: the generation is read before the arrival, which orders it (acq_rel).
    const std::uint64_t gen = generation_.value.load(std::memory_order_relaxed);
    // acq_rel: the last arrival sees every other thread's writes before the barrier.
    if (arrived_.value.fetch_add(1, std::memory_order_acq_rel) + 1 == n_) {
      arrived_.value.store(0, std::memory_order_relaxed);  // relaxed: published below
      // release: the reset and the arrivals' writes are visible to whoever sees gen + 1.
      generation_.value.store(gen + 1, std::memory_order_release);
      return;
    }
    // acquire: pairs with the release above.
    while (generation_.value.load(std::memory_order_acquire) == gen) {
    }
  }

 private:
  const std::uint64_t n_;
  Flag arrived_, generation_;
};

// One pass of the inflation body: reads the first half of `w`, read-modify-writes the
// second half with what it read, in 8 KiB chunks (an engine task's vectors: a force
// field's read of positions and its += into forces).
std::uint64_t body_pass(std::uint64_t* w, std::size_t words, std::uint64_t seed) {
  const std::size_t half = words / 2, chunk = 1024;
  std::uint64_t s = seed;
  for (std::size_t c = 0; c + chunk <= half; c += chunk) {
    std::uint64_t s0 = 0, s1 = 0;
    for (std::size_t i = c; i < c + chunk; i += 2) {
      s0 += w[i];
      s1 += w[i + 1];
    }
    s += s0 ^ s1;
    for (std::size_t i = half + c; i < half + c + chunk; ++i) w[i] = w[i] * 3 + s + i;
  }
  return s;
}

// One pass of the compute body: a dependent chain of 2^17 integer multiply-adds in a
// register, no memory traffic: what a body's arithmetic feels of the other busy cores (the
// lower clock of many busy cores, a core's other hardware thread).
std::uint64_t compute_pass(std::uint64_t seed) {
  std::uint64_t x = seed | 1;
  for (int i = 0; i < (1 << 17); ++i) {
    x = x * 6364136223846793005ull + 1442695040888963407ull;
    asm volatile("" : "+r"(x));  // one step at a time: no closed form, no vectors
  }
  return x;
}

enum class Body { kMemory, kCompute };

// Mean time per thread of `passes` passes of the body, each of `k` pinned threads on its
// own working set of `bytes` (allocated and first touched by that thread; the compute body
// touches none of it), all started together; median over `rounds`.
double busy_pass_ns(const std::vector<int>& cpus, std::size_t k, std::size_t bytes, int rounds,
                    int passes, Body body = Body::kMemory) {
  const std::size_t words = std::max<std::size_t>(bytes / 8, 4096);
  SpinBarrier barrier(k);
  std::vector<std::vector<double>> times(k);
  std::vector<std::uint64_t> sinks(k, 0);
  std::vector<std::thread> threads;
  for (std::size_t t = 0; t < k; ++t) {
    threads.emplace_back([&, t] {
      std::vector<std::uint64_t> w(words, t + 1);
      std::uint64_t s = 0;
      for (int r = -1; r < rounds; ++r) {  // round -1 warms the caches, unmeasured
        barrier.arrive_and_wait();
        const auto t0 = Clock::now();
        for (int p = 0; p < passes; ++p)
          s += body == Body::kMemory ? body_pass(w.data(), words, s) : compute_pass(s);
        const auto t1 = Clock::now();
        if (r >= 0) times[t].push_back(std::chrono::duration<double, std::nano>(t1 - t0).count());
      }
      sinks[t] = s;
    });
    pin(threads.back(), cpus[t]);
  }
  for (std::thread& t : threads) t.join();
  volatile std::uint64_t keep = sinks[0];
  (void)keep;
  std::vector<double> mean_by_round;
  for (int r = 0; r < rounds; ++r) {
    double sum = 0;
    for (std::size_t t = 0; t < k; ++t) sum += times[t][static_cast<std::size_t>(r)];
    mean_by_round.push_back(sum / static_cast<double>(k) / passes);
  }
  return median(mean_by_round);
}

// Rounds of a combine over `k` pinned threads: each writes its partial on its own cache
// line and arrives at a counter; the last to arrive sums the partials and publishes the
// round; every thread waits (spinning) for that. Median ns per round over blocks of 100.
double reduction_round_ns(const std::vector<int>& cpus, std::size_t k, int rounds) {
  constexpr int kBlock = 100;
  const int blocks = std::max(1, rounds / kBlock);
  std::vector<Flag> partial(k);
  Flag arrivals, published, result;
  std::vector<double> per_block;
  std::vector<std::thread> threads;
  for (std::size_t t = 0; t < k; ++t) {
    threads.emplace_back([&, t] {
      std::uint64_t round = 0;
      for (int blk = -1; blk < blocks; ++blk) {
        const auto t0 = Clock::now();
        for (int r = 0; r < kBlock; ++r, ++round) {
          // relaxed: published by the acq_rel arrival below.
          partial[t].value.store(round * k + t, std::memory_order_relaxed);
          // acq_rel: the last arrival sees every partial written before the others arrived.
          if (arrivals.value.fetch_add(1, std::memory_order_acq_rel) + 1 == (round + 1) * k) {
            std::uint64_t sum = 0;
            for (std::size_t q = 0; q < k; ++q)
              sum += partial[q].value.load(std::memory_order_relaxed);  // ordered above
            result.value.store(sum, std::memory_order_relaxed);         // relaxed: published below
            // release: the sum is visible to every thread that sees round + 1.
            published.value.store(round + 1, std::memory_order_release);
          }
          // acquire: pairs with the release above.
          while (published.value.load(std::memory_order_acquire) < round + 1) {
          }
        }
        const auto t1 = Clock::now();
        if (t == 0 && blk >= 0)
          per_block.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count() / kBlock);
      }
    });
    pin(threads.back(), cpus[t]);
  }
  for (std::thread& t : threads) t.join();
  return median(per_block);
}

// `k` pinned threads, started together, each reading the clock in a loop for `ns`: per
// thread, the gaps between two readings of at least kInterruptionGapNs (appended to
// gaps[t]) and the loop's length (added to span[t]).
void interruption_gaps(const std::vector<int>& cpus, std::size_t k, double ns,
                       std::vector<std::vector<double>>& gaps, std::vector<double>& span) {
  SpinBarrier barrier(k);
  std::vector<std::vector<double>> found(k);
  std::vector<double> length(k, 0);
  std::vector<std::thread> threads;
  const auto duration =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double, std::nano>(ns));
  for (std::size_t t = 0; t < k; ++t) {
    threads.emplace_back([&, t] {
      std::vector<double> mine;
      barrier.arrive_and_wait();
      const auto t0 = Clock::now(), end = t0 + duration;
      auto last = t0;
      for (;;) {
        const auto now = Clock::now();
        const double gap = std::chrono::duration<double, std::nano>(now - last).count();
        if (gap >= kInterruptionGapNs) mine.push_back(gap);
        last = now;
        if (now >= end) break;
      }
      length[t] = std::chrono::duration<double, std::nano>(last - t0).count();
      found[t] = std::move(mine);
    });
    pin(threads.back(), cpus[t]);
  }
  for (std::thread& t : threads) t.join();
  for (std::size_t t = 0; t < k; ++t) {
    gaps[t].insert(gaps[t].end(), found[t].begin(), found[t].end());
    span[t] += length[t];
  }
}

// Up to 32 quantiles of `v` (all of it when shorter), at the middles of 32 equal shares.
std::vector<double> quantiles(std::vector<double> v) {
  constexpr std::size_t kQ = 32;
  std::sort(v.begin(), v.end());
  if (v.size() <= kQ) return v;
  std::vector<double> out;
  for (std::size_t j = 0; j < kQ; ++j)
    out.push_back(v[std::min(v.size() - 1, (2 * j + 1) * v.size() / (2 * kQ))]);
  return out;
}

// 1, 2, 4, ... below n, and n.
std::vector<std::size_t> thread_counts(std::size_t n) {
  std::vector<std::size_t> out;
  for (std::size_t k = 1; k < n; k *= 2) out.push_back(k);
  out.push_back(n);
  return out;
}

}  // namespace

Spread spread_of(std::vector<double> v) {
  if (v.empty()) return {};
  std::sort(v.begin(), v.end());
  return {v.front(), v[v.size() / 2], v.back()};
}

Calibration measure_calibration(const CalibrateOptions& options) {
  const auto start = Clock::now();
  const std::vector<int> cpus = allowed_cpus();
  if (cpus.size() < 2)
    throw std::runtime_error("calibrate: needs two CPUs, this process may use " +
                             std::to_string(cpus.size()));
  Calibration c;
  c.cpu_a = cpus[0];
  c.cpu_b = cpus[1];
  c.rounds = std::max(options.rounds, 500);
  c.buffer_bytes = options.buffer_bytes;
  c.park_rounds = std::max(options.park_rounds, 20);
  c.inflation_bytes = options.inflation_bytes;
  c.samples = std::max(options.samples, 1);
  // Every measurement is taken `samples` times, the samples interleaved (a sample of each,
  // then the next), so that a machine whose speed drifts (a shared VM whose vCPUs the
  // hypervisor moves) spreads each measurement alike; each value is the samples' median and
  // its spread (min, median, max) is reported beside it.
  const std::vector<std::size_t> ks = thread_counts(cpus.size());
  std::vector<double> latency, per_byte, park, pass_per_byte;
  std::vector<std::vector<double>> inflation(ks.size()), compute(ks.size()), reduction(ks.size());
  // Interruptions: per thread count, per thread, the gaps and the loop's time.
  std::vector<std::vector<std::vector<double>>> gaps(ks.size());
  std::vector<std::vector<double>> spans(ks.size());
  for (std::size_t i = 0; i < ks.size(); ++i) {
    gaps[i].resize(ks[i]);
    spans[i].assign(ks[i], 0.0);
  }
  // Bytes one pass of the memory body touches (each word once: read, or read and written).
  const double pass_bytes =
      static_cast<double>(std::max<std::size_t>(c.inflation_bytes / 8, 4096) * 8);
  const int rounds = std::max(options.inflation_rounds, 1), passes = 20;
  for (int sample = 0; sample < c.samples; ++sample) {
    latency.push_back(measure_latency(c.cpu_a, c.cpu_b, c.rounds));
    per_byte.push_back(
        measure_per_byte(c.cpu_a, c.cpu_b, options.buffer_bytes, std::max(options.repeats, 1)));
    park.push_back(measure_park_wake(c.cpu_a, c.cpu_b, c.park_rounds));
    // Inflation: in each round one thread alone, then K at once (the same body, one round
    // each), so that a drift moves both alike; the median of the rounds' ratios; for the
    // memory body and for the compute body. A pass over 2 MiB takes 0.1-0.5 ms, one of the
    // compute body about 0.1 ms: 20 passes keep a round within tens of ms.
    std::vector<double> alone_per_byte;
    for (std::size_t i = 0; i < ks.size(); ++i) {
      if (options.interruption_ms > 0)
        interruption_gaps(cpus, ks[i], options.interruption_ms * 1e6, gaps[i], spans[i]);
      if (ks[i] < 2) continue;
      std::vector<double> ratio, compute_ratio;
      for (int r = 0; r < rounds; ++r) {
        const double alone = busy_pass_ns(cpus, 1, c.inflation_bytes, 1, passes);
        alone_per_byte.push_back(alone / pass_bytes);
        ratio.push_back(busy_pass_ns(cpus, ks[i], c.inflation_bytes, 1, passes) / alone);
        const double alone_compute =
            busy_pass_ns(cpus, 1, c.inflation_bytes, 1, passes, Body::kCompute);
        compute_ratio.push_back(
            busy_pass_ns(cpus, ks[i], c.inflation_bytes, 1, passes, Body::kCompute) /
            alone_compute);
      }
      inflation[i].push_back(median(ratio));
      compute[i].push_back(median(compute_ratio));
      reduction[i].push_back(
          reduction_round_ns(cpus, ks[i], std::max(options.reduction_rounds, 100)));
    }
    if (!alone_per_byte.empty()) pass_per_byte.push_back(median(alone_per_byte));
  }
  c.inflation_pass_spread = spread_of(pass_per_byte);
  c.inflation_ns_per_byte = c.inflation_pass_spread.median;
  c.latency_spread = spread_of(latency);
  c.per_byte_spread = spread_of(per_byte);
  c.park_wake_spread = spread_of(park);
  c.sync_latency_ns = c.latency_spread.median;
  c.per_byte_ns = c.per_byte_spread.median;
  c.park_wake_ns = c.park_wake_spread.median;
  const std::size_t measured = options.interruption_ms > 0 ? ks.size() : 0;
  for (std::size_t i = 0; i < measured; ++i) {
    InterruptionsPoint point{static_cast<std::uint32_t>(ks[i]), {}};
    for (std::size_t t = 0; t < ks[i]; ++t) {
      double lost = 0;
      for (double g : gaps[i][t]) lost += g;
      ThreadInterruptions ti;
      ti.lost = spans[i][t] > 0 ? std::min(0.5, lost / spans[i][t]) : 0.0;
      ti.lengths_ns = quantiles(gaps[i][t]);
      point.cpus.push_back(std::move(ti));
    }
    c.interruptions.push_back(std::move(point));
  }
  for (std::size_t i = 0; i < ks.size(); ++i) {
    const auto k = static_cast<std::uint32_t>(ks[i]);
    if (k < 2) {
      c.inflation.push_back({1, 1.0});
      c.compute_inflation.push_back({1, 1.0});
      continue;
    }
    c.inflation_spread.push_back({k, spread_of(inflation[i])});
    c.reduction_spread.push_back({k, spread_of(reduction[i])});
    // K copies of the body cannot each run faster than one alone on the same cores: a median
    // below 1 is the machine's noise (its spread says how much), and the factor is 1.
    c.inflation.push_back({k, std::max(1.0, c.inflation_spread.back().spread.median)});
    c.compute_inflation_spread.push_back({k, spread_of(compute[i])});
    c.compute_inflation.push_back(
        {k, std::max(1.0, c.compute_inflation_spread.back().spread.median)});
    c.reduction.push_back({k, c.reduction_spread.back().spread.median});
  }
  c.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return c;
}

Calibration calibrate_machine(const CalibrateOptions& options,
                              const ExecutorOverheadSampler& sampler) {
  Calibration c = measure_calibration(options);
  const auto start = std::chrono::steady_clock::now();
  const auto samples = static_cast<std::uint32_t>(std::max(c.samples, 1));
  // The same K as the inflation's (its curve lists 1 first).
  for (const ThreadsPoint& p : c.inflation) {
    if (p.threads < 2) continue;
    const Spread s = spread_of(sampler(p.threads, samples));
    c.executor_overhead_spread.push_back({p.threads, s});
    // Below 0 is the noise of a machine on which the executor costs nothing measurable.
    c.executor_overhead.push_back({p.threads, std::max(0.0, s.median)});
  }
  c.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return c;
}

std::string calibrate_file(const CalibrateOptions& options, const std::string& path, bool json,
                           const ExecutorOverheadSampler& sampler) {
  const Calibration c = calibrate_machine(options, sampler);  // runtime_error: the work's
  return calibration_report(c, save_calibration(c, path), json);
}

}  // namespace tgraph::model
