// SPDX-License-Identifier: MIT
// The METIS objective equals the cut gpmetis (default options) reports on the same graph file.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "test_graphs.hpp"
#include "tgraph/partition/partition_graph.hpp"
#include "tgraph/partition/stg.hpp"
#include "tgraph/partition/strategy.hpp"

namespace tgraph::partition {
namespace {

// The file `tgraph export --format metis` writes: header "n m 011", 1-based neighbours.
std::string metis_file(const UndirectedGraph& u) {
  std::ostringstream s;
  s << u.vertices() << ' ' << u.edges() << " 011\n";
  for (std::uint32_t v = 0; v < u.vertices(); ++v) {
    s << u.vwgt[v];
    for (auto i = u.xadj[v]; i < u.xadj[v + 1]; ++i) s << ' ' << u.adjncy[i] + 1 << ' ' << u.adjwgt[i];
    s << '\n';
  }
  return s.str();
}

// Runs gpmetis and returns the "Edgecut: N" it prints, or -1.
long long gpmetis_cut(const std::string& file, std::uint32_t k) {
  const std::string cmd = std::string(TGRAPH_GPMETIS) + " " + file + " " + std::to_string(k) + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return -1;
  std::string out;
  char buf[512];
  while (std::fgets(buf, sizeof(buf), p) != nullptr) out += buf;
  pclose(p);
  const std::size_t at = out.find("Edgecut:");
  if (at == std::string::npos) return -1;
  return std::atoll(out.c_str() + at + 8);
}

TEST(Metis, ObjectiveMatchesGpmetisOnTheExportedGraph) {
  if (std::string(TGRAPH_GPMETIS).empty() || !std::filesystem::exists(TGRAPH_GPMETIS))
    GTEST_SKIP() << "gpmetis not installed";
  const auto dir = std::filesystem::temp_directory_path() / "tgraph_gpmetis_test";
  std::filesystem::create_directories(dir);
  std::vector<StepGraph> graphs = {
      read_stg(std::string(TGRAPH_SHARED_DIR) + "/data/stg/100/rand0001.stg").trace.steps[0],
      testing::random_graph(77, 400, 60, true)};
  int compared = 0;
  for (std::size_t i = 0; i < graphs.size(); ++i) {
    const std::string file = (dir / (testing::name("g", i) + ".metis")).string();
    std::ofstream(file) << metis_file(library_graph(graphs[i]));
    for (std::uint32_t k : {2u, 4u, 8u}) {
      const Result r = make_strategy("metis")->partition(graphs[i], k, {}, {});
      const long long ref = gpmetis_cut(file, k);
      ASSERT_GE(ref, 0) << "gpmetis failed on " << file;
      ASSERT_TRUE(r.stats.edgecut.has_value());
      EXPECT_NEAR(static_cast<double>(*r.stats.edgecut), static_cast<double>(ref), 0.05 * static_cast<double>(ref) + 1)
          << file << " k=" << k;
      ++compared;
    }
  }
  std::filesystem::remove_all(dir);
  EXPECT_EQ(compared, 6);
}

}  // namespace
}  // namespace tgraph::partition
