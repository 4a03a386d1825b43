// SPDX-License-Identifier: MIT
// `tgraph-mpi partition --method ptscotch` under mpirun, end to end: the .tga it writes fits
// the trace, reads back and is accepted by `tgraph evaluate`; its cut is the one it reports
// and within 10 % of sequential Scotch's at the same K; bad input exits 2 with one line.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "tgraph/graph/trace_io.hpp"
#include "tgraph/partition/assignment_io.hpp"
#include "tgraph/partition/partition_graph.hpp"
#include "tgraph/partition/strategy.hpp"
#include "../scratch_dir.hpp"

// The cases exist in builds whose tgraph::mpi has PT-Scotch.
#if defined(TGRAPH_HAVE_PTSCOTCH)
namespace {

namespace fs = std::filesystem;
namespace tp = tgraph::partition;

struct Outcome {
  int rc = -1;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class PtScotch : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = tgraph::test::scratch_dir("tgraph_ptscotch_");
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// Runs `cmd` (a shell command line), stdout and stderr captured.
  Outcome run(const std::string& cmd) const {
    const fs::path out = dir_ / "stdout", err = dir_ / "stderr";
    const int status =
        std::system((cmd + " >'" + out.string() + "' 2>'" + err.string() + "'").c_str());
    Outcome r;
    r.rc = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
  }
  /// `mpirun -np N tgraph-mpi ARGS` (quiet: mpirun's own banners off; CI runs as root),
  /// with its session directory in the test's folder (two jobs starting at once collide
  /// on OpenMPI 4's /tmp/ompi.<host>.<uid>).
  Outcome mpi(int np, const std::string& args) const {
    return run(std::string(TGRAPH_MPIEXEC) + " -q --allow-run-as-root --mca orte_tmpdir_base '" +
               dir_.string() + "' " + (np > 2 ? "--oversubscribe " : "") + "-np " +
               std::to_string(np) + " '" + TGRAPH_MPI_BIN + "' " + args);
  }
  /// `tgraph generate --tasks N --pattern P` into the test's folder.
  std::string generate(const std::string& pattern, int tasks, int steps = 1) const {
    const std::string path = (dir_ / (pattern + ".tgt")).string();
    const Outcome r =
        run(std::string("'") + TGRAPH_BIN + "' generate --tasks " + std::to_string(tasks) +
            " --pattern " + pattern + " --steps " + std::to_string(steps) + " -o '" + path + "'");
    EXPECT_EQ(r.rc, 0) << r.err;
    return path;
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  fs::path dir_;
};

/// Checks the .tga at `tga` against `trace` and returns its steps' cuts (library units).
std::vector<std::int64_t> check_assignment(const tgraph::Trace& trace, const std::string& tga,
                                           std::uint32_t k) {
  const tgraph::TraceAssignment a = tp::load_assignment(tga, trace, "trace");
  EXPECT_EQ(a.method, "ptscotch");
  EXPECT_EQ(a.k, k);
  std::vector<std::int64_t> cuts;
  for (std::size_t s = 0; s < a.steps.size(); ++s) {
    const tgraph::Assignment& as = a.steps[s];
    EXPECT_EQ(as.proc.size(), trace.steps[s].tasks.size());
    std::vector<std::uint32_t> used(k, 0);
    for (const tgraph::ProcId p : as.proc) {
      EXPECT_LT(p, k);
      if (p < k) ++used[p];
    }
    for (std::uint32_t p = 0; p < k; ++p) EXPECT_GT(used[p], 0u) << "processor " << p << " empty";
    cuts.push_back(tp::edgecut(tp::library_graph(trace.steps[s]), as.proc));
  }
  return cuts;
}

/// Sequential Scotch's cut (the `scotch` strategy, default options) on `g` at K = `k`.
std::int64_t scotch_cut(const tgraph::StepGraph& g, std::uint32_t k) {
  const tp::Result r = tp::make_strategy("scotch")->partition(g, k, {}, tp::Options{});
  return *r.stats.edgecut;
}

class PtScotchPattern : public PtScotch, public ::testing::WithParamInterface<const char*> {};

TEST_P(PtScotchPattern, WritesAValidAssignmentWithinTenPercentOfScotchsCut) {
  const std::string trace_path = generate(GetParam(), 10000);
  const std::string tga = path("a.tga");
  const Outcome r = mpi(2, "partition '" + trace_path +
                               "' --method ptscotch --nodes 2 --cores 4 -o '" + tga + "' --json");
  ASSERT_EQ(r.rc, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("ranks"), 2);
  EXPECT_EQ(j.at("k"), 8);
  const tgraph::Trace trace = tgraph::read_trace(trace_path);
  const std::vector<std::int64_t> cuts = check_assignment(trace, tga, 8);
  ASSERT_EQ(cuts.size(), 1u);
  EXPECT_EQ(j.at("cut").get<std::int64_t>(), cuts[0]);
  EXPECT_LE(j.at("node_cut").get<std::int64_t>(), cuts[0]);
  EXPECT_LT(j.at("imbalance").get<double>(), 1.10);
  const std::int64_t sequential = scotch_cut(trace.steps[0], 8);
  EXPECT_LE(static_cast<double>(cuts[0]), 1.10 * static_cast<double>(sequential))
      << "ptscotch " << cuts[0] << ", scotch " << sequential;

  const Outcome eval =
      run(std::string("'") + TGRAPH_BIN + "' evaluate '" + trace_path + "' '" + tga + "' --json");
  ASSERT_EQ(eval.rc, 0) << eval.err;
  EXPECT_EQ(nlohmann::json::parse(eval.out).at("k"), 8);
}

INSTANTIATE_TEST_SUITE_P(Generated, PtScotchPattern,
                         ::testing::Values("stencil", "random", "tree", "domain"));

TEST_F(PtScotch, PlacesMoreNodesThanRanksOnThreeOversubscribedRanks) {
  const std::string trace_path = generate("random", 10000);
  const std::string tga = path("a.tga");
  const Outcome r =
      mpi(3, "partition '" + trace_path + "' --nodes 5 --cores 3 -o '" + tga + "' --json");
  ASSERT_EQ(r.rc, 0) << r.err;
  const tgraph::Trace trace = tgraph::read_trace(trace_path);
  const std::vector<std::int64_t> cuts = check_assignment(trace, tga, 15);
  EXPECT_EQ(nlohmann::json::parse(r.out).at("cut").get<std::int64_t>(), cuts.at(0));
  EXPECT_LE(static_cast<double>(cuts[0]),
            1.10 * static_cast<double>(scotch_cut(trace.steps[0], 15)));
}

TEST_F(PtScotch, PartitionsEveryStepOrTheOneNamed) {
  const std::string trace_path = generate("stencil", 2000, 3);
  const tgraph::Trace trace = tgraph::read_trace(trace_path);
  const Outcome all =
      mpi(2, "partition '" + trace_path + "' --nodes 2 --cores 2 -o '" + path("all.tga") + "'");
  ASSERT_EQ(all.rc, 0) << all.err;
  EXPECT_EQ(check_assignment(trace, path("all.tga"), 4).size(), 3u);
  const Outcome one = mpi(2, "partition '" + trace_path + "' --nodes 2 --cores 2 --step 2 -o '" +
                                 path("one.tga") + "' --json");
  ASSERT_EQ(one.rc, 0) << one.err;
  const tgraph::TraceAssignment a = tp::read_assignment(path("one.tga"));
  ASSERT_EQ(a.steps.size(), 1u);
  EXPECT_EQ(a.steps[0].proc.size(), trace.steps[2].tasks.size());
  EXPECT_EQ(nlohmann::json::parse(one.out).at("per_step").at(0).at("step"), 2);
}

/// Non-empty lines of `text`.
std::size_t lines(const std::string& text) {
  std::istringstream in(text);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);) n += line.empty() ? 0 : 1;
  return n;
}

TEST_F(PtScotch, RejectsAMissingTraceWithOneLineAndExit2) {
  const Outcome r =
      mpi(2, "partition '" + path("missing.tgt") + "' --nodes 2 -o '" + path("a.tga") + "'");
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("missing.tgt"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("a.tga")));
}

TEST_F(PtScotch, RejectsZeroNodesWithOneLineAndExit2) {
  const std::string trace_path = generate("stencil", 1000);
  const Outcome r = mpi(2, "partition '" + trace_path + "' --nodes 0 -o '" + path("a.tga") + "'");
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("--nodes"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("a.tga")));
}

}  // namespace
#endif  // TGRAPH_HAVE_PTSCOTCH
