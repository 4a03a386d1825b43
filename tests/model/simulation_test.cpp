// SPDX-License-Identifier: MIT
// `tgraph simulate`'s engines and `tgraph platform`'s file: the cluster shape, the platform
// XML, exact transfer costs on SimGrid, agreement of SimGrid with the built-in simulator on
// one host (random graphs; bars64 and falling in tests/measure/simgrid_agreement_test.cpp),
// bad platforms and assignments.
#include "tgraph/model/simulation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "../scratch_dir.hpp"
#include "test_graphs.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/model/platform.hpp"
#include "tgraph/model/simulator.hpp"
#include "tgraph/partition/strategy.hpp"

namespace tgraph::model {
namespace {

using namespace tgraph::partition;  // the strategies that place the tasks

using partition::testing::Builder;
using partition::testing::M;

SimulatedPlatform on_cluster(ClusterShape c, const CostModel& m,
                             IntraNodeTransfer intra = IntraNodeTransfer::reader) {
  SimulatedPlatform p;
  p.cluster = c;
  p.model = m;
  p.intra_node = intra;
  return p;
}

SimulatedPlatform on_file(const std::string& file, const CostModel& m) {
  SimulatedPlatform p;
  p.file = file;
  p.model = m;
  return p;
}

TEST(ParseCluster, ReadsNodesAndCores) {
  const ClusterShape c = parse_cluster("64x16");
  EXPECT_EQ(c.nodes, 64u);
  EXPECT_EQ(c.cores, 16u);
  EXPECT_EQ(c.processors(), 1024u);
  EXPECT_EQ(parse_cluster("1X2").cores, 2u);
}

TEST(ParseCluster, RejectsAnythingButTwoPositiveCounts) {
  for (const char* bad : {"", "64", "x16", "64x", "0x4", "4x0", "4x16x2", "-1x4", "ax4", "4x 2",
                          "99999999999x1", "1x5000"}) {
    try {
      parse_cluster(bad, "shape");
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const OptionError& e) {
      EXPECT_EQ(e.option(), "shape") << e.what();
    }
  }
  try {
    cluster_shape(0, 4);
    ADD_FAILURE() << "accepted 0 nodes";
  } catch (const OptionError& e) {
    EXPECT_STREQ(e.what(), "nodes: expected 1 to 1048576, found 0");
  }
  try {
    cluster_shape(4, kMaxCores + 1);
    ADD_FAILURE() << "accepted 4097 cores";
  } catch (const OptionError& e) {
    EXPECT_STREQ(e.what(), "cores: expected 1 to 4096, found 4097");
  }
}

// A cost model with these links: between two cores of a node (signal latency, ns per byte)
// and between nodes (MPI latency, ns per byte).
CostModel links(double sync_latency_ns, double per_byte_ns, double mpi_latency_ns,
                double mpi_per_byte_ns) {
  CostModel m;
  m.sync_latency_ns = sync_latency_ns;
  m.per_byte_ns = per_byte_ns;
  m.mpi_latency_ns = mpi_latency_ns;
  m.mpi_per_byte_ns = mpi_per_byte_ns;
  return m;
}

TEST(PlatformXml, TakesLinkLatencyAndBandwidthFromTheCostModel) {
  const CostModel m = links(100, 0.05, 1500, 0.08);
  const std::string xml = platform_xml({4, 16}, m);
  EXPECT_NE(xml.find("radical=\"0-3\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("core=\"16\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("loopback_lat=\"100ns\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("loopback_bw=\"20000000000Bps\""), std::string::npos) << xml;
  // Two private links per message: half the latency each.
  EXPECT_NE(xml.find("lat=\"750ns\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("bw=\"12500000000Bps\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("<prop id=\"network/model\" value=\"CM02\"/>"), std::string::npos) << xml;
}

TEST(PlatformXml, WritePlatformWritesTheXmlOfTheCalibrationsLinks) {
  const std::filesystem::path dir = tgraph::test::scratch_dir("tgraph_write_platform_");
  const std::string cal = (dir / "c.json").string(), out = (dir / "p.xml").string();
  std::ofstream(cal) << R"({"sync_latency_ns": 100, "per_byte_ns": 0.05})";
  EXPECT_EQ(write_platform(out, 4, 16, cal),
            "wrote " + out + ": 4 nodes x 16 cores, costs from " + cal + "\n");
  CostModel m = parse_calibration(R"({"sync_latency_ns": 100, "per_byte_ns": 0.05})", cal);
  m.source = cal;
  std::ifstream f(out);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(f), {}), platform_xml({4, 16}, m));
  EXPECT_THROW(write_platform(out, 0, 16, cal), OptionError);
  std::filesystem::remove_all(dir);
}

