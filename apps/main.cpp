// SPDX-License-Identifier: MIT
// `tgraph`: parses the verb and hands over to the modules. Exit 0 ok, 1 failure of the
// work, 2 bad usage or bad input (one line on stderr naming the file or flag).
#include <exception>
#include <iostream>
#include <new>

#include "commands.hpp"
#include "option_words.hpp"
#include "tgraph/version.hpp"

int main(int argc, char** argv) {
  using namespace tgraph::app;
  CLI::App app{
      "tgraph: capture, partition, evaluate and replay task graphs of physics simulations"};
  app.set_version_flag("--version", "tgraph " + std::string(tgraph::kVersionString));
  app.require_subcommand(0, 1);
  add_all_verbs(app);
  try {
    app.parse(argc, argv);
    if (app.get_subcommands().empty()) {
      // `tgraph` alone runs the default job.
      char demo[] = "demo";
      char* demo_argv[] = {argv[0], demo};
      app.parse(2, demo_argv);
    }
  } catch (const CLI::Success& e) {  // --help, --help-all, --version
    return app.exit(e);
  } catch (const std::exception& e) {
    const bool bad_input =
        dynamic_cast<const CLI::ParseError*>(&e) || dynamic_cast<const tgraph::Error*>(&e);
    const bool no_memory = dynamic_cast<const std::bad_alloc*>(&e) != nullptr;
    std::cerr << "tgraph: " << (no_memory ? "out of memory" : error_line(e)) << "\n";
    return bad_input ? 2 : 1;  // Failure and other errors of the work: 1
  }
  return 0;
}
