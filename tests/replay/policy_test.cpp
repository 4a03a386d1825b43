// SPDX-License-Identifier: MIT
#include "tgraph/replay/policy.hpp"

#include <gtest/gtest.h>

#include <string_view>
#include <vector>

#include "tgraph/replay/executor.hpp"

namespace tgraph::replay {

TEST(Policy, NamesRoundTrip) {
  for (Policy p : {Policy::kSequential, Policy::kPartition, Policy::kWorksteal, Policy::kBarrier,
                   Policy::kStarpu, Policy::kOmpTasks})
    EXPECT_EQ(parse_policy(to_string(p)), p);
  EXPECT_FALSE(parse_policy("magic").has_value());
  EXPECT_EQ(parse_policy("omp-tasks"), Policy::kOmpTasks);
  EXPECT_EQ(to_string(CwMode::kReduce), "reduce");
}

TEST(Policy, TheRegistryListsEveryPolicyOnceWithItsHelpAndItsFactory) {
  const std::vector<PolicyInfo> all = policies();
  std::vector<std::string_view> names;
  for (const PolicyInfo& p : all) {
    names.push_back(p.name);
    EXPECT_EQ(to_string(p.policy), p.name);
    EXPECT_FALSE(p.help.empty()) << p.name;
    EXPECT_EQ(p.built, p.missing.empty()) << p.name;
    if (!p.built) continue;
    ExecOptions o;
    o.threads = 2;
    EXPECT_NE(make_executor(p.policy, o), nullptr) << p.name;
  }
  EXPECT_EQ(names, (std::vector<std::string_view>{"partition", "worksteal", "barrier", "starpu",
                                                  "omp-tasks", "sequential"}));
  // The command line's words come from here.
  EXPECT_EQ(policy_list("or"), "partition, worksteal, barrier, starpu, omp-tasks or sequential");
  EXPECT_EQ(policy_list("", true), "worksteal, barrier, starpu, omp-tasks");
}

}  // namespace tgraph::replay
