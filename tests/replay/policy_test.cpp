// SPDX-License-Identifier: MIT
#include "tgraph/replay/policy.hpp"

#include <gtest/gtest.h>

namespace tgraph::replay {

TEST(Policy, NamesRoundTrip) {
  for (Policy p : {Policy::kSequential, Policy::kPartition, Policy::kWorksteal, Policy::kBarrier,
                   Policy::kStarpu, Policy::kOmpTasks})
    EXPECT_EQ(parse_policy(to_string(p)), p);
  EXPECT_FALSE(parse_policy("magic").has_value());
  EXPECT_EQ(parse_policy("omp-tasks"), Policy::kOmpTasks);
  EXPECT_EQ(to_string(CwMode::kReduce), "reduce");
}

}  // namespace tgraph::replay
