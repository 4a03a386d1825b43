// SPDX-License-Identifier: MIT
// OptionError: a module names its options' fields; a front end says them in its own words.
#include <gtest/gtest.h>

#include <cstdint>
#include <optional>
#include <string>

#include "tgraph/graph/error.hpp"

namespace tgraph {
namespace {

std::string as_flag(const std::string& field) { return "--" + field; }

TEST(OptionError, SaysTheFieldAndTheProblem) {
  const OptionError e("threads", "must be at least 1");
  EXPECT_STREQ(e.what(), "threads: must be at least 1");
  EXPECT_EQ(e.option(), "threads");
  EXPECT_EQ(e.problem(), "must be at least 1");
}

TEST(OptionError, NamesEveryOtherFieldOfTheProblemInTheFrontEndsWords) {
  const OptionError e("engine", "simgrid needs {platform} or {cluster}, not {}");
  EXPECT_STREQ(e.what(), "engine: simgrid needs platform or cluster, not ");
  EXPECT_EQ(e.render(as_flag), "--engine: simgrid needs --platform or --cluster, not --");
  // An unclosed brace is text.
  EXPECT_EQ(OptionError("steps", "got {1").render(as_flag), "--steps: got {1");
}

TEST(ErrorWithFields, AnInputErrorNamesAFieldInTheFrontEndsWordsAndKeepsItsFileAsItIs) {
  const InputError e("{x}.tgt", std::uint64_t{12}, "trace not closed — read with {recover}",
                     kNamesFields);
  EXPECT_STREQ(e.what(), "{x}.tgt: offset 12: trace not closed — read with recover");
  EXPECT_EQ(e.render(as_flag), "{x}.tgt: offset 12: trace not closed — read with --recover");
  // Without the tag, braces are text; only a snake_case name in braces is a field.
  EXPECT_EQ(InputError("f", std::nullopt, "got {recover}").render(as_flag), "f: got {recover}");
  EXPECT_EQ(name_fields("{a_1} {A} {a b} {", as_flag), "--a_1 {A} {a b} {");
}

TEST(OptionError, IsAUsageError) {
  try {
    throw OptionError("steps", "must be at least 1");
  } catch (const UsageError& e) {
    EXPECT_STREQ(e.what(), "steps: must be at least 1");
    return;
  }
  FAIL() << "not caught as a UsageError";
}

}  // namespace
}  // namespace tgraph
