// SPDX-License-Identifier: MIT
// An enum value from its name, for the enums whose to_string() names their values.
#pragma once

#include <initializer_list>
#include <string>
#include <string_view>

#include "tgraph/graph/error.hpp"

namespace tgraph {

/// The one of `values` whose to_string() is `name`; otherwise an OptionError of the options
/// field `field`: "<field>: expected a, b or c, got '<name>'" naming `values` in order.
/// Example:
///   parse_enum(s, {Collapse::kNone, Collapse::kObject}, "collapse")
template <class Enum>
Enum parse_enum(std::string_view name, std::initializer_list<Enum> values, std::string_view field) {
  std::string names;
  std::size_t i = 0;
  for (Enum v : values) {
    if (to_string(v) == name) return v;
    names += i == 0 ? "" : i + 1 == values.size() ? " or " : ", ";
    names += to_string(v);
    ++i;
  }
  throw OptionError(std::string(field), "expected " + names + ", got '" + std::string(name) + "'");
}

}  // namespace tgraph
