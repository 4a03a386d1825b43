// SPDX-License-Identifier: MIT
// `tgraph-mpi partition T.tgt --method ptscotch --nodes N --cores C [--step S] -o A.tga
// [--json]`: every rank reads the trace; each step is partitioned by all ranks together
// (tgraph::mpi::ptscotch_partition_file), and rank 0 writes the .tga and the report.
#include <mpi.h>

#include <iostream>
#include <memory>
#include <string>

#include "tgraph/graph/error.hpp"
#include "tgraph/mpi/ptscotch.hpp"  // declarations only: defined where PT-Scotch is found
#include "verbs.hpp"

namespace tgraph::mpi_app {

namespace {

struct PartitionArgs {
  std::string method = "ptscotch";
  bool json = false;
  mpi::PtScotchFileOptions file;
};

#if defined(TGRAPH_HAVE_PTSCOTCH)
void run(const PartitionArgs& a) {
  const mpi::PtScotchFileReport r = mpi::ptscotch_partition_file(a.file, MPI_COMM_WORLD);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank != 0) return;
  std::cout << (a.json ? mpi::ptscotch_json(r.result, r.run) + "\n"
                       : mpi::ptscotch_text(r.result, r.run))
            << std::flush;
}
#else
void run(const PartitionArgs&) {
  throw UsageError(
      "--method ptscotch: this tgraph-mpi was built without PT-Scotch "
      "(Debian libptscotch-dev)");
}
#endif

}  // namespace

void add_partition_verb(CLI::App& app) {
  auto a = std::make_shared<PartitionArgs>();
  auto* cmd = app.add_subcommand(
      "partition",
      "Partition a trace's steps across the ranks: nodes with PT-Scotch, then cores with Scotch");
  cmd->add_option("trace", a->file.trace, "Trace file (.tgt), read by every rank")->required();
  cmd->add_option("--method,-m", a->method, "Strategy: ptscotch")
      ->check(CLI::IsMember({"ptscotch"}));
  cmd->add_option("--nodes", a->file.nodes, "Nodes: parts of the distributed partitioning")->required();
  cmd->add_option("--cores", a->file.cores, "Cores per node: parts of each node (1)");
  cmd->add_option("--step", a->file.step,
                  "Partition only this step (the .tga then holds one step); default every step");
  cmd->add_option("-o,--output", a->file.output, "Assignment file to write (.tga), by rank 0");
  cmd->add_option("--imbalance", a->file.options.imbalance,
                  "Max/mean processor load allowed (1.03; its square root per level)")
      ->check(CLI::Range(1.0, 100.0));
  cmd->add_option("--seed", a->file.options.seed, "Scotch / PT-Scotch seed (0)");
  cmd->add_option("--scotch-strategy", a->file.scotch, "Flavour: default, quality, speed, balance")
      ->check(CLI::IsMember({"default", "quality", "speed", "balance"}));
  cmd->add_flag("--json", a->json, "Print one JSON object (rank 0)");
  cmd->callback([a] { run(*a); });
}

}  // namespace tgraph::mpi_app
