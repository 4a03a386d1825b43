// SPDX-License-Identifier: MIT
// `tgraph simulate T.tgt A.tga --engine builtin|simgrid (--platform P.xml | --cluster NxC)`:
// the predicted makespan of every step, from the built-in simulator or SimGrid.
#include <iostream>

#include "commands.hpp"
#include "tgraph/measure/lowered.hpp"
#include "tgraph/partition/assignment_io.hpp"
#include "tgraph/partition/cost_model.hpp"
#include "tgraph/partition/simulation.hpp"

namespace tgraph::app {

namespace tp = tgraph::partition;

std::vector<std::uint64_t> SerialFlags::per_step(std::size_t steps) const {
  return tp::serial_work(live, serial_ns, steps);
}

void add_serial_flags(CLI::App* cmd, SerialFlags& f) {
  auto* live = cmd->add_option(
      "--live", f.live,
      "A `tgraph run --json` output of the same steps: each step's record + partition + "
      "prepare time is serial work before its tasks (instead of the trace's host time)");
  cmd->add_option("--serial-ns", f.serial_ns,
                  "Serial work of the main thread before every step's tasks, ns (instead of the "
                  "trace's host time)")
      ->excludes(live);
}

void add_simulate(CLI::App& app) {
  struct Flags {
    std::string engine = "builtin", platform, cluster, model = "calibrated", calibration;
    std::string intra_node = "reader";
    bool lower = false;
  };
  auto a = std::make_shared<Args>();
  auto f = std::make_shared<Flags>();
  auto* cmd = app.add_subcommand(
      "simulate", "Predict each step's makespan of an assignment: built-in simulator or SimGrid");
  cmd->add_option("trace", a->input, "Trace file (.tgt)")->required();
  cmd->add_option("assignment", a->assignment, "Assignment file (.tga)")->required();
  cmd->add_option("--engine", f->engine, "builtin (default; one machine) or simgrid")
      ->check(CLI::IsMember({"builtin", "simgrid"}));
  auto* platform =
      cmd->add_option("--platform", f->platform, "SimGrid platform file (tgraph platform -o)");
  cmd->add_option("--cluster", f->cluster,
                  "N nodes x C cores (e.g. 64x16): processor p on core p % C of node p / C")
      ->excludes(platform);
  cmd->add_option("--intra-node", f->intra_node,
                  "simgrid, bytes between two cores of a node: reader (default; the reading core "
                  "spends size / loopback bandwidth) or link (the loopback link carries them)")
      ->check(CLI::IsMember({"reader", "link"}));
  cmd->add_option("--model", f->model, "Cost model: calibrated (default) or ideal (free syncs)")
      ->check(CLI::IsMember({"ideal", "calibrated"}));
  cmd->add_option("--calibration", f->calibration,
                  "Calibration file (default: " + tp::default_calibration_path() + " if present)");
  cmd->add_flag("--lower", f->lower,
                "Simulate the graph the partition executors run: each cumulative-write group "
                "that spans processors reduced through a reducer task on its first writer's "
                "processor (two hops), each processor in program order");
  cmd->add_flag("--json", a->json, "Print one JSON object");
  auto serial = std::make_shared<SerialFlags>();
  add_serial_flags(cmd, *serial);
  cmd->callback([a, f, serial] {
    tp::SimulatedPlatform p;
    p.model = tp::select_cost_model(f->model, f->calibration);
    if (!f->cluster.empty()) p.cluster = tp::parse_cluster(f->cluster);
    p.file = f->platform;
    p.intra_node =
        f->intra_node == "link" ? tp::IntraNodeTransfer::link : tp::IntraNodeTransfer::reader;
    const tp::SimulationEngine engine =
        f->engine == "simgrid" ? tp::SimulationEngine::simgrid : tp::SimulationEngine::builtin;
    if (engine == tp::SimulationEngine::builtin && !p.file.empty())
      throw UsageError("--platform: the builtin engine has no platform model (use --engine simgrid)");
    const Trace trace = read_trace(a->input);
    const TraceAssignment as = tp::load_assignment(a->assignment, trace, a->input);
    p.serial_ns = serial->per_step(trace.steps.size());
    if (!p.serial_ns.empty() && engine != tp::SimulationEngine::builtin)
      throw UsageError("--live/--serial-ns: only the builtin engine charges the main thread's work");
    const tp::Prediction r = measure::simulate(trace, as, engine, p, f->lower);
    std::cout << (a->json ? tp::prediction_json(r) + "\n" : tp::prediction_text(r));
  });
}

void add_platform(CLI::App& app) {
  struct Flags {
    std::uint64_t nodes = 1, cores = 1;
    std::string calibration;
  };
  auto a = std::make_shared<Args>();
  auto f = std::make_shared<Flags>();
  auto* cmd = app.add_subcommand(
      "platform", "Write a SimGrid platform file: a cluster whose links follow the calibration");
  cmd->add_option("--nodes", f->nodes, "Nodes of the cluster")->required();
  cmd->add_option("--cores", f->cores, "Cores per node")->required();
  cmd->add_option("--calibration", f->calibration,
                  "Calibration file (default: " + tp::default_calibration_path() + " if present)");
  cmd->add_option("-o,--output", a->output, "Platform file to write (.xml)")->required();
  cmd->callback([a, f] {
    std::cout << tp::write_platform(a->output, f->nodes, f->cores, f->calibration);
  });
}

}  // namespace tgraph::app
