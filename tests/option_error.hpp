// SPDX-License-Identifier: MIT
// What a module's check of its options says: the field at fault and the problem.
#pragma once

#include <string>

#include "tgraph/graph/error.hpp"

namespace tgraph::test {

/// The what() of the `Error` that `call()` throws, or "accepted" when it returns; any other
/// exception passes through (and fails the test).
template <class Error, class Call>
std::string error_of(Call&& call) {
  try {
    call();
  } catch (const Error& e) {
    return e.what();
  }
  return "accepted";
}

/// The OptionError's ("threads: must be at least 1").
template <class Call>
std::string option_error(Call&& call) {
  return error_of<OptionError>(call);
}

/// The InputError's (a file it read: "cal.json: ...").
template <class Call>
std::string input_error(Call&& call) {
  return error_of<InputError>(call);
}

}  // namespace tgraph::test
