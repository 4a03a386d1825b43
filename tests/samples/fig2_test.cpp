// SPDX-License-Identifier: MIT
// The paper's Figure 2 scene: exactly which graph one explicit step must produce.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <set>
#include <string>
#include <tuple>

#include "tgraph/capture/recorder.hpp"
#include "tgraph/graph/metrics.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/samples/scene.hpp"

namespace tgraph::samples {
namespace {

StepGraph capture_step(Scene& scene, capture::Recorder& rec) {
  scene.step(rec);
  return rec.end_step();
}

std::string datum_name(const StepGraph& g, DatumId d) { return g.data[d].name; }

// Task t as "kind@object: datum:mode datum:mode ...".
std::string describe(const StepGraph& g, TaskId t) {
  std::string s = g.kind_name(t) + "@" + g.objects[g.tasks[t].object].name + ":";
  for (const Access& a : g.accesses_of(t)) s += " " + datum_name(g, a.datum) + ":" + std::string(to_string(a.mode));
  return s;
}

TEST(Fig2, OneStepHasTheNineTasksOfThePaperFigure) {
  auto scene = make_scene("fig2");
  capture::Recorder rec(capture::Mode::kCapture);
  const StepGraph g = capture_step(*scene, rec);
  ASSERT_EQ(g.validate(), "");
  const std::vector<std::string> expected = {
      "resetForce@A: A.f:W",
      "resetForce@B: B.f:W",
      "addForce@A: A.f:CW",                          // gravity ("accumulate")
      "addForce@B: B.f:CW",                          // gravity ("accumulate")
      "addForce@AB: A.x:R B.x:R A.f:CW B.f:CW",      // the interaction's compute force
      "updateVelocity@A: A.f:R A.v:RW",              // v += a dt
      "updateVelocity@B: B.f:R B.v:RW",
      "updatePosition@A: A.v:R A.x:RW",              // x += v dt
      "updatePosition@B: B.v:R B.x:RW",
  };
  ASSERT_EQ(g.tasks.size(), expected.size());
  for (TaskId t = 0; t < g.tasks.size(); ++t) EXPECT_EQ(describe(g, t), expected[t]) << "task " << t;
  EXPECT_EQ(g.data.size(), 6u);
  EXPECT_EQ(g.objects.size(), 3u);
  EXPECT_TRUE(g.loops.empty());
  ASSERT_EQ(g.contacts.size(), 1u);
  EXPECT_EQ(g.objects[g.contacts[0].a].name, "A");
  EXPECT_EQ(g.objects[g.contacts[0].b].name, "B");
  EXPECT_EQ(g.groups, (std::vector<std::uint32_t>{0, 0, 0}));
}

TEST(Fig2, EdgesAreExactlyTheDataflowOfTheFigure) {
  auto scene = make_scene("fig2");
  capture::Recorder rec(capture::Mode::kCapture);
  const StepGraph g = capture_step(*scene, rec);
  using E = std::tuple<TaskId, TaskId, std::string, EdgeKind>;
  std::set<E> got;
  for (const Edge& e : g.edges) got.insert({e.from, e.to, datum_name(g, e.datum), e.kind});
  const std::set<E> expected = {
      {0, 2, "A.f", EdgeKind::WAW}, {0, 4, "A.f", EdgeKind::WAW},  // reset before the CW group
      {1, 3, "B.f", EdgeKind::WAW}, {1, 4, "B.f", EdgeKind::WAW},
      {2, 5, "A.f", EdgeKind::RAW}, {4, 5, "A.f", EdgeKind::RAW},  // the velocity update reads all CW writers
      {3, 6, "B.f", EdgeKind::RAW}, {4, 6, "B.f", EdgeKind::RAW},
      {5, 7, "A.v", EdgeKind::RAW}, {6, 8, "B.v", EdgeKind::RAW},
      {4, 7, "A.x", EdgeKind::WAR}, {4, 8, "B.x", EdgeKind::WAR},  // positions move after the force read them
  };
  EXPECT_EQ(got, expected);
  EXPECT_TRUE(g.carried_edges.empty());
  // The two CW writers of A.f (gravity and interaction) are independent.
  for (const Edge& e : g.edges) EXPECT_FALSE(e.from == 2 && e.to == 4);
}

TEST(Fig2, TenCapturedStepsShareOneStructureAndMeasureWork) {
  auto scene = make_scene("fig2");
  capture::Recorder rec(capture::Mode::kCapture);
  const auto path = std::filesystem::temp_directory_path() / "tgraph_fig2_test.tgt";
  {
    TraceHeader header;
    header.scene = "fig2";
    TraceWriter writer(path.string(), header);
    for (int s = 0; s < 10; ++s) writer.append(capture_step(*scene, rec));
    writer.close();
  }
  EXPECT_EQ(rec.errors(), 0u);
  const Trace trace = read_trace(path.string());
  std::filesystem::remove(path);
  ASSERT_EQ(trace.steps.size(), 10u);
  std::uint64_t work = 0;
  for (const StepGraph& g : trace.steps) {
    EXPECT_TRUE(g.same_structure(trace.steps[0]));
    const Metrics m = compute_metrics(g);
    EXPECT_EQ(m.tasks, 9u);
    EXPECT_EQ(m.edges, 12u);
    EXPECT_EQ(m.data, 6u);
    EXPECT_EQ(m.loops, 0u);
    EXPECT_GE(m.span_ns, 1u);
    EXPECT_LE(m.span_ns, m.work_ns);
    EXPECT_EQ(m.per_kind.at("addForce"), 3u);
    work += m.work_ns;
  }
  EXPECT_GT(work, 0u);
}

TEST(Fig2, CentreOfMassFallsFreelyUnderTheInternalSpring) {
  // The spring is internal to the pair, so the centre of mass follows v = g t exactly
  // (symplectic Euler is exact for constant acceleration in velocity).
  auto scene = make_scene("fig2");
  capture::Recorder rec(capture::Mode::kOff);
  for (int s = 0; s < 10; ++s) {
    scene->step(rec);
    rec.end_step();
  }
  Vec3 momentum = Vec3::Zero();
  double mass = 0.0;
  for (const auto& b : scene->bodies()) {
    const auto* p = dynamic_cast<const ParticleBody*>(b.get());
    ASSERT_NE(p, nullptr);
    for (Index i = 0; i < p->columns(); ++i) momentum += p->mass(i) * p->vec(VecId::kV).col(i);
    mass += p->total_mass();
  }
  const Vec3 v = momentum / mass;
  EXPECT_NEAR(v.y(), -9.81 * 10 * 0.001, 1e-12);
  EXPECT_NEAR(v.x(), 0.0, 1e-12);
  // The stretched spring (rest 0.15, length 0.2) pulls the objects together.
  const auto& a = scene->find_body("A")->vec(VecId::kV);
  const auto& b = scene->find_body("B")->vec(VecId::kV);
  EXPECT_LT(a(1, 0), b(1, 0));
}

}  // namespace
}  // namespace tgraph::samples
