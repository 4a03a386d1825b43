// SPDX-License-Identifier: MIT
#include "messages.hpp"

#include <ode/ode.h>

#include <atomic>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <mutex>

namespace tgraph::ode::detail {
namespace {

std::mutex g_mutex;
int g_users = 0;
dMessageFunction* g_previous_error = nullptr;
dMessageFunction* g_previous_debug = nullptr;
dMessageFunction* g_previous_message = nullptr;
std::atomic<std::uint64_t> g_messages{0};  // a count; the text below is under g_mutex
std::string g_first;

[[noreturn]] void fatal(const char* what, int num, const char* msg, va_list ap) {
  char text[512];
  std::vsnprintf(text, sizeof text, msg ? msg : "", ap);
  for (char* p = text; *p; ++p)
    if (*p == '\n' || *p == '\r') *p = ' ';  // one line
  std::fprintf(stderr, "tgraph: ODE %s %d: %s\n", what, num, text);
  std::fflush(stderr);
  std::_Exit(1);  // ODE's own handler would exit or abort; the state is not to be trusted
}

void on_error(int num, const char* msg, va_list ap) { fatal("error", num, msg, ap); }
void on_debug(int num, const char* msg, va_list ap) {
  fatal("internal error (dDebug)", num, msg, ap);
}
void on_message(int num, const char* msg, va_list ap) {
  if (g_messages.fetch_add(1, std::memory_order_relaxed) == 0) {
    char text[512];
    std::vsnprintf(text, sizeof text, msg ? msg : "", ap);
    std::lock_guard<std::mutex> lock(g_mutex);
    g_first = "ODE message " + std::to_string(num) + ": " + text;
  }
}

}  // namespace

void acquire_message_handlers() {
  std::lock_guard<std::mutex> lock(g_mutex);
  if (g_users++ > 0) return;
  g_previous_error = dGetErrorHandler();
  g_previous_debug = dGetDebugHandler();
  g_previous_message = dGetMessageHandler();
  dSetErrorHandler(&on_error);
  dSetDebugHandler(&on_debug);
  dSetMessageHandler(&on_message);
}

void release_message_handlers() {
  std::lock_guard<std::mutex> lock(g_mutex);
  if (--g_users > 0) return;
  dSetErrorHandler(g_previous_error);
  dSetDebugHandler(g_previous_debug);
  dSetMessageHandler(g_previous_message);
}

std::uint64_t message_count() { return g_messages.load(std::memory_order_relaxed); }

std::string first_message() {
  std::lock_guard<std::mutex> lock(g_mutex);
  return g_first;
}

}  // namespace tgraph::ode::detail
