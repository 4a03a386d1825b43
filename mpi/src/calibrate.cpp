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
#include "tgraph/graph/generate.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/model/cost_model.hpp"
#include "tgraph/mpi/replay.hpp"
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

struct World {
  int rank = 0, size = 1;
};

// This process's rank and the job's size; UsageError below 2 ranks when `pair` is asked.
World world(bool pair) {
  World w;
  MPI_Comm_rank(MPI_COMM_WORLD, &w.rank);
  MPI_Comm_size(MPI_COMM_WORLD, &w.size);
  if (pair && w.size < 2)
    throw UsageError("calibrate needs 2 ranks (2 MPI processes)");
  return w;
}

// The median step wall time (ns) of replaying step `g` under `a` `steps` times through
// replay_distributed() with one thread per rank, leaving out the first step (it touches the
// data); every rank calls it.
double median_step_ns(const StepGraph& g, const Assignment& a, int steps) {
  Trace trace;
  trace.steps.assign(static_cast<std::size_t>(steps), g);
  TraceAssignment ta;
  ta.method = "calibrate";
  ta.k = a.k;
  ta.steps.assign(static_cast<std::size_t>(steps), a);
  const MpiReplayResult r = replay_distributed(trace, ta, MpiReplayOptions{});
  std::vector<double> wall;
  for (std::size_t s = 1; s < r.steps.size(); ++s)
    wall.push_back(static_cast<double>(r.steps[s].wall_ns));
  if (wall.empty()) return 0;
  std::sort(wall.begin(), wall.end());
  return wall[wall.size() / 2];
}

}  // namespace

MpiLink measure_mpi_link(int rounds, std::uint64_t message_bytes, int repeats) {
  const int rank = world(true).rank;
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
  const World w = world(false);
  if (tasks == 0 || steps < 2) throw UsageError("calibrate: bad task count or steps");
  const ChainsStep chains = chains_step(static_cast<std::uint32_t>(w.size), tasks, cost_ns);
  const double wall = median_step_ns(chains.graph, chains.assignment, steps);
  if (w.rank != 0) return 0;
  return std::max(0.0, (wall - static_cast<double>(tasks) * static_cast<double>(cost_ns)) / tasks);
}

namespace {

// A step and its assignment in which every processor r writes `messages` data of 8 bytes,
// then reads those of processor r - 1 (all sent by then, or nearly): each rank sends and
// receives `messages` messages and waits for almost nothing.
struct Exchange {
  StepGraph g;
  Assignment a;
};

Exchange exchange_step(std::uint32_t ranks, std::uint32_t messages) {
  Exchange x;
  StepGraph& g = x.g;
  Assignment& a = x.a;
  const KindId kind = g.intern_kind("calibrate");
  for (std::uint32_t r = 0; r < ranks; ++r)
    for (std::uint32_t m = 0; m < messages; ++m)
      g.data.push_back({"d " + std::to_string(r) + " " + std::to_string(m), kNoObject, 8});
  a.k = ranks;
  std::uint32_t seq = 0;
  for (std::uint32_t r = 0; r < ranks; ++r)
    for (std::uint32_t m = 0; m < messages; ++m) {
      const Access w[] = {{static_cast<DatumId>(r * messages + m), AccessMode::W}};
      g.add_task(kind, kNoObject, w, 0, seq++);
      a.proc.push_back(r);
    }
  for (std::uint32_t r = 0; r < ranks; ++r)
    for (std::uint32_t m = 0; m < messages; ++m) {
      const std::uint32_t from = (r + ranks - 1) % ranks;
      const Access rd[] = {{static_cast<DatumId>(from * messages + m), AccessMode::R}};
      g.add_task(kind, kNoObject, rd, 0, seq++);
      a.proc.push_back(r);
    }
  g.derive_edges();
  return x;
}

}  // namespace

double measure_message_overhead(double task_overhead_ns, std::uint32_t messages, int steps) {
  const World w = world(true);
  if (messages < 8 || steps < 2) throw UsageError("calibrate: bad message count or steps");
  const auto ranks = static_cast<std::uint32_t>(w.size);
  // Two sizes: the slope leaves out what a step costs whatever its messages (the barrier,
  // starting the threads, the counters' reduction). Past a few hundred messages in flight a
  // message costs more (longer matching queues): the sizes stay below.
  const std::uint32_t few = messages / 4;
  const Exchange small_step = exchange_step(ranks, few), large_step = exchange_step(ranks, messages);
  std::vector<double> slopes;
  for (int round = 0; round < 5; ++round) {
    const double small = median_step_ns(small_step.g, small_step.a, steps);
    const double large = median_step_ns(large_step.g, large_step.a, steps);
    slopes.push_back((large - small) / static_cast<double>(messages - few));
  }
  if (w.rank != 0) return 0;
  std::sort(slopes.begin(), slopes.end());
  // Per extra message: one send, one receive and two task instances on each rank.
  const double per_message = slopes[slopes.size() / 2];
  return std::max(0.0, (per_message - 2.0 * task_overhead_ns) / 2.0);
}

std::string with_mpi_link(std::string_view text, const std::string& name, const MpiLink& link) {
  model::parse_calibration(text, name);  // InputError unless it is a calibration file
  nlohmann::json j = nlohmann::json::parse(text.begin(), text.end());
  j["mpi_latency_ns"] = link.latency_ns;
  j["mpi_per_byte_ns"] = link.per_byte_ns;
  if (link.task_overhead_ns > 0) j["task_overhead_ns"] = link.task_overhead_ns;
  if (link.message_overhead_ns) j["mpi_message_overhead_ns"] = *link.message_overhead_ns;
  j["mpi_calibration"] = {{"measured_by", "tgraph-mpi calibrate"},
                          {"between", "two MPI ranks on this machine"},
                          {"rounds", link.rounds},
                          {"message_bytes", link.message_bytes},
                          {"task_overhead", link.task_overhead_ns > 0
                                                ? "per task instance of tgraph-mpi replay"
                                                : "not measured"},
                          {"message_overhead", link.message_overhead_ns
                                                   ? "per message and side of tgraph-mpi replay"
                                                   : "not measured"}};
  std::string out = j.dump(2) + "\n";
  model::parse_calibration(out, name);  // still a calibration file, with the new fields
  return out;
}

}  // namespace tgraph::mpi
