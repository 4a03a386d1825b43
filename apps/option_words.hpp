// SPDX-License-Identifier: MIT
// How the command line says the options' fields a module's error or warning names: as flags.
#pragma once

#include <exception>
#include <string>

#include "tgraph/graph/error.hpp"

namespace tgraph::app {

/// The flag of an options field: "threads_per_rank" -> "--threads-per-rank"; a one-letter
/// field is a short flag ("k" -> "-k").
inline std::string flag_of(std::string field) {
  if (field.size() == 1) return "-" + field;
  for (char& c : field)
    if (c == '_') c = '-';
  return "--" + field;
}

/// The one line a command prints for an error: the options' fields a module's error names
/// (OptionError, ErrorWithFields) in the command line's words, anything else as it is.
inline std::string error_line(const std::exception& e) {
  if (const auto* o = dynamic_cast<const ErrorWithFields*>(&e)) return o->render(flag_of);
  return e.what();
}

}  // namespace tgraph::app
