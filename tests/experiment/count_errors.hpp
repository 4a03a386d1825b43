// SPDX-License-Identifier: MIT
// What every experiment's plan says of a count of 0 (steps, repeat): the field and the bound.
#pragma once

#include <gtest/gtest.h>

#include "../option_error.hpp"

namespace tgraph::test {

/// `plan(o)` refuses Options with steps 0, then with repeat 0, naming each field.
template <class Options, class Plan>
void expect_zero_counts_refused(Plan plan) {
  Options o;
  o.steps = 0;
  EXPECT_EQ(option_error([&] { plan(o); }), "steps: must be at least 1");
  o = {};
  o.repeat = 0;
  EXPECT_EQ(option_error([&] { plan(o); }), "repeat: must be at least 1");
}

}  // namespace tgraph::test
