// SPDX-License-Identifier: MIT
// PassTimes: the medians over passes that every measurement reports.
#include "tgraph/measure/passes.hpp"

#include <gtest/gtest.h>

namespace tgraph::measure {
namespace {

TEST(PassTimes, ReportsTheMedianOfEachStepAndOfThePassTotals) {
  PassTimes t(2);
  const std::int64_t passes[3][2] = {{10, 100}, {30, 50}, {20, 400}};
  for (const auto& p : passes) {
    t.add(0, p[0]);
    t.add(1, p[1]);
    t.end_pass();
  }
  EXPECT_EQ(t.step_median(0), 20);
  EXPECT_EQ(t.step_median(1), 100);
  EXPECT_EQ(t.pass_totals(), (std::vector<std::int64_t>{110, 80, 420}));
  // The median pass is not the sum of the step medians.
  EXPECT_EQ(t.median_total(), 110);
}

TEST(PassTimes, EvenPassCountsTakeTheMeanOfTheMiddleTwoAndNoPassGivesZero) {
  PassTimes t(1);
  EXPECT_EQ(t.step_median(0), 0);
  EXPECT_EQ(t.median_total(), 0);
  for (std::int64_t v : {4, 8, 1, 100}) {
    t.add(0, v);
    t.end_pass();
  }
  EXPECT_EQ(t.step_median(0), 6);
  EXPECT_EQ(t.median_total(), 6);
}

}  // namespace
}  // namespace tgraph::measure
