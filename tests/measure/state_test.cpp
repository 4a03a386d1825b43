// SPDX-License-Identifier: MIT
// The first difference named right: regions ordered by the program order of their writes in
// the last recorded step, each with the task that last wrote it.
#include "tgraph/measure/state.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "tgraph/measure/adapter.hpp"

namespace tgraph::measure {
namespace {

TEST(State, RegionsFollowTheProgramOrderOfTheirWritesWithTheirLastWriter) {
  // Declared u, p, q; written q (task 0), then p (tasks 1 and 2); u never.
  StepGraph g;
  g.kinds = {"matvec", "direction", "fix"};
  g.objects = {{"tile(0,0)"}};
  g.data = {{"u", 0, 8}, {"p", 0, 8}, {"q", 0, 8}};
  auto task = [&g](KindId k, std::vector<Access> acc) {
    Task t;
    t.kind = k;
    t.object = 0;
    t.access_begin = static_cast<std::uint32_t>(g.accesses.size());
    t.access_count = static_cast<std::uint32_t>(acc.size());
    g.accesses.insert(g.accesses.end(), acc.begin(), acc.end());
    g.tasks.push_back(t);
  };
  task(0, {{1, AccessMode::R}, {2, AccessMode::W}});
  task(1, {{2, AccessMode::R}, {1, AccessMode::RW}});
  task(1, {{2, AccessMode::R}, {1, AccessMode::RW}});
  double u = 1, p = 2, q = 3;
  std::vector<StateRegion> r = {{"u", &u, 8}, {"p", &p, 8}, {"q", &q, 8}};
  set_write_order(r, g);
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r[2].first_write, 0u);  // q
  EXPECT_EQ(r[2].writer, "matvec of tile(0,0)");
  EXPECT_EQ(r[1].first_write, 1u);  // p
  EXPECT_EQ(r[1].writer, "direction of tile(0,0) #1");  // its second occurrence wrote last
  EXPECT_EQ(r[0].first_write, StateRegion::kNotWritten);  // u
  EXPECT_EQ(r[0].writer, "");
  // Both p and q differ: q, written first, is named, with its writer.
  double p2 = 2.5, q2 = 3.5;
  std::vector<StateRegion> r2 = {{"u", &u, 8}, {"p", &p2, 8}, {"q", &q2, 8}};
  set_write_order(r2, g);
  const auto d = compare(snapshot(r), snapshot(r2));
  ASSERT_TRUE(d.has_value());
  EXPECT_EQ(d->datum, "q");
  EXPECT_EQ(to_string(*d),
            "first differing datum q (byte 6, 1 bytes differ), last written by task matvec of "
            "tile(0,0)");
}

TEST(State, SnapshotsInAnotherOrderAreMatchedByName) {
  double a = 1, b = 2, b2 = 2.5;
  const StateRegion e[] = {{"a", &a, 8}, {"b", &b, 8}};
  const StateRegion x[] = {{"b", &b2, 8}, {"a", &a, 8}};
  const auto d = compare(snapshot(e), snapshot(x));
  ASSERT_TRUE(d.has_value());
  EXPECT_EQ(d->datum, "b");
  const StateRegion fewer[] = {{"a", &a, 8}};
  ASSERT_TRUE(compare(snapshot(e), snapshot(fewer)).has_value());
  EXPECT_EQ(compare(snapshot(e), snapshot(fewer))->datum, "b");
  EXPECT_FALSE(compare(snapshot(e), snapshot(e)).has_value());
}

TEST(State, AnEnginesStateKnowsItsWriteOrderAfterARecordedStep) {
  struct Two {
    double first = 1, second = 1;
  };
  auto e = std::make_shared<Two>();
  EngineCallbacks c;
  DatumId d1 = 0, d2 = 0;
  c.declare = [e, &d1, &d2](capture::Recorder& rec) {
    d2 = rec.datum("declared first, written second", kNoObject, 8, &e->second);
    d1 = rec.datum("declared second, written first", kNoObject, 8, &e->first);
  };
  c.step = [e, &d1, &d2](capture::Recorder& rec) {
    const KindId k = rec.kind("k");
    rec.task(k, kNoObject, {{d1, AccessMode::W}}, [e] { e->first = 2; });
    rec.task(k, kNoObject, {{d1, AccessMode::R}, {d2, AccessMode::W}}, [e] { e->second = e->first; });
  };
  std::unique_ptr<LiveEngine> engine = make_live_engine(std::move(c));
  engine->record_step(false);
  const std::vector<StateRegion> s = engine->state();
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].name, "declared first, written second");  // declaration order kept
  EXPECT_EQ(s[0].first_write, 1u);
  EXPECT_EQ(s[0].writer, "k #1");
  EXPECT_EQ(s[1].first_write, 0u);
  EXPECT_EQ(s[1].writer, "k");
}

}  // namespace
}  // namespace tgraph::measure
