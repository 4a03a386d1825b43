// SPDX-License-Identifier: MIT
// Helpers shared by the libFuzzer targets.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "tgraph/graph/byte_codec.hpp"

namespace tgraph::fuzz {

/// The input as text.
inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

/// Stops the run with a crash the fuzzer reports (an invariant of the target failed).
[[noreturn]] inline void invariant_failed() { __builtin_trap(); }

}  // namespace tgraph::fuzz
