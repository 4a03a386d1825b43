// SPDX-License-Identifier: MIT
// A fixed trace's predictions to the nanosecond: `tgraph simulate` (built-in engine, plain and
// --lower; SimGrid when built with it) and `tgraph evaluate` on tests/data/golden/ (falling,
// 3 steps captured once; its metis k = 3 assignment; a hand-written calibration file with
// every model term). The figures are what the code printed before the models moved into
// their own module (issue 50): a change of any of them is a change of the model, not of
// where its code lives.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "../scratch_dir.hpp"
#include "cli_run.hpp"

namespace {

namespace fs = std::filesystem;

const std::string kData = std::string(TGRAPH_TEST_DATA) + "/golden/";
const std::string kFiles = "'" + kData + "falling3.tgt' '" + kData + "falling3_metis_k3.tga' " +
                           "--calibration '" + kData + "calibration.json'";

class PredictionGolden : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = tgraph::test::scratch_dir("tgraph_golden_"); }
  void TearDown() override { fs::remove_all(dir_); }
  nlohmann::json run_json(const std::string& args) {
    const tgraph::test::CliResult r = tgraph::test::run_tgraph(dir_, args);
    EXPECT_EQ(r.code, 0) << args << ": " << r.err;
    return r.code == 0 ? nlohmann::json::parse(r.out) : nlohmann::json();
  }
  fs::path dir_;
};

/// One step of a simulation: makespan, messages and bytes.
struct StepFigures {
  std::int64_t makespan_ns, messages, bytes;
};

void expect_simulation(const nlohmann::json& j, std::int64_t makespan_ns,
                       const std::vector<StepFigures>& steps) {
  ASSERT_TRUE(j.is_object());
  EXPECT_EQ(j.at("makespan_ns").get<std::int64_t>(), makespan_ns);
  ASSERT_EQ(j.at("per_step").size(), steps.size());
  for (std::size_t s = 0; s < steps.size(); ++s) {
    const nlohmann::json& p = j["per_step"][s];
    EXPECT_EQ(p.at("makespan_ns").get<std::int64_t>(), steps[s].makespan_ns) << "step " << s;
    EXPECT_EQ(p.at("messages").get<std::int64_t>(), steps[s].messages) << "step " << s;
    EXPECT_EQ(p.at("bytes").get<std::int64_t>(), steps[s].bytes) << "step " << s;
  }
}

TEST_F(PredictionGolden, BuiltinSimulatorPredictsTheFixedTraceToTheNanosecond) {
  const nlohmann::json j = run_json("simulate " + kFiles + " --json");
  EXPECT_EQ(j.value("engine", ""), "builtin");
  EXPECT_FALSE(j.value("lowered", true));
  EXPECT_EQ(j.value("task_overhead_ns", 0.0), 40.0);
  expect_simulation(j, 11916673,
                    {{4900128, 5, 21000}, {3133164, 0, 0}, {3883381, 1253, 6587177}});
}

TEST_F(PredictionGolden, LoweredSimulationPredictsTheFixedTraceToTheNanosecond) {
  const nlohmann::json j = run_json("simulate " + kFiles + " --lower --json");
  EXPECT_TRUE(j.value("lowered", false));
  // Step 2's cumulative writes across processors go through reducers: two hops, more
  // messages and a longer step; steps 0 and 1 have none that cross.
  expect_simulation(j, 11957833,
                    {{4900128, 5, 21000}, {3133164, 0, 0}, {3924541, 1481, 6588737}});
}

#ifdef TGRAPH_HAVE_SIMGRID
TEST_F(PredictionGolden, SimGridOnATwoByTwoClusterPredictsTheFixedTraceToTheNanosecond) {
  const nlohmann::json j = run_json("simulate " + kFiles + " --engine simgrid --cluster 2x2 --json");
  EXPECT_EQ(j.value("engine", ""), "simgrid");
  expect_simulation(j, 10417434,
                    {{4296450, 5, 21000}, {2543627, 0, 0}, {3577357, 749, 6587177}});
  EXPECT_EQ(j["per_step"][2].value("inter_node_messages", -1), 749);
}
#endif

TEST_F(PredictionGolden, EvaluatePredictsTheFixedTracesMakespanAndSpeedup) {
  const nlohmann::json j = run_json("evaluate " + kFiles + " --json");
  ASSERT_TRUE(j.is_object());
  EXPECT_EQ(j.at("predicted_makespan_ns").get<std::int64_t>(), 11916673);
  EXPECT_EQ(j.at("lower_bound_ns").get<std::int64_t>(), 7019734);
  EXPECT_EQ(j.at("work_ns").get<std::int64_t>(), 14066090);
  EXPECT_EQ(j.at("cut_edges").get<std::int64_t>(), 55);
  EXPECT_EQ(j.at("reducers").get<std::int64_t>(), 196);
  EXPECT_NEAR(j.at("predicted_speedup").get<double>(), 1.3113306037683505, 1e-12);
  EXPECT_NEAR(j.at("predicted_speedup_with_partitioning").get<double>(), 1.056397592283626,
              1e-12);
  const std::vector<std::int64_t> makespans = {4900128, 3133164, 3883381};
  const std::vector<double> speedups = {1.28017757903467, 1.4772750484813435,
                                        1.2167539059391803};
  ASSERT_EQ(j.at("per_step").size(), 3u);
  for (std::size_t s = 0; s < 3; ++s) {
    EXPECT_EQ(j["per_step"][s].at("predicted_makespan_ns").get<std::int64_t>(), makespans[s]);
    EXPECT_NEAR(j["per_step"][s].at("predicted_speedup").get<double>(), speedups[s], 1e-12);
  }
}

}  // namespace
