// SPDX-License-Identifier: MIT
// --verify-accesses live (measure/verify.hpp): the two planted mistakes of the test engine
// (a task writing p declared R; a mat-vec missing its north halo) named under every policy
// and at K = 1, nothing found with the declarations right.
#include "tgraph/measure/verify.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "tgraph/graph/error.hpp"
#include "tgraph/measure/adapter.hpp"
#include "tgraph/replay/executor.hpp"

namespace tgraph::measure {
namespace {

struct Case {
  const char* method;
  std::uint32_t threads;
};

// Verifies the test engine `engine` with `c`; nullopt when the policy is not built here.
std::optional<VerifyResult> verify(const std::string& engine, const Case& c, std::uint32_t steps = 2) {
  const MethodChoice m = choose_method(c.method);
  LiveOptions o;
  o.policy = m.policy;
  o.exec.threads = c.threads;
  o.exec.pin = false;
  o.steps = steps;
  if (m.policy == replay::Policy::kStarpu) {
    try {
      replay::make_executor(m.policy, o.exec);
    } catch (const std::exception&) {
      return std::nullopt;
    }
  }
  std::optional<partition::StepPartitioner> part;
  if (m.policy == replay::Policy::kPartition) part = partition::step_partitioner(m.method);
  return verify_accesses([engine] { return make_live_engine(engine); }, part ? &*part : nullptr, o);
}

class VerifyLive : public ::testing::TestWithParam<Case> {};

TEST_P(VerifyLive, NamesAWriteDeclaredReadWhateverThePolicy) {
  const auto r = verify("tiled-heat:wrong-mode", GetParam());
  if (!r) GTEST_SKIP() << "policy not built";
  ASSERT_EQ(r->findings.size(), 1u);
  EXPECT_EQ(to_string(r->findings[0]), "task direction of tile(1,2) wrote tile(1,2).p, declared R");
  EXPECT_EQ(r->threads, GetParam().threads);
}

TEST_P(VerifyLive, NamesAMissingHaloReadWhateverThePolicy) {
  const auto r = verify("tiled-heat:missing-halo", GetParam());
  if (!r) GTEST_SKIP() << "policy not built";
  ASSERT_EQ(r->findings.size(), 1u);
  EXPECT_EQ(to_string(r->findings[0]), "task matvec of tile(1,1) read tile(0,1).p, declared none");
  EXPECT_EQ(r->findings[0].found, AccessFound::kRead);
}

TEST_P(VerifyLive, FindsNothingWithTheDeclarationsRight) {
  const auto r = verify("tiled-heat", GetParam());
  if (!r) GTEST_SKIP() << "policy not built";
  EXPECT_TRUE(r->findings.empty()) << to_string(r->findings[0]);
  EXPECT_EQ(r->data_checked, 9u * 5 + 7);  // every datum with storage
  EXPECT_GT(r->counts.reruns, 0u);
  EXPECT_EQ(r->counts.reads_unchecked, 0u);
}

INSTANTIATE_TEST_SUITE_P(PoliciesAndThreads, VerifyLive,
                         ::testing::Values(Case{"owner", 1}, Case{"owner", 2}, Case{"metis", 3},
                                           Case{"sticky", 2}, Case{"worksteal", 1},
                                           Case{"worksteal", 2}, Case{"barrier", 1},
                                           Case{"barrier", 2}, Case{"omp-tasks", 2},
                                           Case{"starpu", 2}, Case{"sequential", 1}),
                         [](const auto& p) {
                           std::string m = p.param.method;
                           for (char& ch : m)
                             if (ch == '-') ch = '_';
                           return m + "_" + std::to_string(p.param.threads);
                         });

TEST(Verify, TheJsonListsTheFindings) {
  const auto r = verify("tiled-heat:missing-halo", {"owner", 2});
  const auto j = nlohmann::json::parse(verify_json(*r, "tiled-heat:missing-halo", "owner"));
  ASSERT_EQ(j["access_findings"].size(), 1u);
  EXPECT_EQ(j["access_findings"][0],
            nlohmann::json({{"task", "matvec of tile(1,1)"},
                            {"datum", "tile(0,1).p"},
                            {"found", "read"},
                            {"declared", "none"}}));
  EXPECT_EQ(j["threads"], 2);
  EXPECT_GT(j["cost"].get<double>(), 0.0);
}

}  // namespace
}  // namespace tgraph::measure
