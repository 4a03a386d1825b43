// SPDX-License-Identifier: MIT
// ODE's error, debug and message handlers (ode/error.h) while an attachment lives: dError
// and dDebug print one line and exit 1 instead of ODE's exit or abort; dMessage (warnings
// such as "LCP internal error, s <= 0") is counted, its first text kept.
#pragma once

#include <cstdint>
#include <string>

namespace tgraph::ode::detail {

/// Installs the handlers (counted: the last release restores ODE's previous ones).
void acquire_message_handlers();
void release_message_handlers();
/// dMessage calls so far (process-wide) and the first one's text.
std::uint64_t message_count();
std::string first_message();

}  // namespace tgraph::ode::detail
