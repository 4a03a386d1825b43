// SPDX-License-Identifier: MIT
// The first difference named right: regions ordered by the program order of their writes in
// the last recorded step, each with the task that last wrote it.
#include "tgraph/measure/state.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "tgraph/measure/adapter.hpp"
#include "tgraph/measure/live.hpp"
#include "tgraph/partition/strategy.hpp"
#include "tgraph/measure/report.hpp"

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

TEST(State, ValuesAreComparedAsDoublesAndAFlagBitForBit) {
  double a[3] = {1.0, -4.0, 0.0}, b[3] = {1.0, -4.0 + 0x1p-50, 0.0};
  const StateRegion e[] = {{"v", a, sizeof a}};
  const StateRegion x[] = {{"v", b, sizeof b}};
  const ValueDifference d = compare_values(snapshot(e), snapshot(x));
  EXPECT_EQ(d.max_abs_diff, 0x1p-50);
  EXPECT_EQ(d.max_rel_diff, 0x1p-50 / 4.0);  // relative to the datum's largest magnitude
  EXPECT_EQ(d.max_rel_datum, "v");
  EXPECT_EQ(d.differing_values, 1u);
  EXPECT_TRUE(d.incomparable.empty());
  // The magnitudes involved (a residual made small by cancellation) widen the scale.
  const Magnitudes involved{{"v", 64.0}};
  EXPECT_EQ(compare_values(snapshot(e), snapshot(x), &involved).max_rel_diff, 0x1p-50 / 64.0);
  bool f1 = true, f2 = false;
  const StateRegion fe[] = {{"converged", &f1, 1}};
  const StateRegion fx[] = {{"converged", &f2, 1}};
  EXPECT_NE(compare_values(snapshot(fe), snapshot(fx)).incomparable.find("converged"),
            std::string::npos);
  double n1 = std::nan(""), n2 = 1.0;
  const StateRegion ne[] = {{"nan", &n1, 8}};
  const StateRegion nx[] = {{"nan", &n2, 8}};
  EXPECT_FALSE(compare_values(snapshot(ne), snapshot(nx)).incomparable.empty());
}

TEST(State, TheReductionOrderBoundIsTwoGammaPerRound) {
  const double u = 0x1p-53;
  EXPECT_EQ(reduction_order_bound(1, 100), 0.0);  // nothing summed in another order
  EXPECT_DOUBLE_EQ(reduction_order_bound(9, 1), 2 * 8 * u / (1 - 8 * u));
  EXPECT_DOUBLE_EQ(reduction_order_bound(9, 10), 10 * reduction_order_bound(9, 1));
}

// An engine that sums 16 terms of mixed magnitudes into one datum by CW (a reduction whose
// order the partition policy changes), the sum fed back into the terms every step; with
// `planted`, a body adds 1e-9 when run live (a real difference).
struct Sums {
  static constexpr int kTerms = 16;
  double terms[kTerms] = {};
  double total = 0;
  bool planted = false;
  bool live = false;
  DatumId d_terms[kTerms] = {}, d_total = 0;
  Accumulator acc;
  void declare(capture::Recorder& rec) {
    live = rec.mode() == capture::Mode::kDeferred;
    for (int i = 0; i < kTerms; ++i) {
      terms[i] = std::ldexp(1.0 + i / 7.0, (i % 5) * 7 - 14) * (i % 2 ? -1 : 1);
      d_terms[i] = rec.datum("term" + std::to_string(i), rec.object("o" + std::to_string(i)), 8,
                             &terms[i]);
    }
    d_total = rec.datum("total", kNoObject, 8, &total);
    acc = make_accumulator(total);
    rec.accumulator(d_total, acc);
  }
  void step(capture::Recorder& rec) {
    const KindId add = rec.kind("add"), feed = rec.kind("feed");
    for (int i = 0; i < kTerms; ++i)
      rec.task(add, static_cast<ObjectId>(i), {{d_terms[i], AccessMode::R}, {d_total, AccessMode::CW}},
               [this, i] { accumulate(total) += terms[i] + (planted && live && i == 3 ? 1e-9 : 0.0); });
    for (int i = 0; i < kTerms; ++i)
      rec.task(feed, static_cast<ObjectId>(i), {{d_total, AccessMode::R}, {d_terms[i], AccessMode::RW}},
               [this, i] { terms[i] = terms[i] * 0.5 + total * 1e-3; });
  }
};

LiveResult run_sums(bool planted, CheckReference reference) {
  LiveOptions o;
  o.exec.threads = 2;
  o.exec.pin = false;
  o.steps = 6;
  o.check = true;
  o.check_reference = reference;
  o.observe = false;
  o.baseline = false;
  const CallbacksFactory make = [planted] {
    auto e = std::make_shared<Sums>();
    e->planted = planted;
    EngineCallbacks c;
    c.declare = [e](capture::Recorder& rec) { e->declare(rec); };
    c.step = [e](capture::Recorder& rec) { e->step(rec); };
    return c;
  };
  return run_engine_live(make, choose_method("owner"), o);
}