TEST(Calibration, InterNodeFieldsAreOptionalWithDefaults) {
  const CostModel old = parse_calibration(R"({"sync_latency_ns": 70, "per_byte_ns": 0.03})", "c");
  EXPECT_EQ(old.mpi_latency_ns, CostModel::defaults().mpi_latency_ns);
  EXPECT_EQ(old.mpi_per_byte_ns, CostModel::defaults().mpi_per_byte_ns);
  const CostModel mpi = parse_calibration(
      R"({"sync_latency_ns": 70, "per_byte_ns": 0.03, "mpi_latency_ns": 2500, "mpi_per_byte_ns": 0.2})",
      "c");
  EXPECT_EQ(mpi.mpi_latency_ns, 2500);
  EXPECT_EQ(mpi.mpi_per_byte_ns, 0.2);
  EXPECT_THROW(
      parse_calibration(R"({"sync_latency_ns": 1, "per_byte_ns": 0, "mpi_latency_ns": -1})", "c"),
      InputError);
}

TEST(Calibration, TaskOverheadIsOptionalAndZeroByDefault) {
  EXPECT_EQ(
      parse_calibration(R"({"sync_latency_ns": 70, "per_byte_ns": 0.03})", "c").task_overhead_ns,
      0.0);
  EXPECT_EQ(CostModel::ideal().task_overhead_ns, 0.0);
  EXPECT_EQ(parse_calibration(
                R"({"sync_latency_ns": 70, "per_byte_ns": 0.03, "task_overhead_ns": 61.5})", "c")
                .task_overhead_ns,
            61.5);
  EXPECT_EQ(parse_calibration(R"({"sync_latency_ns": 70, "per_byte_ns": 0.03})", "c")
                .mpi_message_overhead_ns,
            0.0);
  EXPECT_EQ(
      parse_calibration(
          R"({"sync_latency_ns": 70, "per_byte_ns": 0.03, "mpi_message_overhead_ns": 412.5})", "c")
          .mpi_message_overhead_ns,
      412.5);
  EXPECT_THROW(
      parse_calibration(
          R"({"sync_latency_ns": 1, "per_byte_ns": 0, "mpi_message_overhead_ns": -3})", "c"),
      InputError);
  EXPECT_THROW(parse_calibration(
                   R"({"sync_latency_ns": 1, "per_byte_ns": 0, "task_overhead_ns": "x"})", "c"),
               InputError);
}

TEST(SimulateTrace, BuiltinEngineIsTheScheduleSimulator) {
  Trace trace;
  trace.steps = {partition::testing::random_graph(3, 30, 6, true), partition::testing::random_graph(4, 30, 6, true)};
  const TracePartition tp = partition_trace(trace, "roundrobin", 3);
  const SimulatedPlatform p = on_file("", CostModel::defaults());
  const Prediction r = simulate_trace(trace, tp.assignment, SimulationEngine::builtin, p);
  ASSERT_EQ(r.steps.size(), 2u);
  for (std::size_t s = 0; s < 2; ++s)
    EXPECT_EQ(r.steps[s].makespan_ns,
              simulate(trace.steps[s], tp.assignment.steps[s], p.model).makespan_ns);
  EXPECT_EQ(r.makespan_ns, r.steps[0].makespan_ns + r.steps[1].makespan_ns);
  const nlohmann::json j = nlohmann::json::parse(prediction_json(r));
  EXPECT_EQ(j["engine"], "builtin");
  EXPECT_EQ(j["makespan_ns"], r.makespan_ns);
  EXPECT_EQ(j["per_step"][1]["makespan_ns"], r.steps[1].makespan_ns);
}

TEST(SimulateTrace, RefusesMoreProcessorsThanTheClusterHas) {
  Trace trace;
  trace.steps = {partition::testing::random_graph(5, 20, 4, false)};
  const TracePartition tp = partition_trace(trace, "roundrobin", 5);
  const SimulatedPlatform p = on_cluster(ClusterShape{2, 2}, CostModel::defaults());
  EXPECT_THROW(simulate_trace(trace, tp.assignment, SimulationEngine::builtin, p), Error);
  EXPECT_THROW(simulate_trace(trace, tp.assignment, SimulationEngine::simgrid, p), Error);
}

#if TGRAPH_HAVE_SIMGRID

