// SPDX-License-Identifier: MIT
// `tgraph`: parses the verb and hands over to the modules. Exit 0 ok, 1 failure of the
// work, 2 bad usage or bad input (one line on stderr naming the file or flag).
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <thread>
#include <exception>
#include <iostream>

#include "commands.hpp"

namespace tgraph::app {

void print_json(const nlohmann::json& j) { std::cout << j.dump() << std::endl; }

Trace load_trace(const std::string& path, bool recover) {
  ReadOptions options;
  options.recover = recover;
  return read_trace(path, options);
}

std::string machine_description() {
  std::string model;
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);) {
    if (line.rfind("model name", 0) == 0) {
      if (auto colon = line.find(':'); colon != std::string::npos) model = line.substr(colon + 2);
      break;
    }
  }
  if (model.empty()) model = "unknown cpu";
  return model + ", " + std::to_string(std::thread::hardware_concurrency()) + " hardware threads";
}

std::uint32_t default_threads() { return std::max(1u, std::thread::hardware_concurrency()); }

}  // namespace tgraph::app

int main(int argc, char** argv) {
  using namespace tgraph::app;
  CLI::App app{"tgraph: capture, partition, evaluate and replay task graphs of physics simulations"};
  app.set_version_flag("--version", std::string("tgraph ") + TGRAPH_VERSION);
  app.require_subcommand(0, 1);
  add_demo(app);
  add_capture(app);
  add_info(app);
  add_export(app);
  add_diff(app);
  add_partition_verbs(app);
  add_replay_verbs(app);
  add_validate(app);
  add_viz_verbs(app);
  try {
    app.parse(argc, argv);
    if (app.get_subcommands().empty()) {
      // `tgraph` alone runs the default job.
      char demo[] = "demo";
      char* demo_argv[] = {argv[0], demo};
      app.parse(2, demo_argv);
    }
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "tgraph: " << e.what() << "\n";
    return 2;
  } catch (const tgraph::Error& e) {
    std::cerr << "tgraph: " << e.what() << "\n";
    return 2;
  } catch (const Failure& e) {
    std::cerr << "tgraph: " << e.what() << "\n";
    return 1;
  } catch (const std::bad_alloc&) {
    std::cerr << "tgraph: out of memory\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "tgraph: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
