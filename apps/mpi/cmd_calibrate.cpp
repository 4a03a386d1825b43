// SPDX-License-Identifier: MIT
// `tgraph-mpi calibrate [-o F] [--json]` (mpirun -np 2): the MPI latency and bandwidth between
// two local ranks, added to the calibration file `tgraph calibrate` wrote.
#include <mpi.h>

#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/model/cost_model.hpp"
#include "tgraph/mpi/calibrate.hpp"
#include "verbs.hpp"

namespace tgraph::mpi_app {
namespace {

void calibrate(const std::string& path_flag, bool json) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const std::string path = path_flag.empty() ? model::default_calibration_path() : path_flag;
  // Every rank checks the file first: a bad one ends the job before any measurement.
  std::string text;
  try {
    text = read_file_text(path);
  } catch (const Error&) {
    throw InputError(path, std::nullopt,
                     "no calibration file to add the MPI fields to (run `tgraph calibrate -o " +
                         path + "` first)");
  }
  mpi::with_mpi_link(text, path, {});
  mpi::MpiLink link = mpi::measure_mpi_link();
  link.task_overhead_ns = mpi::measure_task_overhead();
  link.message_overhead_ns = mpi::measure_message_overhead(link.task_overhead_ns);
  if (rank != 0) return;
  write_file_atomic(path, mpi::with_mpi_link(text, path, link));
  if (json) {
    std::cout << "{\"mpi_latency_ns\":" << link.latency_ns
              << ",\"mpi_per_byte_ns\":" << link.per_byte_ns
              << ",\"task_overhead_ns\":" << link.task_overhead_ns
              << ",\"mpi_message_overhead_ns\":" << *link.message_overhead_ns << ",\"output\":\"" << path
              << "\"}\n";
  } else {
    std::cout << "MPI between two local ranks: latency " << link.latency_ns << " ns, "
              << link.per_byte_ns << " ns/byte ("
              << (link.per_byte_ns > 0 ? 1.0 / link.per_byte_ns : 0)
              << " GB/s); the replay's own time per task instance " << link.task_overhead_ns
              << " ns, per message and side " << *link.message_overhead_ns << " ns -> " << path
              << "\n";
  }
}

}  // namespace

void add_calibrate_verb(CLI::App& app) {
  auto out = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  auto* cal = app.add_subcommand(
      "calibrate",
      "Add the MPI latency and bandwidth between two local ranks to the calibration "
      "file (mpirun -np 2)");
  cal->add_option("-o,--output", *out,
                  "Calibration file written by `tgraph calibrate` (default: its default path)");
  cal->add_flag("--json", *json, "Print one JSON object");
  cal->callback([out, json] { calibrate(*out, *json); });
}

}  // namespace tgraph::mpi_app
