// SPDX-License-Identifier: MIT
// `tgraph-mpi replay T.tgt [A.tga] --threads-per-rank T [--steps N] [--check] [--json]
// [--watchdog SECONDS]`: the trace's steps across the MPI ranks (tgraph::mpi).
#include <mpi.h>

#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/mpi/replay.hpp"
#include "tgraph/partition/assignment_io.hpp"
#include "verbs.hpp"

namespace tgraph::mpi_app {
namespace {

struct ReplayArgs {
  std::string trace, assignment, policy = "partition";
  mpi::MpiReplayOptions o;  // the flags bound to its fields, but the policy's word
  bool json = false;
};

void replay(const ReplayArgs& a) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  mpi::MpiReplayOptions o = a.o;
  if (o.threads_per_rank < 1 || o.threads_per_rank > 256)
    throw UsageError("--threads-per-rank " + std::to_string(o.threads_per_rank) +
                     ": expected 1 to 256");
  if (o.steps && *o.steps < 1) throw UsageError("--steps must be at least 1");
  if (!(o.watchdog_s >= 0) || o.watchdog_s > 1e6)
    throw UsageError("--watchdog: expected 0 (off) to 1e6 seconds");
  o.policy = a.policy == "starpu-mpi" ? mpi::MpiPolicy::kStarpuMpi : mpi::MpiPolicy::kPartition;
  const Trace trace = read_trace(a.trace);
  const std::uint32_t k = static_cast<std::uint32_t>(size) * o.threads_per_rank;
  // No file: the strategy `tgraph replay` uses by default (owner with objects, else list).
  const TraceAssignment as = partition::load_or_partition(trace, a.trace, a.assignment, "", k);
  const mpi::MpiReplayResult r = mpi::replay_distributed(trace, as, o);
  if (rank == 0)
    std::cout << (a.json ? mpi::to_json(r, a.trace) + "\n" : mpi::to_text(r, a.trace))
              << std::flush;
  if (r.identical && !*r.identical && rank == 0)
    std::cerr << "tgraph-mpi: the distributed state differs from the sequential replay\n";
  int differs = r.identical && !*r.identical ? 1 : 0;
  MPI_Bcast(&differs, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (differs) throw std::runtime_error("check failed");
}

}  // namespace

void add_replay_verb(CLI::App& app) {
  auto a = std::make_shared<ReplayArgs>();
  auto* cmd =
      app.add_subcommand("replay", "Replay a trace across the MPI ranks (synthetic bodies)");
  cmd->add_option("trace", a->trace, "Trace file (.tgt)")->required();
  cmd->add_option("assignment", a->assignment,
                  "Assignment file (.tga) with K = ranks x threads per rank (default: the "
                  "strategy tgraph replay uses)");
  cmd->add_option("--threads-per-rank", a->o.threads_per_rank, "Threads (processors) per rank")
      ->required();
  cmd->add_option("--steps", a->o.steps, "Replay the first N steps");
  cmd->add_option("--policy", a->policy,
                  "partition: tgraph's schedule over MPI; starpu-mpi: the same graph, bodies "
                  "and ownership submitted through StarPU-MPI")
      ->check(CLI::IsMember({"partition", "starpu-mpi"}));
  cmd->add_flag("--check", a->o.check, "Compare the final state with the sequential replay");
  cmd->add_flag("--host-work", a->o.host_work,
                "Run each step's serial host work (recorded outside the tasks) on rank 0 "
                "before any task, as tgraph replay and tgraph simulate do");
  cmd->add_flag("--json", a->json, "Print one JSON object");
  cmd->add_option("--watchdog", a->o.watchdog_s,
                  "Seconds without progress before a rank names what it waits for and the job "
                  "ends with exit 1 (0: off; default 60)");
  cmd->add_option("--test-drop-message", a->o.test_drop_message, "Testing: never send this message of step 0")
      ->group("");
  cmd->callback([a] { replay(*a); });
}

}  // namespace tgraph::mpi_app