// A writer of `bytes` on processor 0 and its reader on processor 1.
Trace writer_reader(std::uint64_t bytes, std::uint64_t host_ns = 0) {
  Builder b;
  const DatumId d = b.datum("d", bytes);
  b.task({{d, M::W}}, 1000);
  b.task({{d, M::R}}, 2000);
  Trace t;
  t.steps = {b.done()};
  t.steps[0].host_ns = host_ns;
  return t;
}

TraceAssignment split(std::uint32_t k, std::vector<ProcId> proc) {
  TraceAssignment a;
  a.k = k;
  a.steps = {Assignment{k, std::move(proc), {}}};
  return a;
}

TEST(SimgridEngine, ChargesLatencyPlusSizeOverBandwidthInsideAndBetweenNodes) {
  const CostModel m = links(100, 0.05, 2000, 0.5);
  const Trace t = writer_reader(1 << 20, 300);
  const TraceAssignment a = split(2, {0, 1});
  // One node of two cores: the loopback link, the bytes paid by the reader or the link.
  const double inside = 300 + 1000 + 100 + (1 << 20) * 0.05 + 2000;
  for (IntraNodeTransfer mode : {IntraNodeTransfer::reader, IntraNodeTransfer::link}) {
    const Prediction in =
        simulate_trace(t, a, SimulationEngine::simgrid, on_cluster(ClusterShape{1, 2}, m, mode));
    ASSERT_EQ(in.steps.size(), 1u);
    EXPECT_NEAR(static_cast<double>(in.steps[0].makespan_ns), inside, 2) << to_string(mode);
    EXPECT_EQ(in.steps[0].bytes, 1u << 20);
    EXPECT_EQ(in.steps[0].inter_node_bytes, 0u);
  }
  // The built-in simulator charges the same latency and bytes.
  const Prediction builtin = simulate_trace(t, a, SimulationEngine::builtin, on_file("", m));
  EXPECT_NEAR(static_cast<double>(builtin.steps[0].makespan_ns), inside, 2);
  // Two nodes of one core: two private links, the MPI latency and bandwidth.
  const Prediction between =
      simulate_trace(t, a, SimulationEngine::simgrid, on_cluster(ClusterShape{2, 1}, m));
  EXPECT_NEAR(static_cast<double>(between.steps[0].makespan_ns),
              300 + 1000 + 2000 + (1 << 20) * 0.5 + 2000, 2);
  EXPECT_EQ(between.steps[0].inter_node_messages, 1u);
  EXPECT_EQ(between.steps[0].inter_node_bytes, 1u << 20);
  EXPECT_EQ(between.hosts, 2u);
  EXPECT_EQ(between.cores, 2u);
}

TEST(SimgridEngine, TheReaderPaysInsideANodeUnlessTheLinkCarriesTheBytes) {
  // Processor 1 is busy with an unrelated 5000 ns task while the datum is on its way: when
  // the loopback link carries the bytes they overlap that task; when the reading core pays
  // them (the default, as the built-in simulator does) they come after it.
  CostModel m;
  m.sync_latency_ns = 100;
  m.per_byte_ns = 0.05;
  Builder b;
  const DatumId d = b.datum("d", 40000), e = b.datum("e", 8);
  b.task({{d, M::W}}, 1000);  // 0 on processor 0
  b.task({{e, M::W}}, 5000);  // 1 on processor 1
  b.task({{d, M::R}}, 2000);  // 2 on processor 1, after 1
  Trace t;
  t.steps = {b.done()};
  const TraceAssignment a = split(2, {0, 1, 1});
  SimulatedPlatform p = on_cluster(ClusterShape{1, 2}, m);
  const Prediction reader = simulate_trace(t, a, SimulationEngine::simgrid, p);
  EXPECT_EQ(reader.steps[0].makespan_ns, 5000u + 40000 / 20 + 2000);
  EXPECT_EQ(reader.steps[0].makespan_ns,
            simulate_trace(t, a, SimulationEngine::builtin, p).steps[0].makespan_ns);
  p.intra_node = IntraNodeTransfer::link;
  const Prediction link = simulate_trace(t, a, SimulationEngine::simgrid, p);
  EXPECT_EQ(link.steps[0].makespan_ns, 5000u + 2000);  // 1000 + 100 + 2000 < 5000
  EXPECT_EQ(link.steps[0].bytes, reader.steps[0].bytes);
}

// One writer of a 10,000-byte datum (500 ns), two readers (700 and 900 ns).
Trace one_writer_two_readers() {
  Builder b;
  const DatumId d = b.datum("d", 10000);
  b.task({{d, M::W}}, 500);
  b.task({{d, M::R}}, 700);
  b.task({{d, M::R}}, 900);
  Trace t;
  t.steps = {b.done()};
  return t;
}

