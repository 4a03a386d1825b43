// SPDX-License-Identifier: MIT
// The schedule across ranks and its predicted traffic, on hand-made steps (no MPI).
#include "tgraph/mpi/schedule.hpp"

#include <gtest/gtest.h>

#include "tgraph/graph/lowering.hpp"

namespace tgraph::mpi {
namespace {

struct Built {
  StepGraph g;
  Assignment a;
};

DatumId add_datum(StepGraph& g, std::uint64_t bytes) {
  g.data.push_back({"d" + std::to_string(g.data.size()), kNoObject, bytes});
  return static_cast<DatumId>(g.data.size() - 1);
}

TaskId add(Built& b, ProcId p, std::vector<Access> acc, LoopId loop = kNoLoop) {
  const TaskId t = b.g.add_task(0, kNoObject, acc, 1000);
  b.g.tasks[t].loop = loop;
  b.a.proc.push_back(p);
  return t;
}

Traffic predict(Built& b, Layout layout, const Holders* before = nullptr) {
  b.g.derive_edges();
  b.a.k = layout.processors();
  const ExecGraph x = lower(b.g, &b.a, CwMode::kReduce, ReduceScope::kPerProcessor);
  const Holders h = before ? *before : everywhere(b.g.data.size(), layout.ranks);
  return predict_traffic(x, b.g, layout, h);
}

Built start() {
  Built b;
  b.g.intern_kind("work");
  return b;
}

TEST(Schedule, SendsAVersionOncePerReceivingRank) {
  Built b = start();
  const DatumId d = add_datum(b.g, 100);
  add(b, 0, {{d, AccessMode::W}});
  add(b, 1, {{d, AccessMode::R}});
  add(b, 1, {{d, AccessMode::R}});
  const Traffic t = predict(b, {2, 1});
  EXPECT_EQ(t.messages, (std::vector<std::uint64_t>{0, 1, 0, 0}));
  EXPECT_EQ(t.bytes, (std::vector<std::uint64_t>{0, 104, 0, 0}));  // whole 8-byte words
  EXPECT_EQ(t.total_decisions(), 0u);
}

TEST(Schedule, ThreadsOfOneRankShareData) {
  Built b = start();
  const DatumId d = add_datum(b.g, 64);
  add(b, 0, {{d, AccessMode::W}});
  add(b, 1, {{d, AccessMode::R}});
  EXPECT_EQ(predict(b, {1, 2}).total_messages(), 0u);
  Built c = start();
  const DatumId e = add_datum(c.g, 64);
  add(c, 0, {{e, AccessMode::W}});
  add(c, 1, {{e, AccessMode::R}});
  add(c, 2, {{e, AccessMode::R}});  // rank 1 (processors 2 and 3)
  const Traffic t = predict(c, {2, 2});
  EXPECT_EQ(t.messages, (std::vector<std::uint64_t>{0, 1, 0, 0}));
}

TEST(Schedule, ALoopSendsEachIterationsVersionAndItsDecisions) {
  Built b = start();
  const DatumId d = add_datum(b.g, 8), c = add_datum(b.g, 8);
  Loop loop;
  loop.first = 0;
  loop.condition = c;
  loop.iterations = 3;
  add(b, 0, {{d, AccessMode::W}}, 0);
  add(b, 1, {{d, AccessMode::R}, {c, AccessMode::W}}, 0);
  add(b, 1, {{c, AccessMode::R}}, 0);  // the break task decides on rank 1
  loop.last = 3;
  b.g.loops.push_back(loop);
  const Traffic t = predict(b, {2, 1});
  EXPECT_EQ(t.messages, (std::vector<std::uint64_t>{0, 3, 0, 0}));
  EXPECT_EQ(t.decisions, (std::vector<std::uint64_t>{0, 0, 3, 0}));  // 1 -> 0, every iteration
}

TEST(Schedule, CumulativeWritesGoToTheReducersRank) {
  Built b = start();
  const DatumId d = add_datum(b.g, 16);
  add(b, 0, {{d, AccessMode::CW}});
  add(b, 1, {{d, AccessMode::CW}});
  add(b, 2, {{d, AccessMode::R}});
  const Traffic t = predict(b, {3, 1});
  // Rank 1's temporary to the reducer on rank 0, the sum from rank 0 to the reader on 2.
  EXPECT_EQ(t.messages, (std::vector<std::uint64_t>{0, 0, 1, 1, 0, 0, 0, 0, 0}));
  EXPECT_EQ(t.total_bytes(), 32u);
}

TEST(Schedule, VersionsFromBeforeTheStepComeFromAHolder) {
  Built b = start();
  const DatumId d = add_datum(b.g, 24);
  add(b, 0, {{d, AccessMode::R}});
  add(b, 2, {{d, AccessMode::RW}});
  Holders h = everywhere(1, 3);
  h.has = {0, 1, 0};  // only rank 1 holds d
  b.g.derive_edges();
  b.a.k = 3;
  const ExecGraph x = lower(b.g, &b.a, CwMode::kReduce, ReduceScope::kPerProcessor);
  ChannelTable channels;
  const StepSchedule s = schedule_step(x, b.g, {3, 1}, h, channels);
  EXPECT_EQ(s.traffic.messages, (std::vector<std::uint64_t>{0, 0, 0, 1, 0, 1, 0, 0, 0}));
  EXPECT_EQ(s.traffic.entering_messages, 2u);
  EXPECT_EQ(s.traffic.entering_bytes, 48u);
  // Rank 2 wrote the last version: it alone holds it now.
  EXPECT_EQ(s.holders_after.has, (std::vector<std::uint8_t>{0, 0, 1}));
  // The reader and the writer of the same datum on other ranks: the writer does not wait
  // for the reader (each rank has its own copy).
  EXPECT_TRUE(s.instances[1].waits.size() == 1 &&
              s.instances[1].waits[0].kind == WaitKind::kMessage);
}

TEST(Schedule, ChannelsAreReusedByLaterSteps) {
  Built b = start();
  const DatumId d = add_datum(b.g, 8);
  add(b, 0, {{d, AccessMode::RW}});
  add(b, 1, {{d, AccessMode::RW}});
  b.g.derive_edges();
  b.a.k = 2;
  const ExecGraph x = lower(b.g, &b.a, CwMode::kReduce, ReduceScope::kPerProcessor);
  ChannelTable channels;
  const StepSchedule s1 = schedule_step(x, b.g, {2, 1}, everywhere(1, 2), channels);
  const std::size_t after_first = channels.channels().size();
  const StepSchedule s2 = schedule_step(x, b.g, {2, 1}, s1.holders_after, channels);
  // Step 2 also brings rank 1's version back to rank 0 (a version from before the step).
  EXPECT_EQ(s1.traffic.total_messages(), 1u);
  EXPECT_EQ(s2.traffic.total_messages(), 2u);
  EXPECT_EQ(s2.traffic.entering_messages, 1u);
  EXPECT_EQ(channels.channels().size(), after_first + 1);
  EXPECT_EQ(s2.messages[1].channel, s1.messages[0].channel);
}

}  // namespace
}  // namespace tgraph::mpi

namespace tgraph::mpi {
namespace {

TEST(Schedule, AVersionFromAnotherHolderTakesAnotherChannel) {
  ChannelTable channels;
  Channel a;
  a.what = 3;
  a.from = 0;
  a.to = 2;
  Channel b = a;
  b.from = 1;  // the same datum from before the step, held by another rank this time
  const std::uint32_t ca = channels.get(a);
  const std::uint32_t cb = channels.get(b);
  EXPECT_EQ(ca, 0u);
  EXPECT_EQ(cb, 1u);
  EXPECT_EQ(channels.get(a), ca);
  EXPECT_EQ(channels.channels().size(), 2u);
}

}  // namespace
}  // namespace tgraph::mpi
