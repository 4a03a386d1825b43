// SPDX-License-Identifier: MIT
// `tgraph explain` on a replay's timeline: the table, --json in the shape checks read, --step,
// and one line with exit 2 for what it cannot explain.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "../../apps/cli_run.hpp"
#include "../../scratch_dir.hpp"

namespace tgraph {
namespace {

class ExplainCli : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::scratch_dir("explain_cli"); }
  test::CliResult run(const std::string& args) { return test::run_tgraph(dir_, args); }
  std::filesystem::path dir_;
};

TEST_F(ExplainCli, ExplainsAReplayTimeline) {
  ASSERT_EQ(run("capture --scene fig2 --steps 3 -o f.tgt").code, 0);
  const auto r = run("replay f.tgt --threads 2 --repeat 1 --timeline r.json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto text = run("explain r.json");
  ASSERT_EQ(text.code, 0) << text.err;
  EXPECT_NE(text.out.find("handoff"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("what if"), std::string::npos) << text.out;
  const auto js = run("explain r.json --json");
  ASSERT_EQ(js.code, 0) << js.err;
  const nlohmann::json j = nlohmann::json::parse(js.out);
  ASSERT_EQ(j["steps"].size(), 3u);
  for (const auto& s : j["steps"]) {
    const auto& a = s["attribution"];
    std::int64_t sum = 0;
    for (const auto& [name, ns] : a["causes"].items()) sum += ns.get<std::int64_t>();
    EXPECT_EQ(sum, a["lost_ns"].get<std::int64_t>());
    EXPECT_LE(std::abs(a["causes"]["residual"].get<std::int64_t>()),
              s["threads"].get<std::int64_t>() * s["makespan_ns"].get<std::int64_t>() / 20);
    ASSERT_FALSE(s["critical_path"].empty());
    for (const auto& l : s["critical_path"])
      EXPECT_TRUE(l["link"] == "body" || l["link"] == "wait" || l["link"] == "handoff" ||
                  l["link"] == "serial");
    ASSERT_FALSE(s["what_if"].empty());
    for (std::size_t k = 1; k < s["what_if"].size(); ++k)
      EXPECT_GE(s["what_if"][k - 1]["gain"].get<std::int64_t>(),
                s["what_if"][k]["gain"].get<std::int64_t>());
  }
  const auto one = run("explain r.json --step 1 --json");
  ASSERT_EQ(one.code, 0) << one.err;
  EXPECT_EQ(nlohmann::json::parse(one.out)["steps"].size(), 1u);
}

// `run --json`'s attribution (the observed pass), per run and per step: the causes add up
// to the lost time and the residual is within 5 % of it (and so of K x makespan); `run
// --timeline` names its file in the JSON, which explain then reads.
TEST_F(ExplainCli, RunJsonCarriesAnAttributionThatAddsUp) {
  for (const char* method : {"owner", "worksteal", "barrier"}) {
    const auto r = run(std::string("run --scene fig2 --steps 3 --threads 2 --method ") + method +
                       " --timeline r.tl --json");
    ASSERT_EQ(r.code, 0) << method << ": " << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["timeline"], "r.tl");
    ASSERT_EQ(j["per_step"].size(), 3u);
    std::int64_t lost = 0;
    for (const auto& s : j["per_step"]) {
      const auto& a = s["attribution"];
      std::int64_t sum = 0;
      for (const auto& [name, ns] : a["causes"].items()) sum += ns.get<std::int64_t>();
      EXPECT_EQ(sum, a["lost_ns"].get<std::int64_t>()) << method;
      EXPECT_LE(std::abs(a["causes"]["residual"].get<std::int64_t>()),
                std::abs(a["lost_ns"].get<std::int64_t>()) / 20)
          << method;
      lost += a["lost_ns"].get<std::int64_t>();
    }
    EXPECT_EQ(j["attribution"]["lost_ns"].get<std::int64_t>(), lost) << method;
    const auto x = run("explain r.tl --json");
    ASSERT_EQ(x.code, 0) << x.err;
    EXPECT_EQ(nlohmann::json::parse(x.out)["attribution"], j["attribution"]) << method;
  }
}

TEST_F(ExplainCli, RefusesWhatItCannotExplainWithOneLine) {
  ASSERT_EQ(run("capture --scene fig2 --steps 1 -o f.tgt").code, 0);
  for (const char* args : {"explain f.tgt", "explain missing.json", "explain r.json --step 7"}) {
    if (std::string(args).find("r.json") != std::string::npos)
      ASSERT_EQ(run("replay f.tgt --threads 2 --repeat 1 --timeline r.json").code, 0);
    const auto r = run(args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
  }
}

}  // namespace
}  // namespace tgraph
