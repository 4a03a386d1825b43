// SPDX-License-Identifier: MIT
// What a method name means to a measurement, and the names of a live run's check.
#include "tgraph/measure/method.hpp"

#include <gtest/gtest.h>
#include <string>

#include "tgraph/graph/error.hpp"
#include "tgraph/measure/live.hpp"

namespace tgraph::measure {
namespace {

using replay::Policy;

TEST(Method, BaselinePolicyNamesGiveThatPolicyAndOtherNamesAStrategy) {
  EXPECT_EQ(choose_method("worksteal").policy, Policy::kWorksteal);
  EXPECT_EQ(choose_method("omp-tasks").policy, Policy::kOmpTasks);
  EXPECT_EQ(choose_method("sequential").policy, Policy::kSequential);
  const MethodChoice m = choose_method("metis");
  EXPECT_EQ(m.policy, Policy::kPartition);
  EXPECT_EQ(m.method, "metis");
}

TEST(Method, AnUnknownNameListsTheStrategiesAndTheBaselinePolicies) {
  // Issue 52 saw `unknown method 'metsi' (known: list, metis, ...)` without the baselines.
  try {
    choose_method("metsi");
    FAIL() << "metsi was accepted";
  } catch (const UsageError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("unknown method 'metsi' (strategies: ", 0), 0u) << m;
    for (const char* name : {"owner", "metis", "sticky", "worksteal", "barrier", "omp-tasks",
                             "starpu", "sequential"})
      EXPECT_NE(m.find(name), std::string::npos) << name << " missing from: " << m;
  }
  // No command-line alias here: "partition" is a policy, not a method (apps map it to owner).
  EXPECT_THROW(choose_method("partition"), UsageError);
}

TEST(Method, ReportsNameTheStrategyUnderThePartitionPolicyElseThePolicy) {
  EXPECT_EQ(method_name({Policy::kPartition, "sticky"}), "sticky");
  EXPECT_EQ(method_name({Policy::kBarrier, "ignored"}), "barrier");
}

TEST(Check, NamesAreThoseOfTheJson) {
  EXPECT_EQ(to_string(Check::kIdentical), "identical");
  EXPECT_EQ(to_string(Check::kDiffers), "differs");
}

}  // namespace
}  // namespace tgraph::measure
