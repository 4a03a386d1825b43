// SPDX-License-Identifier: MIT
// `tgraph simulate T.tgt A.tga --engine builtin|simgrid (--platform P.xml | --cluster NxC)`:
// the predicted makespan of every step, from the built-in simulator or SimGrid
// (model::simulate_command); `tgraph platform`: a SimGrid platform file.
#include <iostream>

#include "commands.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/model/platform.hpp"
#include "tgraph/model/simulate.hpp"
#include "tgraph/partition/assignment_io.hpp"

namespace tgraph::app {

namespace tp = tgraph::partition;

void add_serial_flags(CLI::App* cmd, model::SerialWork& w) {
  auto* live = cmd->add_option("--live", w.live,
                               "A `tgraph run --json` output of the same steps: each step's record "
                               "+ partition + prepare time is serial work before its tasks");
  cmd->add_option("--serial-ns", w.serial_ns,
                  "Serial work of the main thread before every step's tasks, ns (instead of the "
                  "trace's host time)")
      ->excludes(live);
}

void add_simulate(CLI::App& app) {
  using enum model::SimulationEngine;
  using enum model::IntraNodeTransfer;
  auto c = std::make_shared<model::SimulateCommand>();
  auto n = std::make_shared<tp::NamedOptions>();  // the cost model by name
  auto* cmd = app.add_subcommand(
      "simulate", "Predict each step's makespan of an assignment: built-in simulator or SimGrid");
  cmd->add_option("trace", c->trace, "Trace file (.tgt)")->required();
  cmd->add_option("assignment", c->assignment, "Assignment file (.tga)")->required();
  add_enum(cmd, "--engine", c->engine, {builtin, simgrid}, "builtin (one machine) or simgrid");
  auto* platform_flag =
      cmd->add_option("--platform", c->platform, "SimGrid platform file (tgraph platform -o)");
  cmd->add_option("--cluster", c->cluster,
                  "N nodes x C cores (e.g. 64x16): processor p on core p % C of node p / C")
      ->excludes(platform_flag);
  add_enum(cmd, "--intra-node", c->intra_node, {reader, link},
           "simgrid, bytes between two cores of a node: reader (default; the reading core spends "
           "size / loopback bandwidth) or link (the loopback link carries them)");
  add_model_flags(cmd, *n);
  cmd->add_flag("--lower", c->lower,
                "Simulate the graph the partition executors run: each cumulative-write group "
                "across processors through a reducer on its first writer's (two hops)");
  cmd->add_flag("--json", c->json, "Print one JSON object");
  add_serial_flags(cmd, c->serial);
  cmd->callback([c, n] {
    // The options first (calibration, cluster, platform), then the files, then the model.
    c->model = n->cost_model();
    const model::SimulatedPlatform platform = model::simulated_platform(*c);
    const Trace trace = read_trace(c->trace);
    const TraceAssignment as = tp::load_assignment(c->assignment, trace, c->trace);
    std::cout << model::simulate_command(*c, platform, trace, as);
  });
}

void add_platform(CLI::App& app) {
  struct Flags {
    std::uint64_t nodes = 1, cores = 1;
    std::string calibration, output;
  };
  auto f = std::make_shared<Flags>();
  auto* cmd = app.add_subcommand(
      "platform", "Write a SimGrid platform file: a cluster whose links follow the calibration");
  cmd->add_option("--nodes", f->nodes, "Nodes of the cluster")->required();
  cmd->add_option("--cores", f->cores, "Cores per node")->required();
  cmd->add_option(
      "--calibration", f->calibration,
      "Calibration file (default: " + model::default_calibration_path() + " if present)");
  cmd->add_option("-o,--output", f->output, "Platform file to write (.xml)")->required();
  cmd->callback(
      [f] { std::cout << model::write_platform(f->output, f->nodes, f->cores, f->calibration); });
}

}  // namespace tgraph::app
