// SPDX-License-Identifier: MIT
// libFuzzer target: the `tgraph` command-line parser. The input is split at NUL bytes into
// arguments and parsed by the real verbs' option definitions (types, ranges, choices,
// required options); the verbs' work never starts: the root's parse-complete callback, which
// CLI11 runs after every option is parsed and checked and before any verb's callback,
// throws. Every argument vector must parse or give a CLI11 parse error or a tgraph::Error,
// never a crash or another exception.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "../apps/commands.hpp"
#include "fuzz_util.hpp"

namespace {

constexpr std::size_t kMaxArgs = 64;

// Thrown once parsing succeeded, before any verb runs.
struct Parsed {};

CLI::App& make_app() {
  // Built once: the registration is what main() does, minus the callbacks.
  static CLI::App* app = [] {
    auto* a = new CLI::App{"tgraph"};
    a->set_version_flag("--version", std::string("tgraph fuzz"));
    a->require_subcommand(0, 1);
    tgraph::app::add_all_verbs(*a);
    // The verbs' callbacks keep their option storage alive: they stay registered.
    a->parse_complete_callback([] { throw Parsed{}; });
    return a;
  }();
  return *app;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::string> args{"tgraph"};
  std::string cur;
  for (std::size_t i = 0; i < size && args.size() < kMaxArgs; ++i) {
    if (data[i] == 0) {
      args.push_back(cur);
      cur.clear();
    } else {
      cur.push_back(static_cast<char>(data[i]));
    }
  }
  if (args.size() < kMaxArgs) args.push_back(cur);
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  CLI::App& app = make_app();
  try {
    app.clear();
    app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const Parsed&) {
  } catch (const CLI::Error&) {
  } catch (const tgraph::Error&) {
  }
  return 0;
}
