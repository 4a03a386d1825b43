// SPDX-License-Identifier: MIT
// Simulated clusters: the N x C shape of a cluster and the SimGrid platform file of
// `tgraph platform` (a cluster zone whose links follow the cost model).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "tgraph/model/cost_model.hpp"

namespace tgraph::model {

/// N identical nodes of C cores each. Processor p of an assignment runs on core p % C of
/// node p / C.
///
///   ClusterShape c = parse_cluster("64x16");   // c.nodes 64, c.cores 16
struct ClusterShape {
  std::uint32_t nodes = 1;
  std::uint32_t cores = 1;
  /// Processors the cluster holds (nodes x cores).
  std::uint64_t processors() const { return std::uint64_t{nodes} * cores; }
};

/// Largest node count and core count accepted (a platform of 2^20 hosts is far beyond
/// what SimGrid simulates in minutes).
inline constexpr std::uint32_t kMaxNodes = 1u << 20;
inline constexpr std::uint32_t kMaxCores = 4096;

/// Parses "NxC" (1 <= N <= kMaxNodes, 1 <= C <= kMaxCores); otherwise an OptionError of the
/// options field `field`.
ClusterShape parse_cluster(std::string_view text, std::string_view field = "cluster");
/// Checks a shape given as two numbers; otherwise an OptionError of the field "nodes" or
/// "cores", the one out of range.
ClusterShape cluster_shape(std::uint64_t nodes, std::uint64_t cores);

/// The SimGrid platform (XML, DTD 4.1) of cluster `c` whose costs follow `m`:
/// * hosts `node-0` ... `node-(N-1)`, C cores each at 1 Gflop/s (one flop = one ns of a
///   task's measured cost);
/// * inside a node, a loopback link of latency `m.sync_latency_ns` and bandwidth
///   1 / `m.per_byte_ns` (shared by nobody: SimGrid's cluster loopback is a fat pipe);
/// * between nodes, each node's private link (split duplex) of latency
///   `m.mpi_latency_ns / 2` and bandwidth 1 / `m.mpi_per_byte_ns`, no backbone: a message
///   crosses two links, latency `m.mpi_latency_ns`, and shares its nodes' links only;
/// * the network model that makes a transfer cost exactly latency + size / bandwidth
///   (CM02, no cross traffic, no TCP window bound).
/// A per-byte cost of 0 becomes a bandwidth of 1e18 B/s (SimGrid needs a finite one).
std::string platform_xml(const ClusterShape& c, const CostModel& m);
/// `tgraph platform`: platform_xml() of a `nodes` x `cores` cluster (cluster_shape() checks
/// them) whose links follow the calibration file `calibration` (select_cost_model), written
/// to `output`; returns the line that says what was written.
std::string write_platform(const std::string& output, std::uint64_t nodes, std::uint64_t cores,
                           const std::string& calibration);

/// The SimGrid configuration the engine and platform_xml() set, as "key:value" items.
inline constexpr std::string_view kSimgridNetworkConfig[] = {
    "network/model:CM02", "network/crosstraffic:0", "network/TCP-gamma:0"};

}  // namespace tgraph::model