TEST(SimgridEngine, SendsADatumVersionOnceToANodeForAllItsReaders) {
  // Processor 0 (node 0) writes d; processors 2 and 3 (both on node 1) read it: one
  // message between the nodes, its bytes once; each reader starts when it arrives.
  CostModel m;
  m.mpi_latency_ns = 1000;
  m.mpi_per_byte_ns = 0.1;
  const Trace t = one_writer_two_readers();
  const Prediction r = simulate_trace(t, split(4, {0, 2, 3}), SimulationEngine::simgrid,
                                      on_cluster(ClusterShape{2, 2}, m));
  EXPECT_EQ(r.steps[0].inter_node_messages, 1u);
  EXPECT_EQ(r.steps[0].inter_node_bytes, 10000u);
  EXPECT_NEAR(static_cast<double>(r.steps[0].makespan_ns), 500 + 1000 + 10000 * 0.1 + 900, 2);
}

TEST(SimgridEngine, ChargesEachMessageBetweenNodesToTheSenderAndToOneReceiver) {
  // As above, with 300 ns of processor time per message and side: the writer's instance
  // takes 500 + 300, the message 1000 + 1000, and processor 2 (the node's first receiver,
  // where the rank polls) 300 before its 700; processor 3 does not pay again.
  CostModel m;
  m.mpi_latency_ns = 1000;
  m.mpi_per_byte_ns = 0.1;
  m.mpi_message_overhead_ns = 300;
  const Trace t = one_writer_two_readers();
  const Prediction r = simulate_trace(t, split(4, {0, 2, 3}), SimulationEngine::simgrid,
                                      on_cluster(ClusterShape{2, 2}, m));
  EXPECT_EQ(r.message_overhead_ns, 300);
  EXPECT_NEAR(static_cast<double>(r.steps[0].makespan_ns), 500 + 300 + 2000 + 300 + 700, 2);
  // Inside one node nothing is a message: the same as without the overhead.
  CostModel none = m;
  none.mpi_message_overhead_ns = 0;
  const TraceAssignment in_node = split(2, {0, 1, 1});
  EXPECT_EQ(
      simulate_trace(t, in_node, SimulationEngine::simgrid, on_cluster(ClusterShape{1, 2}, m))
          .makespan_ns,
      simulate_trace(t, in_node, SimulationEngine::simgrid, on_cluster(ClusterShape{1, 2}, none))
          .makespan_ns);
}

TEST(SimgridEngine, RunsEachProcessorsTasksOneAfterTheOther) {
  // Four independent tasks of 1000 ns on one processor of a one-core host, and on two
  // processors of a two-core host: 4000 ns and 2000 ns, never shared CPU time.
  Builder b;
  for (int i = 0; i < 4; ++i) b.task({{b.datum(partition::testing::name("d", i), 8), M::W}}, 1000);
  Trace t;
  t.steps = {b.done()};
  const SimulatedPlatform one = on_cluster(ClusterShape{1, 1}, CostModel::defaults());
  EXPECT_EQ(simulate_trace(t, split(1, {0, 0, 0, 0}), SimulationEngine::simgrid, one).makespan_ns,
            4000u);
  const SimulatedPlatform two = on_cluster(ClusterShape{1, 2}, CostModel::defaults());
  EXPECT_EQ(simulate_trace(t, split(2, {0, 1, 0, 1}), SimulationEngine::simgrid, two).makespan_ns,
            2000u);
  // Three processors on one two-core host would share it: the engine's mapping gives
  // processor 2 the first core of node 1 instead.
  const SimulatedPlatform twonodes = on_cluster(ClusterShape{2, 2}, CostModel::defaults());
  EXPECT_EQ(
      simulate_trace(t, split(3, {0, 1, 2, 2}), SimulationEngine::simgrid, twonodes).makespan_ns,
      2000u);
}

