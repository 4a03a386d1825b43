// SPDX-License-Identifier: MIT
// The synthetic bodies' data pass: which words a task touches, computed from its recorded
// cost and a touch rate, never from anything that differs between processes when the rate
// is given.
#include "tgraph/replay/synthetic.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "tgraph/replay/executor.hpp"

namespace tgraph::replay {
namespace {

constexpr std::uint64_t kWords = 1000;  // each datum: 8000 bytes

// Words of datum d that no longer hold first_touch's pattern ((d << 32) + i).
std::uint64_t changed(const SyntheticWorkload& w, DatumId d) {
  std::uint64_t n = 0;
  const auto words = w.words(d);
  for (std::uint64_t i = 0; i < words.size(); ++i)
    n += words[i] != (static_cast<std::uint64_t>(d) << 32) + i ? 1 : 0;
  return n;
}

// One task with `acc` on data of kWords words each, recorded at `cost_ns`, run once
// sequentially by a workload that sizes its pass at `rate` ns per byte and does not spin.
std::unique_ptr<SyntheticWorkload> run_one(std::vector<Access> acc, std::uint64_t cost_ns,
                                           double rate) {
  StepGraph g;
  g.intern_kind("k");
  for (std::size_t d = 0; d < acc.size(); ++d)
    g.data.push_back({"d" + std::to_string(d), kNoObject, kWords * 8});
  g.add_task(0, kNoObject, acc, cost_ns);
  g.derive_edges();
  SyntheticOptions o;
  o.fraction_ns_per_byte = rate;
  o.spin = false;
  auto w = std::make_unique<SyntheticWorkload>(o);
  w->set_step(g);
  make_executor(Policy::kSequential, {})->run_step(g, nullptr, *w);
  return w;
}

TEST(SyntheticPass, AShortTaskTouchesTheLeadingFractionThatFitsItsCost) {
  // Read 8000 bytes + read and write 8000: 24000 bytes at 0.01 ns = 240 ns for a 100 ns
  // task, so 100 / 240 of each datum: 417 of the RW datum's 1000 words change.
  const auto w = run_one({{0, AccessMode::R}, {1, AccessMode::RW}}, 100, 0.01);
  EXPECT_EQ(changed(*w, 0), 0u);
  EXPECT_EQ(changed(*w, 1), 417u);
  // A task whose whole pass fits in its cost touches everything.
  EXPECT_EQ(changed(*run_one({{0, AccessMode::R}, {1, AccessMode::RW}}, 1000, 0.01), 1), kWords);
}

TEST(SyntheticPass, AWTaskWritesTheWholeDatumAndTheRestSharesWhatIsLeft) {
  // W: all 8000 bytes (80 ns of the 100); the RW datum's 16000 bytes get the 20 ns left:
  // 125 words.
  const auto w = run_one({{0, AccessMode::W}, {1, AccessMode::RW}}, 100, 0.01);
  EXPECT_EQ(changed(*w, 0), kWords);
  EXPECT_EQ(changed(*w, 1), 125u);
  // Even when the W datum alone takes longer than the cost, it is whole; the RW one keeps
  // its first word touched.
  const auto v = run_one({{0, AccessMode::W}, {1, AccessMode::RW}}, 10, 0.01);
  EXPECT_EQ(changed(*v, 0), kWords);
  EXPECT_EQ(changed(*v, 1), 1u);
}

TEST(SyntheticPass, TheGivenRateDecidesTheWordsNotTheProcessCalibration) {
  const std::vector<Access> acc = {{0, AccessMode::R}, {1, AccessMode::RW}};
  const auto a = run_one(acc, 100, 0.01), b = run_one(acc, 100, 0.01);
  EXPECT_TRUE(std::ranges::equal(a->words(1), b->words(1)));
  EXPECT_EQ(changed(*run_one(acc, 100, 0.02), 1), 208u);  // 100 / 480 of 1000, rounded
}

TEST(SyntheticPass, TimedBodiesSumTheirTimeCostAndBytes) {
  // Two tasks of 1000 and 3000 ns recorded, spins off: their bodies are their data passes
  // (8000 bytes read + 8000 read and written each, at 0.01 ns a byte all of it fits); the
  // sums start again at time_bodies(true) and stop at time_bodies(false).
  StepGraph g;
  g.intern_kind("k");
  g.data.push_back({"d0", kNoObject, kWords * 8});
  g.data.push_back({"d1", kNoObject, kWords * 8});
  const std::vector<Access> acc = {{0, AccessMode::R}, {1, AccessMode::RW}};
  g.add_task(0, kNoObject, acc, 1000);
  g.add_task(0, kNoObject, acc, 3000);
  g.derive_edges();
  SyntheticOptions o;
  o.fraction_ns_per_byte = 0.01;
  o.spin = false;
  SyntheticWorkload w(o);
  w.set_step(g);
  const auto ex = make_executor(Policy::kSequential, {});
  w.time_bodies(true);
  ex->run_step(g, nullptr, w);
  EXPECT_EQ(w.timed().tasks, 2u);
  EXPECT_EQ(w.timed().cost_ns, 4000.0);
  EXPECT_EQ(w.timed().bytes, 2.0 * 3 * kWords * 8);
  EXPECT_GT(w.timed().body_ns, 0.0);
  w.time_bodies(true);
  EXPECT_EQ(w.timed().tasks, 0u);
  EXPECT_EQ(w.timed().bytes, 0.0);
  w.time_bodies(false);
  ex->run_step(g, nullptr, w);
  EXPECT_EQ(w.timed().tasks, 0u);
}

}  // namespace
}  // namespace tgraph::replay
