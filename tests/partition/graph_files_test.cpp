// SPDX-License-Identifier: MIT
// The shipped graph writers (what `tgraph export --format metis|scotch` writes) read back by
// gpmetis and scotch_gpart as the graph the partitioners see: the cut each tool reports
// equals the cut of its partition computed on library_graph, and METIS's objective in
// tgraph equals gpmetis's cut.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "test_graphs.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/graph/step_json.hpp"
#include "tgraph/partition/export.hpp"
#include "tgraph/partition/partition_graph.hpp"
#include "tgraph/graph/stg.hpp"
#include "tgraph/partition/strategy.hpp"

namespace tgraph::partition {
namespace {

bool installed(const char* path) {
  return std::string(path).size() > 0 && std::filesystem::exists(path);
}

// Runs `cmd` and returns what it printed (stdout and stderr).
std::string output_of(const std::string& cmd) {
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  if (p == nullptr) return {};
  std::string out;
  char buf[512];
  while (std::fgets(buf, sizeof(buf), p) != nullptr) out += buf;
  pclose(p);
  return out;
}

// The integer after `label` in `text` (digits only), or -1.
long long number_after(const std::string& text, const std::string& label) {
  const std::size_t at = text.find(label);
  if (at == std::string::npos) return -1;
  return std::atoll(text.c_str() + at + label.size());
}

// The graphs checked: an STG graph, a random graph with a loop, and one whose weights
// exceed 2^30 in total (scaled down by library_graph).
std::vector<StepGraph> graphs() {
  StepGraph big = testing::random_graph(91, 300, 40, true);
  for (Task& t : big.tasks) t.cost_ns *= 50'000'000;
  return {read_stg(std::string(TGRAPH_TEST_DATA) + "/stg/100/rand0001.stg").trace.steps[0],
          testing::random_graph(77, 400, 60, true), big};
}

class GraphFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        std::filesystem::temp_directory_path() / ("tgraph_graph_files_" + std::to_string(getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

TEST_F(GraphFiles, GpmetisReadsTheShippedMetisWriterAsTheGraphMetisSees) {
  if (!installed(TGRAPH_GPMETIS)) GTEST_SKIP() << "gpmetis not installed";
  int compared = 0;
  const std::vector<StepGraph> gs = graphs();
  for (std::size_t i = 0; i < gs.size(); ++i) {
    const UndirectedGraph u = library_graph(gs[i]);
    const std::string file =
        (dir_ / (testing::name("g", static_cast<std::int64_t>(i)) + ".metis")).string();
    write_file_atomic(file, metis_graph_file(gs[i]));
    for (std::uint32_t k : {2u, 4u, 8u}) {
      const std::string out =
          output_of(std::string(TGRAPH_GPMETIS) + " " + file + " " + std::to_string(k));
      const long long cut = number_after(out, "Edgecut:");
      ASSERT_GE(cut, 0) << "gpmetis failed on " << file << ":\n" << out;
      // gpmetis's partition, evaluated on our graph, has the cut gpmetis reports.
      std::ifstream in(file + ".part." + std::to_string(k));
      std::vector<std::uint32_t> part;
      for (std::uint32_t p; in >> p;) part.push_back(p);
      ASSERT_EQ(part.size(), u.vertices());
      EXPECT_EQ(edgecut(u, part), cut) << file << " k=" << k;
      // The library call in tgraph is the one gpmetis makes: same objective.
      const Result r = make_strategy("metis")->partition(gs[i], k, {}, {});
      ASSERT_TRUE(r.stats.edgecut.has_value());
      EXPECT_EQ(*r.stats.edgecut, cut) << file << " k=" << k;
      ++compared;
    }
  }
  EXPECT_EQ(compared, 9);
}

TEST_F(GraphFiles, ScotchGpartReadsTheShippedScotchWriterAsTheGraphScotchSees) {
  if (!installed(TGRAPH_SCOTCH_GPART)) GTEST_SKIP() << "scotch_gpart not installed";
  int compared = 0;
  const std::vector<StepGraph> gs = graphs();
  for (std::size_t i = 0; i < gs.size(); ++i) {
    const UndirectedGraph u = library_graph(gs[i]);
    const std::string file =
        (dir_ / (testing::name("g", static_cast<std::int64_t>(i)) + ".grf")).string();
    const std::string map = file + ".map";
    write_file_atomic(file, scotch_graph_file(gs[i]));
    for (std::uint32_t k : {2u, 4u, 8u}) {
      // -vm prints the mapping's statistics; CommCutSz's count is the cut in edge loads.
      const std::string out =
          output_of("SCOTCH_PTHREAD_NUMBER=1 " + std::string(TGRAPH_SCOTCH_GPART) + " -vm " +
                    std::to_string(k) + " " + file + " " + map);
      const std::size_t at = out.find("CommCutSz=");
      ASSERT_NE(at, std::string::npos) << "scotch_gpart failed on " << file << ":\n" << out;
      const long long cut = number_after(out.substr(at), "(");
      ASSERT_GE(cut, 0) << out;
      std::ifstream in(map);
      std::size_t n = 0;
      in >> n;
      ASSERT_EQ(n, u.vertices());
      std::vector<std::uint32_t> part(n, k);
      for (std::size_t j = 0; j < n; ++j) {
        std::size_t v = 0;
        std::uint32_t p = 0;
        ASSERT_TRUE(in >> v >> p);
        ASSERT_LT(v, n);
        ASSERT_LT(p, k);
        part[v] = p;
      }
      EXPECT_EQ(edgecut(u, part), cut) << file << " k=" << k;
      ++compared;
    }
  }
  EXPECT_EQ(compared, 9);
}

TEST_F(GraphFiles, WriteTheDocumentedLayout) {
  testing::Builder b;
  const DatumId x = b.datum("x", 16), y = b.datum("y", 0);
  b.task({{x, testing::M::W}}, 5);                      // 0
  b.task({{x, testing::M::R}, {y, testing::M::W}}, 7);  // 1
  b.task({{x, testing::M::R}, {y, testing::M::R}}, 0);  // 2
  const StepGraph g = b.done();
  // Edges 0-1 (x: 16), 0-2 (x: 16), 1-2 (y: max(1, 0) = 1); task 2's weight is at least 1.
  EXPECT_EQ(metis_graph_file(g), "3 3 011\n5 2 16 3 16\n7 1 16 3 1\n1 1 16 2 1\n");
  EXPECT_EQ(scotch_graph_file(g), "0\n3 6\n0 011\n5 2 16 1 16 2\n7 2 16 0 1 2\n1 2 16 0 1 1\n");
}

TEST(GraphFile, WritesTheNamedStepInTheChosenFormat) {
  testing::Builder b;
  const DatumId x = b.datum("x", 16);
  b.task({{x, testing::M::W}}, 5);
  b.task({{x, testing::M::R}}, 7);
  Trace trace;
  trace.steps = {testing::two_halves(2), b.done()};
  const StepGraph& g = trace.steps[1];
  EXPECT_EQ(graph_file(trace, 1, "t.tgt", GraphFileFormat::kMetis), "2 1 011\n5 2 16\n7 1 16\n");
  EXPECT_EQ(graph_file(trace, 1, "t.tgt", GraphFileFormat::kScotch),
            "0\n2 2\n0 011\n5 1 16 1\n7 1 16 0\n");
  EXPECT_EQ(graph_file(trace, 1, "t.tgt", GraphFileFormat::kJson), step_graph_json(g, 1));
  EXPECT_NE(graph_file(trace, 0, "t.tgt", GraphFileFormat::kMetis),
            graph_file(trace, 1, "t.tgt", GraphFileFormat::kMetis));
  try {
    graph_file(trace, 2, "t.tgt", GraphFileFormat::kJson);
    FAIL() << "no error";
  } catch (const UsageError& e) {
    EXPECT_STREQ(e.what(), "step: trace t.tgt has 2 steps, no step 2");
  }
  for (GraphFileFormat f :
       {GraphFileFormat::kJson, GraphFileFormat::kMetis, GraphFileFormat::kScotch})
    EXPECT_EQ(parse_graph_file_format(to_string(f)), f);
  EXPECT_THROW(parse_graph_file_format("dot"), UsageError);
}

}  // namespace
}  // namespace tgraph::partition
