// SPDX-License-Identifier: MIT
// An enum value from its name, for the enums whose to_string() names their values.
#pragma once

#include <initializer_list>
#include <string>
#include <string_view>

#include "tgraph/graph/error.hpp"

namespace tgraph {

/// The one of `values` whose to_string() is `name`; otherwise a UsageError
/// "<what> <name>: expected a, b or c" naming `values` in order. Example:
///   parse_enum(s, {Collapse::kNone, Collapse::kObject}, "--collapse")
template <class Enum>
Enum parse_enum(std::string_view name, std::initializer_list<Enum> values, std::string_view what) {
  std::string names;
  std::size_t i = 0;
  for (Enum v : values) {
    if (to_string(v) == name) return v;
    names += i == 0 ? "" : i + 1 == values.size() ? " or " : ", ";
    names += to_string(v);
    ++i;
  }
  throw UsageError(std::string(what) + " " + std::string(name) + ": expected " + names);
}

}  // namespace tgraph