TEST(State, ThePlainCheckIsWithinRoundingOfAReorderedSumAndSaysItsReference) {
  const LiveResult r = run_sums(false, CheckReference::kPlain);
  ASSERT_TRUE(r.check.has_value());
  EXPECT_EQ(r.check_reference, CheckReference::kPlain);
  EXPECT_EQ(r.longest_reduction, Sums::kTerms + 1u);
  EXPECT_EQ(r.reduction_rounds, 6u);
  EXPECT_DOUBLE_EQ(r.rounding_bound, reduction_order_bound(Sums::kTerms + 1, 6));
  EXPECT_TRUE(*r.check == Check::kIdentical || *r.check == Check::kWithinRounding)
      << to_string(*r.check) << " " << (r.values ? r.values->max_rel_diff : 0);
  if (*r.check == Check::kWithinRounding) {
    ASSERT_TRUE(r.values.has_value());
    EXPECT_GT(r.values->max_abs_diff, 0);
    EXPECT_LE(r.values->max_rel_diff, r.rounding_bound);
  }
  const auto j = nlohmann::json::parse(to_json(r, "sums", "owner"));
  EXPECT_EQ(j["check_reference"], "plain");
  EXPECT_EQ(j["check"], std::string(to_string(*r.check)));
  EXPECT_EQ(j.contains("max_rel_diff"), r.values.has_value());
  // The twin check says so too.
  const LiveResult t = run_sums(false, CheckReference::kTwin);
  EXPECT_EQ(t.check, Check::kIdentical);
  EXPECT_EQ(nlohmann::json::parse(to_json(t, "sums", "owner"))["check_reference"], "twin");
  EXPECT_NE(to_text(t, "sums", "owner", 1).find("check against the twin ("), std::string::npos);
}

TEST(State, APlantedRealDifferenceDiffersFromThePlainRunWithItsFigures) {
  const LiveResult r = run_sums(true, CheckReference::kPlain);
  ASSERT_TRUE(r.check.has_value());
  EXPECT_EQ(*r.check, Check::kDiffers);
  ASSERT_TRUE(r.values.has_value());
  EXPECT_GT(r.values->max_rel_diff, r.rounding_bound);
  EXPECT_GE(r.values->max_abs_diff, 1e-10);
  const auto j = nlohmann::json::parse(to_json(r, "sums", "owner"));
  EXPECT_EQ(j["check"], "differs");
  EXPECT_GT(j["max_abs_diff"].get<double>(), 0);
  EXPECT_GT(j["max_rel_diff"].get<double>(), j["rounding_bound"]["max_rel_diff"].get<double>());
}

// bars64 at 2 threads: under CwMode::kSerialize the live state is the plain run's bit for bit;
// under kReduce the plain check says so and gives its figures and the bound it held them to
// (the implicit CG's values exceed a rounding bound: docs/instrumenting.md).
TEST(State, Bars64IsBitIdenticalToThePlainRunWithSerializedCwAndGivesFiguresWithout) {
  auto run = [](CwMode cw) {
    LiveOptions o;
    o.exec.threads = 2;
    o.exec.pin = false;
    o.exec.cw = cw;
    o.steps = 2;
    o.check = true;
    o.check_reference = CheckReference::kPlain;
    o.observe = false;
    o.baseline = false;
    const partition::StepPartitioner part = partition::step_partitioner("owner", {});
    return run_live([] { return make_live_engine("bars64"); }, &part, o);
  };
  const LiveResult serialized = run(CwMode::kSerialize);
  EXPECT_EQ(serialized.check, Check::kIdentical)
      << (serialized.difference ? to_string(*serialized.difference) : "");
  const LiveResult reduced = run(CwMode::kReduce);
  ASSERT_TRUE(reduced.check.has_value());
  EXPECT_EQ(reduced.check_reference, CheckReference::kPlain);
  EXPECT_FALSE(reduced.iterations.has_value());  // the same CG iterations in both runs
  EXPECT_EQ(reduced.longest_reduction, 65u);  // the 64 bars' partial dot products and the start
  EXPECT_GT(reduced.rounding_bound, 0);
  if (*reduced.check != Check::kIdentical) {
    ASSERT_TRUE(reduced.values.has_value());
    EXPECT_GT(reduced.values->max_abs_diff, 0);
    EXPECT_FALSE(reduced.values->max_rel_datum.empty());
    EXPECT_EQ(*reduced.check, reduced.values->max_rel_diff <= reduced.rounding_bound
                                  ? Check::kWithinRounding
                                  : Check::kDiffers);
  }
}

}  // namespace
}  // namespace tgraph::measure
