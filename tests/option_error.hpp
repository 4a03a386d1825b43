// SPDX-License-Identifier: MIT
// What a module's check of its options says: the field at fault and the problem.
#pragma once

#include <string>

#include "tgraph/graph/error.hpp"

namespace tgraph::test {

/// The what() of the OptionError that `call()` throws ("threads: must be at least 1"), or
/// "accepted" when it returns; any other exception passes through (and fails the test).
template <class Call>
std::string option_error(Call&& call) {
  try {
    call();
  } catch (const OptionError& e) {
    return e.what();
  }
  return "accepted";
}

/// The same for the InputError that `call()` throws (a file it read: "cal.json: ...").
template <class Call>
std::string input_error(Call&& call) {
  try {
    call();
  } catch (const InputError& e) {
    return e.what();
  }
  return "accepted";
}

}  // namespace tgraph::test
