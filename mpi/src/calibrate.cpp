// SPDX-License-Identifier: MIT
// MPI ping-pong between two local ranks, and the calibration file's MPI fields.
#include "tgraph/mpi/calibrate.hpp"

#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <nlohmann/json.hpp>
#include <thread>
#include <vector>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/mpi/replay.hpp"
#include "tgraph/partition/cost_model.hpp"
#include "tgraph/replay/observer.hpp"

namespace tgraph::mpi {
namespace {

// Median one-way time (ns) of `n` round trips of `bytes`, `repeats` times.
double one_way_ns(int rank, std::vector<char>& buf, int bytes, int n, int repeats) {
  std::vector<double> t;
  for (int r = 0; r < repeats; ++r) {
    MPI_Barrier(MPI_COMM_WORLD);
    const std::int64_t t0 = replay::now_ns();
    for (int i = 0; i < n; ++i) {
      if (rank == 0) {
        MPI_Send(buf.data(), bytes, MPI_BYTE, 1, 7, MPI_COMM_WORLD);
        MPI_Recv(buf.data(), bytes, MPI_BYTE, 1, 7, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      } else if (rank == 1) {
        MPI_Recv(buf.data(), bytes, MPI_BYTE, 0, 7, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        MPI_Send(buf.data(), bytes, MPI_BYTE, 0, 7, MPI_COMM_WORLD);
      }
    }
    t.push_back(static_cast<double>(replay::now_ns() - t0) / (2.0 * n));
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

}  // namespace

MpiLink measure_mpi_link(int rounds, std::uint64_t message_bytes, int repeats) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (size < 2) throw UsageError("calibrate needs 2 ranks (mpirun -np 2 tgraph-mpi calibrate)");
  if (rounds < repeats || repeats < 1 || message_bytes < 1 || message_bytes > (1u << 30))
    throw UsageError("calibrate: bad rounds or message size");
  std::vector<char> buf(message_bytes, 1);
  for (int warm = 0; warm < 2; ++warm) one_way_ns(rank, buf, 8, 100, 1);
  MpiLink link;
  link.rounds = rounds;
  link.message_bytes = message_bytes;
  link.latency_ns = one_way_ns(rank, buf, 8, rounds / repeats, repeats);
  const double big = one_way_ns(rank, buf, static_cast<int>(message_bytes), 4, repeats);
  link.per_byte_ns = std::max(0.0, (big - link.latency_ns) / static_cast<double>(message_bytes));
  return link;
}

double measure_task_overhead(std::uint32_t tasks, std::uint64_t cost_ns, int steps) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (tasks == 0 || steps < 2) throw UsageError("calibrate: bad task count or steps");
  const auto ranks = static_cast<std::uint32_t>(size);
  StepGraph g;
  const KindId kind = g.intern_kind("calibrate");
  for (std::uint32_t r = 0; r < ranks; ++r)
    g.data.push_back({"chain " + std::to_string(r), kNoObject, 64});
  Assignment a;
  a.k = ranks;
  for (std::uint32_t i = 0; i < tasks * ranks; ++i) {
    const Access acc[] = {{static_cast<DatumId>(i % ranks), AccessMode::RW}};
    g.add_task(kind, kNoObject, acc, cost_ns, i);
    a.proc.push_back(i % ranks);
  }
  g.derive_edges();
  Trace trace;
  trace.steps.assign(static_cast<std::size_t>(steps), g);
  TraceAssignment ta;
  ta.method = "calibrate";
  ta.k = ranks;
  ta.steps.assign(static_cast<std::size_t>(steps), a);
  const MpiReplayResult r = replay_distributed(trace, ta, MpiReplayOptions{});
  std::vector<double> per_task;
  for (std::size_t s = 1; s < r.steps.size(); ++s)  // the first one touches the data
    per_task.push_back((static_cast<double>(r.steps[s].wall_ns) -
                        static_cast<double>(tasks) * static_cast<double>(cost_ns)) /
                       tasks);
  if (rank != 0 || per_task.empty()) return 0;
  std::sort(per_task.begin(), per_task.end());
  return std::max(0.0, per_task[per_task.size() / 2]);
}

std::string with_mpi_link(std::string_view text, const std::string& name, const MpiLink& link) {
  partition::parse_calibration(text, name);  // InputError unless it is a calibration file
  nlohmann::json j = nlohmann::json::parse(text.begin(), text.end());
  j["mpi_latency_ns"] = link.latency_ns;
  j["mpi_per_byte_ns"] = link.per_byte_ns;
  if (link.task_overhead_ns > 0) j["task_overhead_ns"] = link.task_overhead_ns;
  j["mpi_calibration"] = {{"measured_by", "tgraph-mpi calibrate"},
                          {"between", "two MPI ranks on this machine"},
                          {"rounds", link.rounds},
                          {"message_bytes", link.message_bytes},
                          {"task_overhead", link.task_overhead_ns > 0
                                                ? "per task instance of tgraph-mpi replay"
                                                : "not measured"}};
  std::string out = j.dump(2) + "\n";
  partition::parse_calibration(out, name);  // still a calibration file, with the new fields
  return out;
}

}  // namespace tgraph::mpi
