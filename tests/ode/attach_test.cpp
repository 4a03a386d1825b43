// SPDX-License-Identifier: MIT
// A scene's world attached to tgraph's threading: it steps, its calls are recorded as task
// graphs whose edges are ODE's declared releases, and bad uses are refused by name.
#include "tgraph/ode/attach.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/metrics.hpp"
#include "tgraph/ode/scenes.hpp"

namespace tgraph::ode {
namespace {

class OdeWorld : public ::testing::Test {
 protected:
  void SetUp() override { dInitODE2(0); }
  void TearDown() override { dCloseODE(); }
};

TEST_F(OdeWorld, StepsOnTwoThreadsUnderEachPolicy) {
  for (const char* method :
       {"worksteal", "islands", "islands-serial", "list", "ode", "sequential"}) {
    auto scene = Scene::make("ode-piles");
    AttachOptions o;
    o.method = choose_method(method);
    o.threads = 2;
    o.repartition_interval = 3;
    {
      Attachment attach(scene->world(), o);
      for (int i = 0; i < 10; ++i) scene->step(&attach);
      const AttachStats s = attach.stats();
      EXPECT_EQ(s.steps, 10u) << method;
      EXPECT_GT(s.world_ns, 0) << method;
      EXPECT_GT(s.collide_ns, 0) << method;
      if (o.method.policy != Policy::kOde && o.method.policy != Policy::kSequential) {
        EXPECT_GT(s.calls, 10u * 32) << method;  // every island at least one call a step
      }
    }
    for (double v : scene->state()) ASSERT_TRUE(std::isfinite(v)) << method;
    EXPECT_LT(scene->depth_below_floor(), 0.01) << method;
  }
}

TEST_F(OdeWorld, RecordsEachStepAsAGraphOfOdesCallsInTopologicalOrder) {
  auto scene = Scene::make("ode-piles");
  AttachOptions o;
  o.threads = 2;
  o.record = true;
  Attachment attach(scene->world(), o);
  for (int i = 0; i < 3; ++i) scene->step(&attach);
  const std::vector<StepGraph> steps = attach.take_steps();
  ASSERT_EQ(steps.size(), 3u);
  for (const StepGraph& g : steps) {
    EXPECT_EQ(g.validate(), "");
    std::set<std::string> kinds(g.kinds.begin(), g.kinds.end());
    EXPECT_TRUE(kinds.count("dWorldQuickStep"));
    EXPECT_TRUE(kinds.count("World Islands Stepping Group"));
    EXPECT_TRUE(kinds.count("Island Stepping Job Start"));
    EXPECT_TRUE(kinds.count("QuickStepIsland Stage1"));
    EXPECT_GT(g.host_ns, 0u);  // the collision before the step
    for (const Edge& e : g.edges) EXPECT_LT(e.from, e.to);
    // The two island jobs the stepping thread posts run side by side: no path between them.
    std::vector<TaskId> starts;
    for (TaskId t = 0; t < g.tasks.size(); ++t)
      if (g.kind_name(t) == "World Islands Stepping Start") starts.push_back(t);
    ASSERT_EQ(starts.size(), 4u);  // two calls, each split at its post
    std::vector<bool> reached(g.tasks.size(), false);
    reached[starts[0]] = true;
    for (TaskId t = starts[0]; t < g.tasks.size(); ++t)
      if (reached[t])
        for (const Edge& e : g.edges)
          if (e.from == t) reached[e.to] = true;
    int unreached = 0;
    for (TaskId t : starts) unreached += reached[t] ? 0 : 1;
    EXPECT_EQ(unreached, 2);  // the other call's two parts
    EXPECT_TRUE(g.carried_edges.empty());
  }
  EXPECT_TRUE(attach.take_steps().empty());
}

// The calls of `steps` recorded steps of ode-piles under islands-serial at `threads`.
std::vector<StepGraph> serial_islands_steps(std::uint32_t threads, int steps) {
  auto scene = Scene::make("ode-piles");
  AttachOptions o;
  o.method = choose_method("islands-serial");
  o.threads = threads;
  o.record = true;
  Attachment attach(scene->world(), o);
  for (int i = 0; i < steps; ++i) scene->step(&attach);
  return attach.take_steps();
}

TEST_F(OdeWorld, SerialIslandsStepsEachIslandSingleThreadedInOneJobPerThread) {
  // ODE plans one island job of single-threaded island steps; the runtime adds the others:
  // K "World Islands Stepping Start" calls (each split at its post of the first selection),
  // one "Island Stepping Job Start" per island, and no stage of ODE's threaded quickstep.
  for (const std::uint32_t threads : {1u, 2u, 3u}) {
    const std::vector<StepGraph> steps = serial_islands_steps(threads, 3);
    ASSERT_EQ(steps.size(), 3u);
    for (const StepGraph& g : steps) {
      EXPECT_EQ(g.validate(), "");
      int job_parts = 0, island_steps = 0, stages = 0;
      for (TaskId t = 0; t < g.tasks.size(); ++t) {
        const std::string kind(g.kind_name(t));
        job_parts += kind == "World Islands Stepping Start";
        island_steps += kind == "Island Stepping Job Start";
        stages += kind.rfind("QuickStepIsland", 0) == 0;
      }
      EXPECT_EQ(job_parts, 2 * static_cast<int>(threads)) << threads;
      // The first steps' boxes fall apart, not touching: each of the 640 its own island.
      EXPECT_EQ(island_steps, 640) << threads;
      EXPECT_EQ(stages, 0) << threads;
    }
  }
}

TEST_F(OdeWorld, SerialIslandsOnOneThreadIsOdeSelfThreadedBitForBit) {
  // One thread, one job: the very algorithm and order of ODE self-threaded (each scene made
  // just before its steps: making one seeds ODE's random reordering of constraints).
  const auto forty_steps = [](const char* method) {
    auto scene = Scene::make("ode-piles");
    AttachOptions o;
    o.threads = 1;
    o.method = choose_method(method);
    Attachment attach(scene->world(), o);
    for (int i = 0; i < 40; ++i) scene->step(&attach);
    return scene->state();
  };
  const std::vector<double> reference = forty_steps("sequential");
  EXPECT_EQ(forty_steps("islands-serial"), reference);
}

AttachOptions one_thread_recording() {
  AttachOptions o;
  o.threads = 1;
  o.record = true;
  return o;
}

// Four steps of ode-chains recorded on one thread, taken at once; `room`: their largest.
std::vector<StepGraph> four_steps_whole(const AttachOptions& o, RecordingRoom* room) {
  auto scene = Scene::make("ode-chains");
  Attachment attach(scene->world(), o);
  for (int i = 0; i < 4; ++i) scene->step(&attach);
  if (room) *room = attach.recording_room();
  return attach.take_steps();
}

// One thread records the same call tree from the same world: the same graphs, step by step.
void expect_same_graphs(const std::vector<StepGraph>& a, const std::vector<StepGraph>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < b.size(); ++i) {
    EXPECT_EQ(a[i].validate(), "");
    EXPECT_EQ(a[i].tasks.size(), b[i].tasks.size()) << i;
    EXPECT_EQ(a[i].edges.size(), b[i].edges.size()) << i;
    for (TaskId t = 0; t < b[i].tasks.size() && t < a[i].tasks.size(); ++t)
      ASSERT_EQ(a[i].kind_name(t), b[i].kind_name(t)) << i << " " << t;
  }
}

TEST_F(OdeWorld, ReservedRoomRecordsTheSameGraphsAndTheRoomIsTheLargestStep) {
  // A recording into room made when attaching must give the very graphs of one that grows
  // its logs.
  AttachOptions o = one_thread_recording();
  RecordingRoom room;
  const std::vector<StepGraph> grown = four_steps_whole(o, &room);
  std::size_t largest = 0;
  for (const StepGraph& g : grown) largest = std::max(largest, g.tasks.size());
  EXPECT_EQ(room.parts, largest);         // one task per recorded part
  EXPECT_EQ(room.thread_parts, largest);  // one thread took them all
  EXPECT_GT(room.calls, 24u);             // every chain's island at least one call
  o.reserve_steps = 4;
  o.reserve_room = room;
  expect_same_graphs(four_steps_whole(o, nullptr), grown);
}

TEST_F(OdeWorld, ARecordingTakenInPartsGivesTheGraphsOfOneTakenWhole) {
  // Steps recorded two at a time, room made between the parts (validate's way), against the
  // four taken at once; dropped steps leave no graph and keep the room's maxima.
  AttachOptions o = one_thread_recording();
  RecordingRoom room;
  const std::vector<StepGraph> whole = four_steps_whole(o, &room);
  o.reserve_room = room;
  std::vector<StepGraph> parts;
  {
    auto scene = Scene::make("ode-chains");
    Attachment attach(scene->world(), o);
    for (int part = 0; part < 2; ++part) {
      attach.reserve_recording(2);
      for (int i = 0; i < 2; ++i) scene->step(&attach);
      for (StepGraph& g : attach.take_steps()) parts.push_back(std::move(g));
    }
    scene->step(&attach);
    attach.drop_steps();
    EXPECT_TRUE(attach.take_steps().empty());
    EXPECT_GE(attach.recording_room().parts, room.parts);
  }
  expect_same_graphs(parts, whole);
}

TEST_F(OdeWorld, RefusesZeroThreadsAndRecordingUnderOdesOwnStepping) {
  auto scene = Scene::make("ode-chains");
  AttachOptions o;
  o.threads = 0;
  EXPECT_THROW(Attachment(scene->world(), o), OptionError);
  o.threads = 2;
  o.record = true;
  o.method = choose_method("ode");
  EXPECT_THROW(Attachment(scene->world(), o), OptionError);
  o.method = choose_method("sequential");
  EXPECT_THROW(Attachment(scene->world(), o), OptionError);
  EXPECT_THROW(Attachment(nullptr, AttachOptions{}), OptionError);
  EXPECT_THROW(choose_method("no-such-method"), OptionError);
}

TEST_F(OdeWorld, AWorldNoLongerSteppedThroughTheAttachmentIsNamed) {
  auto scene = Scene::make("ode-chains");
  Attachment attach(scene->world(), AttachOptions{});
  scene->step(&attach);
  dWorldSetStepThreadingImplementation(scene->world(), nullptr, nullptr);  // someone else's
  try {
    scene->step(&attach);
    FAIL() << "no error";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("not stepped through this attachment"), std::string::npos);
  }
}

