// SPDX-License-Identifier: MIT
// An outside engine through the adapter (measure/adapter.hpp): a tiny engine's callbacks run
// live under the partition policy and the baselines give the state of the sequential run bit
// for bit; a body that depends on the thread it runs on is caught as "differs", naming the
// region it writes.
#include "tgraph/measure/adapter.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "tgraph/graph/cumulative.hpp"
#include "tgraph/graph/error.hpp"

namespace tgraph::measure {
namespace {

using capture::Recorder;

// Cells that each grow on their own, and their sum (a CW reduction with an accumulator).
// With `plant`, one more task writes which thread ran it: race-free, but not a function of
// the data it declares, so a run on other threads leaves another value.
struct Tiny {
  static constexpr int kCells = 8;
  std::array<double, kCells> cell{};
  double total = 0;
  double planted = 0;
  bool plant = false;
  std::thread::id home;  // the thread that stepped the engine first (processor 0's)
  std::vector<ObjectId> obj;
  std::vector<DatumId> ids;
  DatumId total_id = 0, planted_id = 0;
  KindId grow = 0, reset = 0, sum = 0, mark = 0;

  void declare(Recorder& rec) {
    home = std::this_thread::get_id();
    grow = rec.kind("grow"), reset = rec.kind("reset"), sum = rec.kind("sum");
    mark = rec.kind("mark");
    for (int i = 0; i < kCells; ++i) {
      cell[static_cast<std::size_t>(i)] = 1.0 + i;
      obj.push_back(rec.object("cell" + std::to_string(i)));
      ids.push_back(rec.datum("cell" + std::to_string(i), obj.back(), sizeof(double),
                              &cell[static_cast<std::size_t>(i)]));
    }
    total_id = rec.datum("total", kNoObject, sizeof(double), &total);
    rec.accumulator(total_id, make_accumulator(total));
    planted_id = rec.datum("planted", kNoObject, sizeof(double), &planted);
  }

