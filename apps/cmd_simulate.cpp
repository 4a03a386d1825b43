// SPDX-License-Identifier: MIT
// `tgraph simulate T.tgt A.tga --engine builtin|simgrid (--platform P.xml | --cluster NxC)`:
// the predicted makespan of every step, from the built-in simulator or SimGrid
// (measure::simulate_command); `tgraph platform`: a SimGrid platform file.
#include <iostream>

#include "commands.hpp"
#include "tgraph/measure/lowered.hpp"
#include "tgraph/partition/platform.hpp"

namespace tgraph::app {

namespace tp = tgraph::partition;

void add_serial_flags(CLI::App* cmd, tp::SerialWork& w) {
  auto* live = cmd->add_option("--live", w.live,
                               "A `tgraph run --json` output of the same steps: each step's record "
                               "+ partition + prepare time is serial work before its tasks");
  cmd->add_option("--serial-ns", w.serial_ns,
                  "Serial work of the main thread before every step's tasks, ns (instead of the "
                  "trace's host time)")
      ->excludes(live);
}

void add_simulate(CLI::App& app) {
  using enum tp::SimulationEngine;
  using enum tp::IntraNodeTransfer;
  auto c = std::make_shared<measure::SimulateCommand>();
  auto* cmd = app.add_subcommand(
      "simulate", "Predict each step's makespan of an assignment: built-in simulator or SimGrid");
  cmd->add_option("trace", c->trace, "Trace file (.tgt)")->required();
  cmd->add_option("assignment", c->assignment, "Assignment file (.tga)")->required();
  add_enum(cmd, "--engine", c->engine, {builtin, simgrid}, "builtin (one machine) or simgrid");
  auto* platform =
      cmd->add_option("--platform", c->platform, "SimGrid platform file (tgraph platform -o)");
  cmd->add_option("--cluster", c->cluster,
                  "N nodes x C cores (e.g. 64x16): processor p on core p % C of node p / C")
      ->excludes(platform);
  add_enum(cmd, "--intra-node", c->intra_node, {reader, link},
           "simgrid, bytes between two cores of a node: reader (default; the reading core spends "
           "size / loopback bandwidth) or link (the loopback link carries them)");
  add_model_flags(cmd, c->model);
  cmd->add_flag("--lower", c->lower,
                "Simulate the graph the partition executors run: each cumulative-write group "
                "across processors through a reducer on its first writer's (two hops)");
  cmd->add_flag("--json", c->json, "Print one JSON object");
  add_serial_flags(cmd, c->serial);
  cmd->callback([c] { std::cout << measure::simulate_command(*c); });
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
  cmd->add_option("--calibration", f->calibration,
                  "Calibration file (default: " + tp::default_calibration_path() + " if present)");
  cmd->add_option("-o,--output", f->output, "Platform file to write (.xml)")->required();
  cmd->callback(
      [f] { std::cout << tp::write_platform(f->output, f->nodes, f->cores, f->calibration); });
}

}  // namespace tgraph::app
