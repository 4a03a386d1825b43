// SPDX-License-Identifier: MIT
// `tgraph-mpi replay` under mpirun -np 1, 2, 4 (--oversubscribe): the final state is the
// sequential replay's and what was sent per rank pair is what the schedule predicted.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>

#include "replay/random_graph.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/mpi/replay.hpp"
#include "tgraph/partition/assignment_io.hpp"
#include "../scratch_dir.hpp"

namespace tgraph::mpi {
namespace {

namespace fs = std::filesystem;

struct Outcome {
  int status = -1;
  std::string out, err;
};

fs::path scratch() { return tgraph::test::scratch_dir("tgraph_mpi_test_"); }

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

Outcome run(const std::string& command, const fs::path& dir) {
  Outcome r;
  const fs::path out = dir / "out.txt", err = dir / "err.txt";
  const int rc = std::system((command + " > " + out.string() + " 2> " + err.string()).c_str());
  r.status = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

// mpirun with its session directory under `dir`: OpenMPI 4 creates /tmp/ompi.<host>.<uid>
// with mkdir and fails ("File exists") when two jobs start at once (ctest -j).
std::string mpirun(int np, const fs::path& dir) {
  return std::string(TGRAPH_MPIEXEC) + " --mca orte_tmpdir_base " + dir.string() + " -np " +
         std::to_string(np) + " --oversubscribe " + TGRAPH_MPI_BIN;
}

nlohmann::json replay_json(const std::string& args, int np, const fs::path& dir) {
  const Outcome r = run(mpirun(np, dir) + " replay " + args + " --check --json --watchdog 60", dir);
  EXPECT_EQ(r.status, 0) << r.err;
  return nlohmann::json::parse(r.out);
}

// `tgraph capture --scene S --steps N` into dir; an empty path (and a failure) if it failed.
fs::path capture(const std::string& scene, int steps, const fs::path& dir) {
  const fs::path trace = dir / (scene + ".tgt");
  const Outcome cap = run(std::string(TGRAPH_BIN) + " capture --scene " + scene + " --steps " +
                              std::to_string(steps) + " -o " + trace.string(),
                          dir);
  EXPECT_EQ(cap.status, 0) << cap.err;
  return cap.status == 0 ? trace : fs::path();
}

void expect_exact(const nlohmann::json& j, int np) {
  EXPECT_EQ(j["check"], "identical");
  EXPECT_EQ(j["bytes_match"], true);
  EXPECT_EQ(j["messages"], j["predicted_messages"]);
  EXPECT_EQ(j["bytes"], j["predicted_bytes"]);
  for (const auto& p : j["per_pair"]) {
    EXPECT_EQ(p["messages"], p["predicted_messages"]);
    EXPECT_EQ(p["bytes"], p["predicted_bytes"]);
    EXPECT_EQ(p["decisions"], p["predicted_decisions"]);
  }
  if (np == 1) {
    EXPECT_EQ(j["messages"], 0);
  } else {
    EXPECT_GT(j["messages"].get<std::uint64_t>(), 0u);
  }
  EXPECT_GT(j["wall_ns"].get<std::int64_t>(), 0);
  EXPECT_GT(j["speedup"].get<double>(), 0.0);
}

class SceneOverRanks : public ::testing::TestWithParam<std::tuple<std::string, int>> {};

TEST_P(SceneOverRanks, IsIdenticalToTheSequentialReplayAndSendsWhatWasPredicted) {
  const auto& [scene, np] = GetParam();
  const fs::path dir = scratch();
  const fs::path trace = capture(scene, 3, dir);
  ASSERT_FALSE(trace.empty());
  const nlohmann::json j = replay_json(trace.string() + " --threads-per-rank 1", np, dir);
  expect_exact(j, np);
  EXPECT_EQ(j["per_step"].size(), 3u);
  if (np > 1) {
    EXPECT_GT(j["decision_messages"].get<std::uint64_t>(), 0u);  // CG loops
  }
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Scenes, SceneOverRanks,
                         ::testing::Combine(::testing::Values("bars64", "cloth128", "falling"),
                                            ::testing::Values(1, 2, 4)),
                         [](const auto& p) {
                           return std::get<0>(p.param) + "_np" +
                                  std::to_string(std::get<1>(p.param));
                         });

// 100 random steps with CW groups and loops (tests/replay/random_graph.hpp), each on a new
// random assignment (data move between ranks at every step), written as a trace.
void write_random(const fs::path& trace, const fs::path& tga, std::uint32_t k,
                  std::uint32_t steps = 100) {
  Trace t;
  TraceAssignment a;
  a.method = "random";
  a.k = k;
  for (std::uint32_t s = 0; s < steps; ++s) {
    StepGraph g = replay::test::random_graph(1000 + s);
    for (DatumId d = 0; d < g.data.size(); ++d) g.data[d].bytes = 8 + 40 * (d % 5);  // stable
    a.steps.push_back(replay::test::random_assignment(g, k, 7 * s + k));
    a.partition_ms.push_back(0);
    t.steps.push_back(std::move(g));
  }
  t.header.scene = "random";
  write_trace(trace.string(), t);
  partition::write_assignment(tga.string(), a, t);
}

class RandomOverRanks : public ::testing::TestWithParam<std::tuple<int, int>> {};

TEST_P(RandomOverRanks, HundredRandomGraphsAreIdenticalAndAsPredicted) {
  const auto& [np, threads] = GetParam();
  const fs::path dir = scratch();
  const auto k = static_cast<std::uint32_t>(np * threads);
  write_random(dir / "random.tgt", dir / "random.tga", k);
  const nlohmann::json j =
      replay_json((dir / "random.tgt").string() + " " + (dir / "random.tga").string() +
                      " --threads-per-rank " + std::to_string(threads),
                  np, dir);
  expect_exact(j, np);
  EXPECT_EQ(j["per_step"].size(), 100u);
  if (np > 1) {
    EXPECT_GT(j["migrated_bytes"].get<std::uint64_t>(), 0u);
    EXPECT_GT(j["decision_messages"].get<std::uint64_t>(), 0u);
  }
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Layouts, RandomOverRanks,
                         ::testing::Values(std::make_tuple(1, 2), std::make_tuple(2, 1),
                                           std::make_tuple(2, 2), std::make_tuple(4, 1)),
                         [](const auto& p) {
                           return "np" + std::to_string(std::get<0>(p.param)) + "_threads" +
                                  std::to_string(std::get<1>(p.param));
                         });

TEST(MpiReplay, WatchdogNamesTheStuckRankAndWhatItWaitsFor) {
  const fs::path dir = scratch();
  write_random(dir / "random.tgt", dir / "random.tga", 2);
  // Message 0 of step 0 is never sent: its receiver waits until the watchdog fires.
  const Outcome r = run(mpirun(2, dir) + " replay " + (dir / "random.tgt").string() + " " +
                            (dir / "random.tga").string() +
                            " --threads-per-rank 1 --watchdog 1 --test-drop-message 0",
                        dir);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("watchdog: rank "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("waits for datum "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(" from rank "), std::string::npos) << r.err;
  fs::remove_all(dir);
}

// --host-work: rank 0 runs each step's host work before any task, every rank waiting at a
// barrier; the run stays bit-identical and sends exactly what was predicted.
TEST(MpiReplay, HostWorkKeepsTheRunIdenticalAndAsPredicted) {
  const fs::path dir = scratch();
  const fs::path trace = capture("falling", 2, dir);
  ASSERT_FALSE(trace.empty());
  const nlohmann::json j =
      replay_json(trace.string() + " --threads-per-rank 1 --host-work", 2, dir);
  expect_exact(j, 2);
  EXPECT_EQ(j["per_step"].size(), 2u);
  fs::remove_all(dir);
}

// --policy starpu-mpi: the same lowered graph, bodies and ownership through StarPU-MPI. Its
// transfers are StarPU-MPI's own (bytes per destination from STARPU_COMM_STATS, no message
// counts); the final state must be the sequential replay's.
class StarpuMpiOverRanks : public ::testing::TestWithParam<std::tuple<int, int>> {};

TEST_P(StarpuMpiOverRanks, RandomGraphsWithMovingOwnersAreIdentical) {
  if (!have_starpu_mpi()) GTEST_SKIP() << "built without StarPU-MPI";
  const auto& [np, threads] = GetParam();
  const fs::path dir = scratch();
  const auto k = static_cast<std::uint32_t>(np * threads);
  write_random(dir / "random.tgt", dir / "random.tga", k, 20);
  const nlohmann::json j =
      replay_json((dir / "random.tgt").string() + " " + (dir / "random.tga").string() +
                      " --policy starpu-mpi --threads-per-rank " + std::to_string(threads),
                  np, dir);
  EXPECT_EQ(j["check"], "identical");
  EXPECT_EQ(j["policy"], "starpu-mpi");
  EXPECT_TRUE(j["messages"].is_null());  // StarPU-MPI counts bytes only
  EXPECT_TRUE(j["bytes_match"].is_null());
  EXPECT_EQ(j["per_step"].size(), 20u);
  EXPECT_GT(j["speedup"].get<double>(), 0.0);
  if (np == 1) {
    EXPECT_EQ(j["bytes"], 0);
  } else {
    // A new random assignment every step: data change owners (starpu_mpi_data_migrate).
    EXPECT_GT(j["bytes"].get<std::uint64_t>(), 0u);
    EXPECT_GT(j["migrated_bytes"].get<std::uint64_t>(), 0u);
    EXPECT_GT(j["predicted_bytes"].get<std::uint64_t>(), 0u);
  }
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Layouts, StarpuMpiOverRanks,
                         ::testing::Values(std::make_tuple(1, 2), std::make_tuple(2, 1)),
                         [](const auto& p) {
                           return "np" + std::to_string(std::get<0>(p.param)) + "_threads" +
                                  std::to_string(std::get<1>(p.param));
                         });

TEST(StarpuMpi, FallingIsIdenticalToTheSequentialReplay) {
  if (!have_starpu_mpi()) GTEST_SKIP() << "built without StarPU-MPI";
  const fs::path dir = scratch();
  const fs::path trace = capture("falling", 2, dir);
  ASSERT_FALSE(trace.empty());
  const nlohmann::json j =
      replay_json(trace.string() + " --policy starpu-mpi --threads-per-rank 1", 2, dir);
  EXPECT_EQ(j["check"], "identical");
  EXPECT_EQ(j["per_step"].size(), 2u);
  // Both ranks send: contacts read the other rank's objects, CG scalars cross.
  ASSERT_EQ(j["per_pair"].size(), 2u);
  for (const auto& p : j["per_pair"]) EXPECT_GT(p["bytes"].get<std::uint64_t>(), 0u);
  fs::remove_all(dir);
}

TEST(StarpuMpi, RefusedWithOneLineWhereNotBuilt) {
  if (have_starpu_mpi()) GTEST_SKIP() << "built with StarPU-MPI";
  const fs::path dir = scratch();
  write_random(dir / "random.tgt", dir / "random.tga", 1, 1);
  const Outcome r = run(mpirun(1, dir) + " replay " + (dir / "random.tgt").string() + " " +
                            (dir / "random.tga").string() +
                            " --policy starpu-mpi --threads-per-rank 1",
                        dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--policy: starpu-mpi: "), std::string::npos) << r.err;
  fs::remove_all(dir);
}

TEST(MpiReplay, RejectsAnAssignmentForAnotherProcessorCount) {
  const fs::path dir = scratch();
  write_random(dir / "random.tgt", dir / "random.tga", 3);
  const Outcome r = run(mpirun(2, dir) + " replay " + (dir / "random.tgt").string() + " " +
                            (dir / "random.tga").string() + " --threads-per-rank 1",
                        dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("random.tga"), std::string::npos) << r.err;
  const Outcome missing =
      run(mpirun(1, dir) + " replay " + (dir / "none.tgt").string() + " --threads-per-rank 1", dir);
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.err.find("none.tgt"), std::string::npos) << missing.err;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace tgraph::mpi