  void step(Recorder& rec) {
    Tiny* e = this;
    for (std::size_t i = 0; i < kCells; ++i)
      rec.task(grow, obj[i], {{ids[i], AccessMode::RW}}, [e, i] {
        for (int r = 0; r < 200; ++r) e->cell[i] = std::sqrt(e->cell[i] * e->cell[i] + 0.5);
      });
    rec.task(reset, kNoObject, {{total_id, AccessMode::W}}, [e] { e->total = 0; });
    for (std::size_t i = 0; i < kCells; ++i)
      rec.task(sum, obj[i], {{ids[i], AccessMode::R}, {total_id, AccessMode::CW}},
               [e, i] { accumulate(e->total) += e->cell[i] / (1.0 + static_cast<double>(i)); });
    if (plant)
      rec.task(mark, obj[kCells - 1], {{planted_id, AccessMode::W}},
               [e] { e->planted = std::this_thread::get_id() == e->home ? 1.0 : 2.0; });
  }
};

EngineCallbacks callbacks(const std::shared_ptr<Tiny>& e, bool same_every_step = true) {
  EngineCallbacks c;
  c.declare = [e](Recorder& rec) { e->declare(rec); };
  c.step = [e](Recorder& rec) { e->step(rec); };
  c.same_every_step = same_every_step;
  return c;
}

LiveOptions options(std::uint32_t threads, std::uint32_t steps) {
  LiveOptions o;
  o.exec.threads = threads;
  o.exec.pin = false;
  o.steps = steps;
  o.check = true;
  o.observe = false;
  return o;
}

struct Case {
  const char* method;  // a strategy or a baseline policy
  std::uint32_t threads;
};

class AdapterLive : public ::testing::TestWithParam<Case> {};

TEST_P(AdapterLive, TinyEngineRunsLiveAndIsIdenticalToTheSequentialRun) {
  const Case c = GetParam();
  const LiveResult r = run_engine_live([] { return callbacks(std::make_shared<Tiny>()); },
                                       choose_method(c.method), options(c.threads, 4));
  ASSERT_TRUE(r.check.has_value());
  EXPECT_EQ(*r.check, Check::kIdentical) << (r.difference ? to_string(*r.difference) : "");
  EXPECT_EQ(r.threads, c.threads);
  EXPECT_EQ(r.data_compared, Tiny::kCells + 2u);  // every datum with storage
  ASSERT_EQ(r.steps.size(), 4u);
  EXPECT_TRUE(r.steps[0].recorded);
  for (std::size_t s = 1; s < r.steps.size(); ++s) EXPECT_FALSE(r.steps[s].recorded) << s;
  EXPECT_GT(r.baseline_wall_ns, 0);
  EXPECT_GT(r.speedup, 0.0);
}

INSTANTIATE_TEST_SUITE_P(MethodsAndThreads, AdapterLive,
                         ::testing::Values(Case{"owner", 1}, Case{"owner", 2}, Case{"list", 2},
                                           Case{"roundrobin", 3}, Case{"worksteal", 2},
                                           Case{"barrier", 2}, Case{"sequential", 1}),
                         [](const auto& p) {
                           return std::string(p.param.method) + "_" +
                                  std::to_string(p.param.threads);
                         });

TEST(Adapter, LiveStepsComputeWhatThePlainEngineComputes) {
  // The adapter's plain steps are the sequential engine: the same coordination code with the
  // bodies run at once. Without the reduction in question (sum of 8 in program order), the
  // recorded program run sequentially ends in the same state.
  auto plain = std::make_shared<Tiny>(), recorded = std::make_shared<Tiny>();
  std::unique_ptr<LiveEngine> a = make_live_engine(callbacks(plain));
  std::unique_ptr<LiveEngine> b = make_live_engine(callbacks(recorded, false));
  for (int s = 0; s < 3; ++s) {
    a->plain_step();
    LiveStep step = b->record_step(true);
    ASSERT_FALSE(step.reuse_previous);  // same_every_step off: recorded every time
    for (std::size_t t = 0; t < step.bodies.size(); ++t)
      if (step.bodies[t]) step.bodies[t]();
  }
  EXPECT_EQ(plain->cell, recorded->cell);
  EXPECT_EQ(plain->total, recorded->total);
  EXPECT_NE(plain->cell[0], 1.0);  // the steps ran
  ASSERT_EQ(a->state().size(), Tiny::kCells + 2u);
  EXPECT_EQ(a->state()[Tiny::kCells].name, "total");
  EXPECT_EQ(a->state()[Tiny::kCells].ptr, &plain->total);
}

TEST(Adapter, ABodyThatDependsOnItsThreadIsReportedAsDiffersNamingItsRegion) {
  // Every task on processor 1: a worker thread in the live pass, the calling thread in the
  // serial twin the check compares with.
  const partition::StepPartitioner on_processor_1 = [](const StepGraph& g, std::uint32_t k,
                                                       const StepGraph*, const Assignment*) {
    Assignment a;
    a.k = k;
    a.proc.assign(g.tasks.size(), 1);
    return a;
  };
  LiveOptions o = options(2, 2);
  o.policy = replay::Policy::kPartition;
  // The partitioner's placement at the second step (in the foreground: the first step has
  // the owner rule before any cost is measured), and no stealing: the main thread, idle,
  // would otherwise take processor 1's tasks and run the planted body on its own thread.
  o.background_partition = false;
  o.exec.partition.steal = false;
  const LiveResult r = run_live(
      [] {
        auto e = std::make_shared<Tiny>();
        e->plant = true;
        return make_live_engine(callbacks(e));
      },
      &on_processor_1, o);
  ASSERT_TRUE(r.check.has_value());
  EXPECT_EQ(*r.check, Check::kDiffers);
  ASSERT_TRUE(r.difference.has_value());
  EXPECT_EQ(r.difference->datum, "planted");  // cells and total agree: the first differing
  EXPECT_EQ(r.difference->offset, 6u);        // 1.0 and 2.0 differ in their two top bytes
  EXPECT_EQ(r.difference->differing_bytes, 2u);

  // The same engine without the planted task is identical under the same placement.
  const LiveResult clean = run_live(
      [] { return make_live_engine(callbacks(std::make_shared<Tiny>())); }, &on_processor_1, o);
  ASSERT_TRUE(clean.check.has_value());
  EXPECT_EQ(*clean.check, Check::kIdentical);
}

TEST(Adapter, TheJsonIsTgraphRunsWithTheEnginesOwnKeys) {
  LiveOptions o = options(2, 2);
  o.repeat = 2;
  const LiveResult r = run_engine_live([] { return callbacks(std::make_shared<Tiny>()); },
                                       choose_method("owner"), o);
  const auto j = nlohmann::json::parse(to_json(r, "tiny", "owner", {{"residual", 0.25}}));
  EXPECT_EQ(j["check"], "identical");
  EXPECT_EQ(j["threads"], 2);
  EXPECT_EQ(j["method"], "owner");
  EXPECT_EQ(j["scene"], "tiny");
  EXPECT_EQ(j["policy"], "partition");
  EXPECT_EQ(j["repeat"], 2);
  EXPECT_EQ(j["residual"], 0.25);
  EXPECT_DOUBLE_EQ(j["speedup"].get<double>(), r.speedup);
  EXPECT_TRUE(j.contains("breakdown") && j.contains("sequential_wall_ns"));
  // Without extra keys: exactly `tgraph run --json`'s object.
  EXPECT_EQ(nlohmann::json::parse(to_json(r, "tiny", "owner", {})),
            nlohmann::json::parse(to_json(r, std::string("tiny"), std::string("owner"))));
}

TEST(Adapter, AnEngineSteppedBothWaysIsRefused) {
  std::unique_ptr<LiveEngine> e = make_live_engine(callbacks(std::make_shared<Tiny>()));
  e->record_step(false);
  EXPECT_THROW(e->plain_step(), UsageError);
}

TEST(Adapter, RecorderMisusesAreRefusedNamingTheFirst) {
  auto tiny = std::make_shared<Tiny>();
  EngineCallbacks c = callbacks(tiny);
  c.step = [tiny](Recorder& rec) {
    rec.begin_step();  // the adapter began the step already: one misuse
    tiny->step(rec);
  };
  std::unique_ptr<LiveEngine> e = make_live_engine(std::move(c));
  try {
    e->record_step(false);
    FAIL() << "no error";
  } catch (const UsageError& err) {
    EXPECT_EQ(std::string(err.what()),
              "engine: begin_step: the previous step was not ended (missing end_step) (step 1, "
              "after 0 tasks)");
  }
}

TEST(Adapter, ALiveRunNamesAMissingEndLoop) {
  auto tiny = std::make_shared<Tiny>();
  EngineCallbacks c = callbacks(tiny);
  c.step = [tiny](Recorder& rec) {
    tiny->step(rec);
    const LoopId l = rec.begin_loop(tiny->total_id, 4);
    do {
      rec.task(tiny->sum, kNoObject, {{tiny->total_id, AccessMode::RW}}, [] {});
    } while (!rec.conditional_break(l, [] { return true; }));
    // no end_loop
  };
  try {
    run_engine_live([c] { return c; }, choose_method("owner"), options(2, 1));
    FAIL() << "no error";
  } catch (const UsageError& err) {
    EXPECT_EQ(std::string(err.what()),
              "engine: end_step: the loop is still open (missing end_loop) (loop 0 on total, "
              "step 0, after 19 tasks)");
  }
}

TEST(Adapter, MissingCallbacksAndUnknownStrategiesAreRefused) {
  EXPECT_THROW(make_live_engine(EngineCallbacks{}), UsageError);
  EXPECT_THROW(run_engine_live([] { return callbacks(std::make_shared<Tiny>()); },
                               choose_method("no-such-strategy"), options(2, 1)),
               UsageError);
}

TEST(Adapter, AGivenStateCallbackNamesTheRegionsCompared) {
  auto tiny = std::make_shared<Tiny>();
  EngineCallbacks c = callbacks(tiny);
  c.state = [tiny] { return std::vector<StateRegion>{{"total only", &tiny->total, 8}}; };
  std::unique_ptr<LiveEngine> e = make_live_engine(std::move(c));
  e->plain_step();
  const std::vector<StateRegion> s = e->state();
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].name, "total only");
  EXPECT_EQ(s[0].ptr, &tiny->total);
}

}  // namespace
}  // namespace tgraph::measure
