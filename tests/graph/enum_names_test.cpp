// SPDX-License-Identifier: MIT
// An enum value from its to_string() name; the error lists the names in order.
#include "tgraph/graph/enum_names.hpp"

#include <gtest/gtest.h>

namespace tgraph {
namespace {

enum class Colour { kRed, kGreen, kBlue };

std::string_view to_string(Colour c) {
  switch (c) {
    case Colour::kRed:
      return "red";
    case Colour::kGreen:
      return "green";
    case Colour::kBlue:
      return "blue";
  }
  return "?";
}

TEST(ParseEnum, ReturnsTheValueOfEachName) {
  for (Colour c : {Colour::kRed, Colour::kGreen, Colour::kBlue})
    EXPECT_EQ(parse_enum(to_string(c), {Colour::kRed, Colour::kGreen, Colour::kBlue}, "colour"),
              c);
}

TEST(ParseEnum, RejectsAnotherNameListingTheNamesInOrder) {
  try {
    parse_enum("pink", {Colour::kRed, Colour::kGreen, Colour::kBlue}, "colour");
    FAIL() << "no error";
  } catch (const OptionError& e) {
    EXPECT_STREQ(e.what(), "colour: expected red, green or blue, got 'pink'");
  }
  try {
    parse_enum("", {Colour::kRed}, "colour");
    FAIL() << "no error";
  } catch (const OptionError& e) {
    EXPECT_STREQ(e.what(), "colour: expected red, got ''");
  }
}

}  // namespace
}  // namespace tgraph
