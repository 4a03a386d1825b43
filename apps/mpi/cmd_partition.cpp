// SPDX-License-Identifier: MIT
// `tgraph-mpi partition T.tgt --method ptscotch --nodes N --cores C [--step S] -o A.tga
// [--json]`: every rank reads the trace; each step is partitioned by all ranks together
// (tgraph::mpi::ptscotch_partition), and rank 0 writes the .tga and the report.
#include <mpi.h>

#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/partition/assignment_io.hpp"
#include "tgraph/partition/strategy.hpp"
#include "tgraph/mpi/session.hpp"
#include "verbs.hpp"
#if defined(TGRAPH_HAVE_PTSCOTCH)
#include "tgraph/mpi/ptscotch.hpp"
#endif

namespace tgraph::mpi_app {

namespace {

struct PartitionArgs {
  std::string trace, method = "ptscotch", output, scotch = "quality";
  std::uint32_t nodes = 0, cores = 1;
  std::optional<std::size_t> step;
  partition::Options options;
  bool json = false;
};

#if defined(TGRAPH_HAVE_PTSCOTCH)
void run(const PartitionArgs& a) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  const double t0 = MPI_Wtime();
  Trace trace;
  mpi::agree_on_input(
      [&] {
        if (a.nodes == 0) throw UsageError("--nodes: expected at least 1");
        if (a.cores == 0) throw UsageError("--cores: expected at least 1");
        trace = read_trace(a.trace);
        if (a.step && *a.step >= trace.steps.size())
          throw UsageError("--step: " + std::to_string(*a.step) + " is past the trace's " +
                           std::to_string(trace.steps.size()) + " steps");
      },
      MPI_COMM_WORLD);
  double read_ms = (MPI_Wtime() - t0) * 1e3;
  MPI_Allreduce(MPI_IN_PLACE, &read_ms, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  partition::Options options = a.options;
  options.scotch = partition::parse_scotch_flavour(a.scotch);
  const std::size_t first = a.step.value_or(0);
  const std::size_t last = a.step ? *a.step + 1 : trace.steps.size();
  const mpi::PtScotchTraceResult r =
      mpi::ptscotch_partition_trace(trace, first, last, a.nodes, a.cores, options, MPI_COMM_WORLD);
  mpi::PtScotchRun about;
  about.trace = a.trace;
  about.output = a.output;
  about.ranks = ranks;
  about.nodes = a.nodes;
  about.cores = a.cores;
  about.first = first;
  about.read_ms = read_ms;
  about.max_rss_mib = mpi::max_rss_mib(MPI_COMM_WORLD);
  if (rank != 0) return;
  if (!a.output.empty()) partition::write_assignment(a.output, r.assignment, r.hashes);
  std::cout << (a.json ? mpi::ptscotch_json(r, about) + "\n" : mpi::ptscotch_text(r, about))
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
  cmd->add_option("trace", a->trace, "Trace file (.tgt), read by every rank")->required();
  cmd->add_option("--method,-m", a->method, "Strategy: ptscotch")
      ->check(CLI::IsMember({"ptscotch"}));
  cmd->add_option("--nodes", a->nodes, "Nodes: parts of the distributed partitioning")->required();
  cmd->add_option("--cores", a->cores, "Cores per node: parts of each node (1)");
  cmd->add_option("--step", a->step,
                  "Partition only this step (the .tga then holds one step); default every step");
  cmd->add_option("-o,--output", a->output, "Assignment file to write (.tga), by rank 0");
  cmd->add_option("--imbalance", a->options.imbalance,
                  "Max/mean processor load allowed (1.03; its square root per level)")
      ->check(CLI::Range(1.0, 100.0));
  cmd->add_option("--seed", a->options.seed, "Scotch / PT-Scotch seed (0)");
  cmd->add_option("--scotch-strategy", a->scotch, "Flavour: default, quality, speed, balance")
      ->check(CLI::IsMember({"default", "quality", "speed", "balance"}));
  cmd->add_flag("--json", a->json, "Print one JSON object (rank 0)");
  cmd->callback([a] { run(*a); });
}

}  // namespace tgraph::mpi_app