// Random graphs with loops, several processor counts, steps of one trace: on one host with
// the reader paying for bytes, both engines impose the same precedence, program order, loop
// control, latencies and transfer costs, so the makespans agree to SimGrid's 1 ns timing
// precision per event, with the ideal model and with the default one.
TEST(SimgridEngine, EqualsTheBuiltinSimulatorOnOneHostOnRandomGraphs) {
  CostModel with_overhead = CostModel::defaults();
  with_overhead.task_overhead_ns = 37;
  with_overhead.source = "defaults + task overhead";
  for (const CostModel& model : {CostModel::ideal(), CostModel::defaults(), with_overhead})
    for (std::uint32_t k : {1u, 2u, 3u, 5u}) {
      Trace trace;
      for (std::uint64_t seed = 0; seed < 40; ++seed)
        trace.steps.push_back(partition::testing::random_graph(
            1000 * k + seed, 12 + static_cast<int>(seed % 20), 5, seed % 3 != 0));
      for (const char* method : {"roundrobin", "random", "list"}) {
        const TracePartition tp = partition_trace(trace, method, k);
        const SimulatedPlatform p = on_cluster(ClusterShape{1, k}, model);
        const Prediction b = simulate_trace(trace, tp.assignment, SimulationEngine::builtin, p);
        const Prediction s = simulate_trace(trace, tp.assignment, SimulationEngine::simgrid, p);
        ASSERT_EQ(b.steps.size(), s.steps.size());
        for (std::size_t i = 0; i < b.steps.size(); ++i) {
          // At most 1 ns of SimGrid's timing precision per task instance (loops run 1-4
          // times); a wrong order or a missed dependency costs tasks of up to 1000 ns.
          const std::uint64_t instances = trace.steps[i].tasks.size() * 4;
          EXPECT_NEAR(static_cast<double>(s.steps[i].makespan_ns),
                      static_cast<double>(b.steps[i].makespan_ns), static_cast<double>(instances))
              << model.source << " " << method << " k " << k << " step " << i;
          EXPECT_EQ(s.steps[i].bytes, b.steps[i].bytes) << method << " k " << k << " step " << i;
        }
      }
    }
}

TEST(SimgridEngine, ReportsADeadlockedOrder) {
  Builder b;
  const DatumId x = b.datum("x", 8), y = b.datum("y", 8);
  b.task({{x, M::W}}, 10);             // 0 on processor 0
  b.task({{x, M::R}, {y, M::W}}, 10);  // 1 on processor 1, needs 0
  b.task({{y, M::R}}, 10);             // 2 on processor 0, needs 1
  Trace t;
  t.steps = {b.done()};
  TraceAssignment a = split(2, {0, 1, 0});
  a.steps[0].order = {{2, 0}, {1}};  // processor 0 runs 2 before 0: it waits forever
  try {
    simulate_trace(t, a, SimulationEngine::simgrid,
                   on_cluster(ClusterShape{1, 2}, CostModel::defaults()));
    ADD_FAILURE() << "no deadlock reported";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("deadlocks"), std::string::npos) << e.what();
  }
}

class PlatformFiles : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = tgraph::test::scratch_dir("tgraph_platform_"); }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << text;
    return path;
  }
  std::filesystem::path dir_;
};

TEST_F(PlatformFiles, AWrittenPlatformGivesWhatTheClusterGives) {
  const Trace t = writer_reader(4096);
  const TraceAssignment a = split(3, {0, 2});
  const CostModel m = CostModel::defaults();
  const std::string file = write("p.xml", platform_xml({2, 2}, m));
  const Prediction from_file = simulate_trace(t, a, SimulationEngine::simgrid, on_file(file, m));
  const Prediction from_shape =
      simulate_trace(t, a, SimulationEngine::simgrid, on_cluster(ClusterShape{2, 2}, m));
  EXPECT_EQ(from_file.steps, from_shape.steps);
  EXPECT_EQ(from_file.steps[0].inter_node_messages, 1u);  // processor 2 is on node 1
}

TEST_F(PlatformFiles, MissingOrMalformedPlatformIsAnInputErrorNamingTheFile) {
  const Trace t = writer_reader(8);
  const TraceAssignment a = split(2, {0, 1});
  const std::string missing = (dir_ / "none.xml").string();
  const std::string garbage = write("bad.xml", "<platform version=\"4.1\"><zone id=");
  const std::string empty = write("empty.xml", "");
  for (const std::string& f : {missing, garbage, empty}) {
    try {
      simulate_trace(t, a, SimulationEngine::simgrid, on_file(f, CostModel::defaults()));
      ADD_FAILURE() << "accepted " << f;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  }
}

TEST_F(PlatformFiles, TooFewCoresIsAnError) {
  const Trace t = writer_reader(8);
  const std::string file = write("p.xml", platform_xml({1, 1}, CostModel::defaults()));
  EXPECT_THROW(simulate_trace(t, split(2, {0, 1}), SimulationEngine::simgrid,
                              on_file(file, CostModel::defaults())),
               Error);
}

#endif  // TGRAPH_HAVE_SIMGRID

}  // namespace
}  // namespace tgraph::model