TEST_F(OdeWorld, AnOdeErrorIsOneLineAndExit1NotAnAbort) {
  EXPECT_EXIT(
      {
        auto scene = Scene::make("ode-chains");
        Attachment attach(scene->world(), AttachOptions{});
        dError(7, "planted error %d", 42);
      },
      ::testing::ExitedWithCode(1), "tgraph: ODE error 7: planted error 42");
  EXPECT_EXIT(
      {
        auto scene = Scene::make("ode-chains");
        Attachment attach(scene->world(), AttachOptions{});
        dDebug(3, "planted internal error");
      },
      ::testing::ExitedWithCode(1),
      "tgraph: ODE internal error \\(dDebug\\) 3: planted internal error");
}

TEST_F(OdeWorld, WarningsAreCountedNotPrinted) {
  auto scene = Scene::make("ode-chains");
  Attachment attach(scene->world(), AttachOptions{});
  dMessage(5, "planted warning");
  const AttachStats s = attach.stats();
  EXPECT_EQ(s.messages, 1u);
  EXPECT_NE(s.first_message.find("planted warning"), std::string::npos);
}

TEST_F(OdeWorld, UnknownSceneIsAnInputError) {
  EXPECT_THROW(Scene::make("ode-nothing"), InputError);
  EXPECT_THROW(parse_stepper("euler"), OptionError);
  EXPECT_EQ(parse_stepper("step"), Stepper::kStep);
}

}  // namespace
}  // namespace tgraph::ode
