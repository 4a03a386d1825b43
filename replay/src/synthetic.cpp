// SPDX-License-Identifier: MIT
// Synthetic bodies: calibrated busy loop + passes over the data buffers.
#include "tgraph/replay/synthetic.hpp"

#include <algorithm>
#include <cstring>

#include "tgraph/replay/observer.hpp"

namespace tgraph::replay {

struct SyntheticWorkload::Buffer {
  std::unique_ptr<std::uint64_t[]> w;
  std::uint64_t words = 0;
  bool temp = false;
};

std::uint64_t spin_iterations(std::uint64_t iterations, std::uint64_t seed) {
  std::uint64_t x = seed | 1;
  for (std::uint64_t i = 0; i < iterations; ++i) {
    x = x * 6364136223846793005ull + 1442695040888963407ull;
    asm volatile("" : "+r"(x));  // one dependent step per iteration, never folded
  }
  return x;
}

namespace {

std::uint64_t read_pass(const std::uint64_t* w, std::uint64_t n) {
  std::uint64_t s0 = 0, s1 = 0, s2 = 0, s3 = 0;
  const std::uint64_t n4 = n - n % 4;
  std::uint64_t i = 0;
  for (; i < n4; i += 4) {
    s0 += w[i];
    s1 += w[i + 1];
    s2 += w[i + 2];
    s3 += w[i + 3];
  }
  for (; i < n; ++i) s0 += w[i];
  return (s0 + s1) ^ (s2 + s3);
}

void write_pass(AccessMode mode, std::uint64_t* w, std::uint64_t n, std::uint64_t v) {
  switch (mode) {
    case AccessMode::R:
      return;
    case AccessMode::W:
      for (std::uint64_t i = 0; i < n; ++i) w[i] = v + i * 0x9e3779b97f4a7c15ull;
      return;
    case AccessMode::RW:
      for (std::uint64_t i = 0; i < n; ++i) w[i] = w[i] * 3 + v + i;
      return;
    case AccessMode::CW:
      for (std::uint64_t i = 0; i < n; ++i) w[i] += v + i;
      return;
  }
}

SyntheticCalibration measure() {
  SyntheticCalibration c;
  // The median of several ~1 ms runs: the sustained rate a replay sees (the best of short
  // runs catches a briefly higher clock and makes every task spin too long).
  std::vector<double> rates;
  const std::uint64_t iters = 1'000'000;
  for (int r = 0; r < 9; ++r) {
    const std::int64_t t0 = now_ns();
    volatile std::uint64_t sink = spin_iterations(iters, static_cast<std::uint64_t>(r));
    (void)sink;
    rates.push_back(static_cast<double>(iters) / std::max(1.0, static_cast<double>(now_ns() - t0)));
  }
  std::sort(rates.begin(), rates.end());
  c.spin_iterations_per_ns = rates[rates.size() / 2];
  double best = 1e30;
  const std::uint64_t words = 2048;  // 16 KiB read + 16 KiB read-modify-write, in L1/L2
  std::vector<std::uint64_t> a(words, 1), b(words, 2);
  best = 1e30;
  for (int r = 0; r < 21; ++r) {
    const std::int64_t t0 = now_ns();
    const std::uint64_t s = read_pass(a.data(), words);
    write_pass(AccessMode::RW, b.data(), words, s);
    asm volatile("" : : "r"(b.data()) : "memory");
    best = std::min(best, static_cast<double>(now_ns() - t0));
  }
  c.touch_ns_per_byte = best / static_cast<double>(2 * words * 8);
  return c;
}

}  // namespace

const SyntheticCalibration& SyntheticWorkload::calibration() {
  static const SyntheticCalibration c = measure();
  return c;
}

SyntheticWorkload::SyntheticWorkload(SyntheticOptions options)
    : options_(options), touch_ns_per_byte_(calibration().touch_ns_per_byte) {}

double SyntheticWorkload::calibrate_touch(std::uint64_t bytes) {
  // Half read, half read-modify-write, in chunks of 8 KiB (a task's data), cycling through
  // the whole working set as a step does.
  const std::uint64_t words = std::clamp<std::uint64_t>(bytes / 8, 4096, 32ull << 20) / 2;
  std::vector<std::uint64_t> a(words, 1), b(words, 2);
  const std::uint64_t chunk = 1024;
  double best = 1e30;
  for (int r = 0; r < 5; ++r) {
    const std::int64_t t0 = now_ns();
    std::uint64_t s = 0;
    for (std::uint64_t i = 0; i + chunk <= words; i += chunk) {
      s += read_pass(a.data() + i, chunk);
      write_pass(AccessMode::RW, b.data() + i, chunk, s);
    }
    asm volatile("" : : "r"(b.data()) : "memory");
    best = std::min(best, static_cast<double>(now_ns() - t0));
  }
  touch_ns_per_byte_ = best / static_cast<double>(2 * (words / chunk) * chunk * 8);
  return touch_ns_per_byte_;
}
SyntheticWorkload::~SyntheticWorkload() = default;

void SyntheticWorkload::bind(const ExecGraph& exec) {
  const std::size_t n = exec.graph.data.size();
  buffers_.resize(n);
  want_words_.assign(n, 0);
  is_temp_.assign(n, false);
  for (DatumId d = 0; d < n; ++d) {
    const bool temp = exec.datum_origin[d] != d;
    const std::uint64_t bytes =
        options_.touch ? std::min(exec.graph.data[d].bytes, options_.max_datum_bytes) : 0;
    want_words_[d] = (bytes + 7) / 8;
    is_temp_[d] = temp;
    if (buffers_[d] && (temp || buffers_[d]->temp)) buffers_[d].reset();  // temps are per plan
  }
}

bool SyntheticWorkload::needs_touch(DatumId d) const {
  return d < want_words_.size() && want_words_[d] != 0 &&
         (!buffers_[d] || buffers_[d]->words != want_words_[d]);
}

void SyntheticWorkload::first_touch(DatumId d) {
  auto b = std::make_unique<Buffer>();
  b->words = want_words_[d];
  b->w = std::make_unique<std::uint64_t[]>(b->words);  // zeroed here: first touch
  b->temp = is_temp_[d];
  // Temporaries start at zero; original data with a deterministic pattern.
  if (!b->temp)
    for (std::uint64_t i = 0; i < b->words; ++i)
      b->w[i] = (static_cast<std::uint64_t>(d) << 32) + i;
  buffers_[d] = std::move(b);
}

void SyntheticWorkload::run(const TaskRun& r) {
  const ExecGraph& x = *r.exec;
  if (r.origin == kNoTask) {
    const Reduction& red = x.reductions[x.reduction[r.task]];
    Buffer* target = buffers_[red.target].get();
    if (!target) return;
    for (DatumId t : red.temps) {
      Buffer* tmp = buffers_[t].get();
      if (!tmp) continue;
      const std::uint64_t n = std::min(tmp->words, target->words);
      for (std::uint64_t i = 0; i < n; ++i) {
        target->w[i] += tmp->w[i];
        tmp->w[i] = 0;
      }
    }
    return;
  }
  std::uint64_t acc = (static_cast<std::uint64_t>(r.origin) << 20) ^ r.iteration;
  // Data from the exec graph (a CW writer may be redirected to a temporary), modes from the
  // original step (serialisation turns CW into RW for ordering only).
  const auto acc_list = x.graph.accesses_of(r.task);
  const auto orig = step_ ? step_->accesses_of(r.origin) : acc_list;
  const std::size_t na = std::min(acc_list.size(), orig.size());
  const SyntheticCalibration& c = calibration();
  const double recorded = static_cast<double>(step_ ? step_->tasks[r.origin].cost_ns : 0);
  const double cost = recorded * options_.cost_scale;
  // A task whose recorded time is shorter than a pass over all its data at in-cache speed
  // cannot have touched all of it: a force field reads a few nodes of a body's whole
  // position vector. Its pass covers the leading fraction of each datum that such a pass
  // could cover in the recorded time, after the whole of its W data (a W task makes the
  // whole new version). The fraction depends only on the recorded cost and the touch rate
  // (the process's calibration, or SyntheticOptions::fraction_ns_per_byte; not cost_scale
  // or calibrate_touch), so every run of a step touches the same words and final states
  // stay comparable. A zero cost (a hand-made graph without costs) keeps the whole pass.
  std::uint64_t overwritten = 0, partial = 0;  // bytes of W data; of every other pass
  for (std::size_t i = 0; i < na; ++i) {
    const Buffer* b = buffers_[x.datum_on(acc_list[i].datum, r.thread)].get();
    if (!b) continue;
    if (orig[i].mode == AccessMode::W)
      overwritten += b->words * 8;
    else
      partial += b->words * 8 * ((reads(orig[i].mode) ? 1 : 0) + (writes(orig[i].mode) ? 1 : 0));
  }
  const double rate = options_.fraction_ns_per_byte.value_or(c.touch_ns_per_byte);
  const double budget = recorded - static_cast<double>(overwritten) * rate;
  const double pass_ns = static_cast<double>(partial) * rate;
  const double fraction =
      recorded > 0 && partial > 0 && pass_ns > budget ? std::max(0.0, budget) / pass_ns : 1.0;
  auto words_of = [fraction](const Buffer& b) {
    if (fraction >= 1.0) return b.words;
    const auto w = static_cast<std::uint64_t>(static_cast<double>(b.words) * fraction + 0.5);
    return std::clamp<std::uint64_t>(w, 1, b.words);
  };
  const std::int64_t t0 = timing_ ? now_ns() : 0;
  std::uint64_t bytes = 0;
  for (std::size_t i = 0; i < na; ++i) {
    if (!reads(orig[i].mode)) continue;
    const Buffer* b = buffers_[x.datum_on(acc_list[i].datum, r.thread)].get();
    if (!b) continue;
    const std::uint64_t words = words_of(*b);
    acc = acc * 31 + read_pass(b->w.get(), words);
    bytes += words * 8;
  }
  for (std::size_t i = 0; i < na; ++i) {
    if (!writes(orig[i].mode)) continue;
    Buffer* b = buffers_[x.datum_on(acc_list[i].datum, r.thread)].get();
    if (!b) continue;
    // A W task makes the whole new version (nothing of the old one survives it, so a process
    // that did not receive the old one holds the same words); RW and CW keep a tail that
    // their reader received.
    const std::uint64_t words = orig[i].mode == AccessMode::W ? b->words : words_of(*b);
    write_pass(orig[i].mode, b->w.get(), words, acc);
    bytes += words * 8;
  }
  if (options_.spin)
    spin_ns(cost - static_cast<double>(bytes) * touch_ns_per_byte_ - spin_offset_ns_, acc);
  if (timing_) {
    ++timed_.tasks;
    timed_.body_ns += static_cast<double>(now_ns() - t0);
    timed_.cost_ns += cost;
    timed_.bytes += static_cast<double>(bytes);
  }
}

void SyntheticWorkload::time_bodies(bool on) {
  timing_ = on;
  if (on) timed_ = {};
}

void SyntheticWorkload::spin_ns(double ns, std::uint64_t seed) {
  if (ns <= 0) return;
  volatile std::uint64_t sink =
      spin_iterations(static_cast<std::uint64_t>(ns * calibration().spin_iterations_per_ns), seed);
  (void)sink;
}

std::int64_t SyntheticWorkload::run_host(const StepGraph& g) const {
  if (g.host_ns == 0) return 0;
  const std::int64_t t0 = now_ns();
  spin_ns(static_cast<double>(g.host_ns) * options_.cost_scale, g.host_ns);
  return now_ns() - t0;
}

bool SyntheticWorkload::stop_after(LoopId loop, std::uint32_t iteration) {
  return step_ == nullptr || iteration + 1 >= step_->loops[loop].iterations;
}

std::optional<std::uint32_t> SyntheticWorkload::known_iterations(LoopId loop) const {
  if (step_ == nullptr) return std::nullopt;
  return std::max<std::uint32_t>(1, step_->loops[loop].iterations);
}

std::span<const std::uint64_t> SyntheticWorkload::words(DatumId d) const {
  if (d >= buffers_.size() || !buffers_[d]) return {};
  return {buffers_[d]->w.get(), buffers_[d]->words};
}

std::uint64_t SyntheticWorkload::allocated_bytes() const {
  std::uint64_t s = 0;
  for (const auto& b : buffers_)
    if (b) s += b->words * 8;
  return s;
}

}  // namespace tgraph::replay
