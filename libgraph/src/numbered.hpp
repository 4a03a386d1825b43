// SPDX-License-Identifier: MIT
// Internal: names made of a prefix and a number ("c12"), for generated and imported steps.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace tgraph::detail {

/// prefix + i, appended: GCC 12 inlines `"c" + std::to_string(i)` into a false -Wrestrict
/// warning.
inline std::string numbered(std::string_view prefix, std::uint64_t i) {
  std::string s(prefix);
  s += std::to_string(i);
  return s;
}

}  // namespace tgraph::detail
