// SPDX-License-Identifier: MIT
// What a method name means to a measurement, and the names of a live run's check.
#include "tgraph/measure/method.hpp"

#include <gtest/gtest.h>

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
  // No command-line alias here: "partition" is not a strategy's name (apps map it to owner).
  EXPECT_EQ(choose_method("partition").method, "partition");
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
