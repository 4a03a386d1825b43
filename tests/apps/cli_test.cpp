// SPDX-License-Identifier: MIT
// The `tgraph` command line: exit codes, one-line errors, capture -> info -> export.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <utility>

#include "tgraph/graph/timeline.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/version.hpp"
#include "../scratch_dir.hpp"
#include "cli_run.hpp"

namespace {

namespace fs = std::filesystem;

using Result = tgraph::test::CliResult;
using tgraph::test::slurp;

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = tgraph::test::scratch_dir("tgraph_cli_");
  }
  void TearDown() override { fs::remove_all(dir_); }

  Result run(const std::string& args) { return tgraph::test::run_tgraph(dir_, args); }
  // Runs `tgraph ARGS` expecting exit 0 and parses its standard output as JSON; null when the
  // run failed (the failure recorded), so that a caller's non-const j["key"] fails its checks.
  nlohmann::json run_json(const std::string& args) {
    const Result r = run(args);
    EXPECT_EQ(r.code, 0) << args << ": " << r.err;
    return r.code == 0 ? nlohmann::json::parse(r.out) : nlohmann::json();
  }
  static bool one_line(const std::string& s) {
    return !s.empty() && s.back() == '\n' && std::count(s.begin(), s.end(), '\n') == 1;
  }
  fs::path dir_;
};

TEST_F(Cli, UnknownVerbExits2WithOneLine) {
  const Result r = run("frobnicate");
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(one_line(r.err)) << r.err;
}

TEST_F(Cli, VersionPrintsTheProjectVersionFromVersionHeader) {
  const Result r = run("--version");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out, "tgraph " + std::string(tgraph::kVersionString) + "\n");
  // One source: the project version in CMakeLists.txt (TGRAPH_VERSION, set by CMake).
  EXPECT_EQ(tgraph::kVersionString, TGRAPH_VERSION);
  EXPECT_EQ(std::to_string(tgraph::kVersionMajor) + "." + std::to_string(tgraph::kVersionMinor) +
                "." + std::to_string(tgraph::kVersionPatch),
            TGRAPH_VERSION);
  EXPECT_EQ(tgraph::linked_version(), tgraph::kVersionString);
}

TEST_F(Cli, InfoOnMissingFileExits2NamingIt) {
  const Result r = run("info nowhere.tgt");
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("nowhere.tgt"), std::string::npos) << r.err;
}

TEST_F(Cli, InfoOnGarbageExits2WithOffset) {
  std::ofstream(dir_ / "garbage.tgt") << "this is not a trace at all, just text\n";
  const Result r = run("info garbage.tgt");
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("garbage.tgt: offset"), std::string::npos) << r.err;
}

TEST_F(Cli, UnknownSceneExits2) {
  const Result r = run("capture --scene no_such_scene --steps 2 -o x.tgt");
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "x.tgt"));
}

TEST_F(Cli, AModulesOptionErrorNamesTheFlag) {
  // The executor refuses threads = 0 naming its field; tgraph says the flag.
  ASSERT_EQ(run("capture --scene fig2 --steps 2 -o f.tgt").code, 0);
  const Result r = run("replay f.tgt --policy worksteal --threads 0");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "tgraph: --threads: must be at least 1\n");
  // StarPU's executor names its scheduler field (or the policy, in a build without StarPU).
  const Result s = run("replay f.tgt --policy starpu --threads 1 --starpu-sched no-such");
  EXPECT_EQ(s.code, 2);
  EXPECT_TRUE(one_line(s.err)) << s.err;
  EXPECT_TRUE(s.err.starts_with("tgraph: --starpu-sched: 'no-such' is not a StarPU scheduler") ||
              s.err.starts_with("tgraph: --policy: starpu needs StarPU"))
      << s.err;
}

TEST_F(Cli, ExperimentVizTimelineValidateAndDemoErrorsNameTheFlag) {
  // Each family of the modules' option errors (and of the lists the command line parses):
  // exit 2, one line, starting with the flag. None of them starts the work.
  ASSERT_EQ(run("capture --scene fig2 --steps 2 -o f.tgt").code, 0);
  ASSERT_EQ(run("replay f.tgt --threads 2 --steps 2 --repeat 1 --timeline r.json").code, 0);
  const std::pair<const char*, const char*> cases[] = {
      {"experiment independent --threads 1,,2", "tgraph: --threads 1,,2: expected counts"},
      {"experiment independent --threads 4-2", "tgraph: --threads 4-2: expected counts"},
      {"experiment metg --threads 2000", "tgraph: --threads 2000: expected counts"},
      {"experiment independent --methods owner,nosuch", "tgraph: --methods: unknown method 'nosuch'"},
      {"experiment scaling --methods sequential", "tgraph: --methods: sequential is every run's"},
      {"experiment metg --methods owner", "tgraph: --methods: unknown policy 'owner'"},
      {"experiment domain --subobjects 5", "tgraph: --subobjects: 5 is not a perfect square"},
      {"experiment medical --subobjects 4", "tgraph: --subobjects: applies to the domain"},
      {"experiment scaling --no-replay", "tgraph: --replay: the scaling experiment makes live"},
      {"experiment independent --steps 0", "tgraph: --steps: must be at least 1"},
      {"experiment scaling --repeat 0", "tgraph: --repeat: must be at least 1"},
      {"experiment independent --out f.tgt", "tgraph: --out: cannot create the results folder"},
      {"demo --steps 0", "tgraph: --steps: must be at least 1"},
      {"validate --scene fig2 --repeat 0", "tgraph: --repeat: must be at least 1"},
      {"viz f.tgt --collapse processor -o x.svg", "tgraph: --collapse: f.tgt step 0: processor"},
      {"viz f.tgt --max-nodes 2 -o x.svg", "tgraph: --max-nodes: f.tgt step 0: the picture"},
      {"timeline r.json --steps 3:1 -o x.svg", "tgraph: --steps 3:1: expected a:b"},
      {"timeline r.json --steps 7:9 -o x.svg", "tgraph: --steps: no task in steps 7 to 9"}};
  for (const auto& [args, start] : cases) {
    const Result r = run(args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_TRUE(one_line(r.err)) << args << ": " << r.err;
    EXPECT_EQ(r.err.rfind(start, 0), 0u) << args << ": " << r.err;
  }
  EXPECT_FALSE(fs::exists(dir_ / "x.svg"));
  // A good list: ranges and repeats, sorted once (metg's quick sweep of one policy: seconds).
  const nlohmann::json j =
      run_json("experiment metg --quick --threads 2,1-2 --methods sequential --out m --json");
  EXPECT_EQ(j["threads"], (nlohmann::json{1, 2}));
  EXPECT_EQ(j["command"], "tgraph experiment metg --quick --threads 1,2 --methods sequential --out m");
}

#ifdef TGRAPH_HAVE_ODE
// What ODE's scenes cannot honour is refused by flag, not ignored: ODE posts calls with
// dependencies and never the data they touch, and its runs keep no timeline.
TEST_F(Cli, OdeScenesRefuseTheFlagsTheyCannotHonour) {
  const std::pair<const char*, const char*> cases[] = {
      {"run --scene ode-piles --steps 2 --threads 2 --verify-accesses",
       "tgraph: --verify-accesses: ODE's calls declare no data accesses (ode-piles"},
      {"capture --scene ode-piles --steps 2 -o o.tgt --verify-accesses",
       "tgraph: --verify-accesses: ODE's calls declare no data accesses (ode-piles"},
      {"run --scene ode-heap --steps 2 --threads 2 --timeline t.json",
       "tgraph: --timeline: not written for ODE's scenes (ode-heap"}};
  for (const auto& [args, start] : cases) {
    const Result r = run(args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_TRUE(one_line(r.err)) << args << ": " << r.err;
    EXPECT_EQ(r.err.rfind(start, 0), 0u) << args << ": " << r.err;
  }
  EXPECT_FALSE(fs::exists(dir_ / "o.tgt"));
  EXPECT_FALSE(fs::exists(dir_ / "t.json"));
}
#endif

// The modules' option errors of generate, capture and partition, in the flags' words.
TEST_F(Cli, ModuleOptionErrorsOfGenerateCaptureAndPartitionNameTheFlags) {
  const std::pair<const char*, const char*> cases[] = {
      {"generate --tasks 10 --width 11 -o g.tgt", "--width: expected at most --tasks (10)"},
      {"generate --tasks 10 --pattern domain --iterations 0 -o g.tgt", "--iterations: "},
      {"capture --scene fig2 --steps 0 -o f.tgt", "--steps: must be at least 1"},
      {"capture --scene fig2 --steps 1", "--output: is required (or --no-capture)"},
      {"capture --scene fig2 --dt -1 --steps 1 -o f.tgt", "--dt: must be > 0"},
      {"capture --scene cloth128 --subobjects 3 --steps 1 -o f.tgt", "--subobjects: "},
      {"compare g.tgt --methods list -k 0", "-k: expected values >= 1"},
      {"partition g.tgt -m list -k 0", "-k: expected at least 1"},
      {"partition g.tgt -m list -k 2 --order fifo", "--order: "},
      {"compare g.tgt --methods list -k 2 --sticky-migration-cost -1",
       "--sticky-migration-cost: expected values >= 0"},
  };
  ASSERT_EQ(run("generate --tasks 12 --width 4 -o g.tgt").code, 0);
  for (const auto& [args, starts] : cases) {
    const Result r = run(args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_EQ(r.err.rfind(std::string("tgraph: ") + starts, 0), 0u) << args << ": " << r.err;
    EXPECT_TRUE(one_line(r.err)) << r.err;
  }
}

TEST_F(Cli, VizOfAStepTooLargeToDrawTaskByTaskDrawsItsKindsAndSaysSo) {
  ASSERT_EQ(run("generate --tasks 2500 --pattern stencil -o big.tgt").code, 0);
  const Result r = run("viz big.tgt -o big.svg");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(one_line(r.err)) << r.err;
  EXPECT_EQ(r.err.rfind("tgraph viz: big.tgt step 0: 2500 tasks, too many", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("drawn collapsed by kind"), std::string::npos) << r.err;
  EXPECT_NE(slurp(dir_ / "big.svg").find("<svg"), std::string::npos);
  // Asked to draw every task, or under a limit: refused as before, nothing written.
  for (const char* args :
       {"viz big.tgt --collapse none -o none.svg", "viz big.tgt --max-nodes 2000 -o none.svg"}) {
    const Result s = run(args);
    EXPECT_EQ(s.code, 2) << args;
    EXPECT_EQ(s.err.rfind("tgraph: --max-nodes: big.tgt step 0: the picture", 0), 0u) << s.err;
  }
  EXPECT_FALSE(fs::exists(dir_ / "none.svg"));
}

TEST_F(Cli, ExportRejectsStepOutOfRangeAndBadFormat) {
  ASSERT_EQ(run("capture --scene fig2 --steps 3 -o f.tgt").code, 0);
  Result r = run("export f.tgt --step 3 --format json");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "tgraph: --step: trace f.tgt has 3 steps, no step 3\n");
  r = run("export f.tgt --format dot");
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(one_line(r.err)) << r.err;
}

// Figure 2 of the paper: two objects A and B joined by an interaction force, explicit Euler.
// Per step: resetForce x2, addForce x2 (own forces), addForce on the interaction (reads both
// x, CW into both f), updateVelocity x2, updatePosition x2 = 9 tasks over 6 data (x, v, f of
// each object). Edges: reset -> own addForce and reset -> interaction (WAW, 4), both force
// writers -> updateVelocity (RAW, 4), interaction -> updatePosition (WAR on x, 2),
// updateVelocity -> updatePosition (RAW on v, 2): 12 edges, no loops.
TEST_F(Cli, Fig2CaptureInfoReportsTheFigure2Graph) {
  ASSERT_EQ(run("capture --scene fig2 --steps 10 -o f.tgt").code, 0);
  auto j = run_json("info f.tgt --json");
  EXPECT_EQ(j["steps"], 10);
  EXPECT_EQ(j["tasks"], 90);
  EXPECT_EQ(j["edges"], 120);
  EXPECT_EQ(j["data"], 6);
  EXPECT_EQ(j["loops"], 0);
  EXPECT_EQ(j["distinct_structures"], 1);
  EXPECT_EQ(j["contact_changes"], 0);
  ASSERT_EQ(j["per_step"].size(), 10u);

  // Work and span from the recorded costs, computed by hand on the Figure 2 structure.
  const tgraph::Trace trace = tgraph::read_trace((dir_ / "f.tgt").string());
  std::uint64_t work_total = 0, span_total = 0;
  for (std::size_t s = 0; s < trace.steps.size(); ++s) {
    const auto& g = trace.steps[s];
    ASSERT_EQ(g.tasks.size(), 9u);
    auto c = [&](int t) { return g.tasks[static_cast<std::size_t>(t)].cost_ns; };
    auto kind = [&](int t) { return g.kind_name(static_cast<tgraph::TaskId>(t)); };
    ASSERT_EQ(kind(4), "addForce");
    ASSERT_EQ(g.tasks[4].access_count, 4u);  // the interaction
    // Finish times along the figure's dependencies.
    const auto e0 = c(0), e1 = c(1), e2 = e0 + c(2), e3 = e1 + c(3), e4 = std::max(e0, e1) + c(4);
    const auto e5 = std::max(e2, e4) + c(5), e6 = std::max(e3, e4) + c(6);
    const auto e7 = std::max(e4, e5) + c(7), e8 = std::max(e4, e6) + c(8);
    const auto span = std::max({e0, e1, e2, e3, e4, e5, e6, e7, e8});
    std::uint64_t work = 0;
    for (int t = 0; t < 9; ++t) work += c(t);
    EXPECT_EQ(j["per_step"][s]["span_ns"], span) << "step " << s;
    EXPECT_EQ(j["per_step"][s]["work_ns"], work) << "step " << s;
    EXPECT_EQ(j["per_step"][s]["edges"], 12);
    work_total += work;
    span_total += span;
  }
  EXPECT_EQ(j["work_ns"], work_total);
  EXPECT_EQ(j["span_ns"], span_total);
  EXPECT_DOUBLE_EQ(j["parallelism"].get<double>(),
                   static_cast<double>(work_total) / static_cast<double>(span_total));
}

TEST_F(Cli, ExportedGraphsAreAcceptedByGpmetisAndScotchGpart) {
  ASSERT_EQ(run("capture --scene fig2 --steps 2 -o f.tgt").code, 0);
  ASSERT_EQ(run("export f.tgt --step 1 --format metis -o g.metis").code, 0);
  ASSERT_EQ(run("export f.tgt --step 1 --format scotch -o g.grf").code, 0);
  const std::string d = dir_.string();
  ASSERT_EQ(std::system(("gpmetis '" + d + "/g.metis' 2 >'" + d + "/gpmetis.out' 2>&1").c_str()), 0)
      << slurp(dir_ / "gpmetis.out");
  EXPECT_NE(slurp(dir_ / "gpmetis.out").find("Edgecut:"), std::string::npos);
  EXPECT_TRUE(fs::exists(dir_ / "g.metis.part.2"));
  ASSERT_EQ(std::system(("scotch_gpart 2 '" + d + "/g.grf' '" + d + "/g.map' >'" + d + "/gpart.out' 2>&1").c_str()), 0)
      << slurp(dir_ / "gpart.out");
  // The mapping file: vertex count, then one "vertex part" line per vertex.
  std::ifstream map(dir_ / "g.map");
  int n = 0;
  map >> n;
  EXPECT_EQ(n, 9);
}

TEST_F(Cli, ExportWritesNothingOnBadInput) {
  std::ofstream(dir_ / "bad.tgt") << "TGT";
  const Result r = run("export bad.tgt --format metis -o out.metis");
  EXPECT_EQ(r.code, 2);
  EXPECT_FALSE(fs::exists(dir_ / "out.metis"));
}

TEST_F(Cli, DemoComparesEveryStrategyWithTheBaselinesAndWritesAReport) {
  auto j = run_json("demo --scene fig2 --steps 3 --repeat 1 --threads 2 --out d --json");
  std::vector<std::string> names;
  for (const auto& row : j["rows"]) {
    names.push_back(row["method"]);
    EXPECT_TRUE(row["replay_failure"].is_null()) << row.dump();  // a failed row fails the demo
    EXPECT_GT(row["wall_ns"].get<double>(), 0.0) << row.dump();
    EXPECT_GT(row["sequential_wall_ns"].get<double>(), 0.0) << row.dump();
    if (row["partitioned"].get<bool>()) {
      EXPECT_GE(row["imbalance"].get<double>(), 1.0) << row.dump();
    }
  }
  for (const char* m : {"owner", "metis", "scotch", "sticky", "list", "roundrobin", "random", "worksteal", "barrier"})
    EXPECT_NE(std::find(names.begin(), names.end(), m), names.end()) << m;
#ifdef TGRAPH_HAVE_STARPU
  EXPECT_NE(std::find(names.begin(), names.end(), "starpu"), names.end());
#endif
  EXPECT_TRUE(fs::exists(dir_ / "d" / "fig2.tgt"));
  const std::string html = slurp(dir_ / "d" / "report.html");
  EXPECT_NE(html.find("<table>"), std::string::npos);
  EXPECT_NE(html.find("worksteal"), std::string::npos);
}

// A step whose tasks have no object (kNoObject tasks and data, as an engine outside physics
// declares them): a setup task writes a shared table, then `layers` layers of `width` tasks
// each read the table and the data of two tasks of the layer before and write their own.
// Owner-compute by data affinity alone would follow the table onto one processor.
void write_objectless_trace(const fs::path& path, int layers, int width, std::uint64_t cost_ns) {
  tgraph::Trace trace;
  trace.header.scene = "layers";
  trace.header.engine = "cli_test";
  tgraph::StepGraph& g = trace.steps.emplace_back();
  const tgraph::KindId k = g.intern_kind("cell");
  g.data.push_back({"table", tgraph::kNoObject, 65536});
  g.add_task(g.intern_kind("setup"), tgraph::kNoObject,
             std::vector<tgraph::Access>{{0, tgraph::AccessMode::W}}, cost_ns, 999999);
  for (int l = 0; l < layers; ++l)
    for (int i = 0; i < width; ++i) {
      const auto d = static_cast<tgraph::DatumId>(g.data.size());
      g.data.push_back({"d" + std::to_string(l) + "_" + std::to_string(i), tgraph::kNoObject, 64});
      std::vector<tgraph::Access> acc{{d, tgraph::AccessMode::W}, {0, tgraph::AccessMode::R}};
      if (l > 0) {
        const auto prev = static_cast<tgraph::DatumId>(1 + (l - 1) * width);
        acc.push_back({static_cast<tgraph::DatumId>(prev + i), tgraph::AccessMode::R});
        acc.push_back({static_cast<tgraph::DatumId>(prev + (i + 1) % width), tgraph::AccessMode::R});
      }
      g.add_task(k, tgraph::kNoObject, acc, cost_ns, static_cast<tgraph::StableKey>(d + 1));
    }
  tgraph::write_trace(path.string(), trace);
}

TEST_F(Cli, OwnerOnAGraphWithoutObjectsFallsBackToListSchedulingAndSaysSo) {
  write_objectless_trace(dir_ / "t.tgt", 4, 8, 1000);
  Result r = run("partition t.tgt --method owner -k 2 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("tgraph: warning: owner: the tasks have no objects"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("list"), std::string::npos) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["placed_by"], "list");
  EXPECT_EQ(j["warnings"].size(), 1u);
  // A strategy that leaves a processor empty is reported too.
  r = run("partition t.tgt --method single -k 2");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("single leaves 1 of 2 processors without tasks"), std::string::npos) << r.err;
}

TEST_F(Cli, ReplayWithoutAnAssignmentUsesEveryThreadOnAGraphWithoutObjectsAndNamesTheStrategy) {
  write_objectless_trace(dir_ / "t.tgt", 4, 8, 1000);
  // No stealing: which thread runs a task must be the assignment's (a thread late to start
  // would otherwise see the other take all its tasks, under ASan).
  Result r = run("replay t.tgt --threads 2 --repeat 1 --no-pin --no-steal --json");
  ASSERT_EQ(r.code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["assignment"], "list (computed, default for a trace without objects)");
  EXPECT_TRUE(j["warnings"].empty()) << j["warnings"].dump();
  for (const auto& t : j["per_step"][0]["threads"]) EXPECT_GT(t["tasks"].get<int>(), 0) << j.dump();
  // Named explicitly, owner falls back and the assignment says whose strategy ran.
  r = run("replay t.tgt --threads 2 --repeat 1 --no-pin --method owner --json");
  ASSERT_EQ(r.code, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["assignment"], "list (computed, fallback of owner)");
  EXPECT_EQ(j["warnings"].size(), 1u);
  EXPECT_NE(r.err.find("warning: owner"), std::string::npos) << r.err;
  // On a physics trace the default stays owner.
  ASSERT_EQ(run("capture --scene fig2 --steps 2 -o f.tgt").code, 0);
  r = run("replay f.tgt --threads 2 --repeat 1 --no-pin --json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["assignment"], "owner (computed, default)");
}

TEST_F(Cli, InfoUnitCostGivesTheSpanInTasks) {
  write_objectless_trace(dir_ / "t.tgt", 5, 8, 0);  // no costs recorded
  Result r = run("info t.tgt --unit-cost --json");
  ASSERT_EQ(r.code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["span_tasks"], 6);  // setup, then one task per layer
  EXPECT_EQ(j["work_tasks"], 41);
  EXPECT_EQ(j["span_tasks_max"], 6);
  EXPECT_EQ(j["per_step"][0]["span_tasks"], 6);
  EXPECT_DOUBLE_EQ(j["unit_parallelism"].get<double>(), 41.0 / 6.0);
  // The text never claims a span of 0 ms for a trace without costs: it gives the tasks.
  r = run("info t.tgt");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.find("0.000 ms"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("span (unit)    6 tasks"), std::string::npos) << r.out;
  // A timed trace: the totals say they sum over steps, with the longest step's span.
  ASSERT_EQ(run("capture --scene fig2 --steps 3 -o f.tgt").code, 0);
  r = run("info f.tgt --json");
  j = nlohmann::json::parse(r.out);
  std::uint64_t longest = 0;
  for (const auto& st : j["per_step"]) longest = std::max(longest, st["span_ns"].get<std::uint64_t>());
  EXPECT_EQ(j["span_max_ns"], longest);
  EXPECT_FALSE(j.contains("span_tasks"));  // only with --unit-cost
  r = run("info f.tgt");
  EXPECT_NE(r.out.find("sum of the steps' critical paths; longest step"), std::string::npos) << r.out;
}

TEST_F(Cli, SequentialReplayIsItsOwnBaselineWithSpeedupOne) {
  ASSERT_EQ(run("capture --scene fig2 --steps 2 -o f.tgt").code, 0);
  auto j = run_json("replay f.tgt --policy sequential --repeat 1 --json");
  EXPECT_EQ(j["speedup"], 1.0);
  EXPECT_EQ(j["sequential_wall_ns"], j["wall_ns"]);
}

// `replay --timeline` and `--chrome` write the same observed pass: one Chrome slice per task
// instance (named by its kind, on its thread, of its duration) and per wait, in order.
TEST_F(Cli, ReplayChromeTraceHasOneSlicePerTimelineEvent) {
  ASSERT_EQ(run("capture --scene fig2 --steps 3 -o f.tgt").code, 0);
  const Result r = run("replay f.tgt --threads 2 --repeat 1 --timeline r.json --chrome c.json");
  ASSERT_EQ(r.code, 0) << r.err;
  // The timeline file is gzip-compressed columns: read it as tgraph does.
  const tgraph::Timeline tl = tgraph::read_timeline((dir_ / "r.json").string());
  const nlohmann::json t = nlohmann::json::parse(tgraph::timeline_json(tl));
  const nlohmann::json c = nlohmann::json::parse(slurp(dir_ / "c.json"));
  EXPECT_EQ(t.at("threads"), 2u);
  EXPECT_EQ(t.at("steps"), 3u);
  ASSERT_FALSE(t.at("tasks").empty());
  std::size_t slices = 0, waits = 0, names = 0;
  for (const auto& e : c.at("traceEvents")) {
    if (e["ph"] == "X" && e["cat"] == "wait") ++waits;
    else if (e["ph"] == "X") {
      ASSERT_LT(slices, t["tasks"].size());
      const nlohmann::json& task = t["tasks"][slices++];
      EXPECT_EQ(e["name"], task["kind"]);
      EXPECT_EQ(e["tid"], task["thread"]);
      EXPECT_EQ(e["cat"], task["origin"].is_null() ? "reducer" : "task");
      EXPECT_DOUBLE_EQ(e["dur"].get<double>(),
                       static_cast<double>(task["end_ns"].get<std::int64_t>() -
                                           task["start_ns"].get<std::int64_t>()) / 1000);
    }
    if (e["ph"] == "M") ++names;
  }
  EXPECT_EQ(slices, t["tasks"].size());
  EXPECT_EQ(waits, t["waits"].size());
  EXPECT_EQ(names, 2u);
}

TEST_F(Cli, BarrierRuleFlagChoosesThePhasesAndRejectsUnknownRules) {
  ASSERT_EQ(run("capture --scene fig2 --steps 2 -o f.tgt").code, 0);
  for (const char* rule : {"level", "operation"}) {
    const Result r = run(std::string("replay f.tgt --policy barrier --threads 2 --repeat 1 --no-pin --barrier-rule ") + rule);
    EXPECT_EQ(r.code, 0) << rule << ": " << r.err;
  }
  const Result bad = run("replay f.tgt --policy barrier --barrier-rule task");
  EXPECT_EQ(bad.code, 2);
  EXPECT_TRUE(one_line(bad.err)) << bad.err;
  EXPECT_NE(bad.err.find("--barrier-rule"), std::string::npos) << bad.err;
}

// `--reduce-scope per-thread` gives a dynamic policy one temporary per thread (the JSON says
// so); the partition policy refuses it, and so does `run --check` (a bit-for-bit comparison
// that no reference reproduces for sums in the run's order), each in one line naming the flag.
TEST_F(Cli, ReduceScopeFlagReachesTheDynamicPoliciesOnly) {
  ASSERT_EQ(run("capture --scene fig2 --steps 2 -o f.tgt").code, 0);
  for (const char* scope : {"per-writer", "per-thread"}) {
    const Result r = run(std::string("replay f.tgt --policy worksteal --threads 2 --repeat 1 "
                                     "--no-pin --json --reduce-scope ") + scope);
    ASSERT_EQ(r.code, 0) << scope << ": " << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["reduce_scope"], scope);
  }
  for (const char* bad : {"replay f.tgt --policy partition --threads 2 --reduce-scope per-thread",
                          "replay f.tgt --policy worksteal --reduce-scope per-task",
                          "run --scene fig2 --steps 1 --threads 2 --method worksteal --check "
                          "--reduce-scope per-thread"}) {
    const Result r = run(bad);
    EXPECT_EQ(r.code, 2) << bad;
    EXPECT_TRUE(one_line(r.err)) << r.err;
    EXPECT_NE(r.err.find("--reduce-scope"), std::string::npos) << r.err;
  }
}

// `run` takes `partition`'s strategy flags: they reach the live partitioner (a calibration
// file that does not exist fails when the strategy loads its cost model), are range-checked,
// and a run with other phases still matches the sequential state bit for bit.
// `partition` reports one edge cut for every method: the library graph's cut of each step's
// assignment (METIS's units), summed over the steps; sticky's is no longer its step 0 alone.
TEST_F(Cli, PartitionEdgecutIsTheSameMeasureForEveryMethodAndStep) {
  ASSERT_EQ(run("capture --scene falling --steps 4 -o fp.tgt").code, 0);
  for (const char* method : {"metis", "sticky", "owner"}) {
    const auto j = run_json(std::string("partition fp.tgt -k 2 --json --method ") + method);
    ASSERT_EQ(j["per_step"].size(), 4u) << method;
    std::int64_t sum = 0;
    for (const auto& st : j["per_step"]) {
      ASSERT_TRUE(st.contains("edgecut")) << method << " step " << st["step"];
      sum += st["edgecut"].get<std::int64_t>();
    }
    EXPECT_EQ(j["edgecut"].get<std::int64_t>(), sum) << method;
  }
  const Result text = run("partition fp.tgt -k 2 --method sticky");
  ASSERT_EQ(text.code, 0) << text.err;
  EXPECT_NE(text.out.find("summed over the steps"), std::string::npos) << text.out;
}

TEST_F(Cli, RunTakesThePartitioningFlags) {
  const std::string live = "run --scene fig2 --threads 2 --method sticky --steps 2 --no-pin --json ";
  const Result missing = run(live + "--calibration nope.json");
  EXPECT_EQ(missing.code, 2);
  EXPECT_TRUE(one_line(missing.err)) << missing.err;
  EXPECT_NE(missing.err.find("nope.json"), std::string::npos) << missing.err;
  const Result share = run(live + "--loop-share 1.5");
  EXPECT_EQ(share.code, 2);
  EXPECT_NE(share.err.find("--loop-share"), std::string::npos) << share.err;
  const auto j = run_json(live + "--phases 3 --loop-share 0.5 --objective vol --check");
  EXPECT_EQ(j["check"], "identical");
}

TEST_F(Cli, CapturePassesKeepTheGraphAndRejectZero) {
  Result r = run("capture --scene fig2 --steps 3 --cost-passes 3 -o f3.tgt --json");
  ASSERT_EQ(r.code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["cost_passes"], 3);
  EXPECT_EQ(j["single_pass_runs"], 0);
  ASSERT_EQ(run("capture --scene fig2 --steps 3 -o f1.tgt").code, 0);
  const auto a = nlohmann::json::parse(run("info f1.tgt --json").out);
  const auto b = nlohmann::json::parse(run("info f3.tgt --json").out);
  EXPECT_EQ(a["tasks"], b["tasks"]);
  EXPECT_EQ(a["edges"], b["edges"]);
  EXPECT_EQ(a["distinct_structures"], b["distinct_structures"]);
  r = run("capture --scene fig2 --steps 3 --cost-passes 0 -o f0.tgt");
  EXPECT_EQ(r.code, 2);
  EXPECT_FALSE(fs::exists(dir_ / "f0.tgt"));
}

TEST_F(Cli, SimulateJsonIsOneParsableObjectAndBadPlatformsExit2) {
  ASSERT_EQ(run("capture --scene fig2 --steps 3 -o f.tgt").code, 0);
  ASSERT_EQ(run("partition f.tgt -m metis -k 4 -o f.tga").code, 0);
  const Result b = run("simulate f.tgt f.tga --engine builtin --json");
  ASSERT_EQ(b.code, 0) << b.err;
  const auto jb = nlohmann::json::parse(b.out);
  EXPECT_EQ(jb["engine"], "builtin");
  EXPECT_EQ(jb["per_step"].size(), 3u);
  EXPECT_EQ(jb["lowered"], false);
  const Result l = run("simulate f.tgt f.tga --engine builtin --lower --json");
  ASSERT_EQ(l.code, 0) << l.err;
  const auto jl = nlohmann::json::parse(l.out);
  EXPECT_EQ(jl["lowered"], true);
  EXPECT_EQ(jl["per_step"].size(), 3u);
  const Result none = run("simulate f.tgt f.tga --engine simgrid");
  EXPECT_EQ(none.code, 2);
  EXPECT_EQ(none.err.rfind("tgraph: --engine: simgrid ", 0), 0u) << none.err;
  EXPECT_TRUE(one_line(none.err)) << none.err;
  for (const char* bad : {"--cluster 4", "--cluster 0x4", "--cluster 1x3"}) {
    const Result r = run(std::string("simulate f.tgt f.tga --engine simgrid ") + bad);
    EXPECT_EQ(r.code, 2) << bad;
    if (std::string(bad) != "--cluster 1x3") {  // that one is well formed but too small
      EXPECT_EQ(r.err.rfind("tgraph: --cluster: expected ", 0), 0u) << r.err;
    }
    EXPECT_TRUE(one_line(r.err)) << bad << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << bad;
  }
#ifdef TGRAPH_HAVE_SIMGRID
  const Result s = run("simulate f.tgt f.tga --engine simgrid --cluster 2x2 --json");
  ASSERT_EQ(s.code, 0) << s.err;
  EXPECT_TRUE(one_line(s.out)) << s.out;
  const auto js = nlohmann::json::parse(s.out);
  EXPECT_EQ(js["engine"], "simgrid");
  ASSERT_EQ(js["per_step"].size(), 3u);
  std::uint64_t sum = 0;
  for (const auto& st : js["per_step"]) sum += st["makespan_ns"].get<std::uint64_t>();
  EXPECT_EQ(js["makespan_ns"].get<std::uint64_t>(), sum);
  const Result no_nodes = run("platform --nodes 0 --cores 2 -o p.xml");
  EXPECT_EQ(no_nodes.code, 2);
  EXPECT_EQ(no_nodes.err, "tgraph: --nodes: expected 1 to 1048576, found 0\n");
  ASSERT_EQ(run("platform --nodes 2 --cores 2 -o p.xml").code, 0);
  const Result p = run("simulate f.tgt f.tga --engine simgrid --platform p.xml --json");
  ASSERT_EQ(p.code, 0) << p.err;
  EXPECT_EQ(nlohmann::json::parse(p.out)["makespan_ns"], js["makespan_ns"]);
  std::ofstream(dir_ / "bad.xml") << "<platform version=";
  for (const char* bad : {"--platform bad.xml", "--platform none.xml"}) {
    const Result r = run(std::string("simulate f.tgt f.tga --engine simgrid ") + bad + " --json");
    EXPECT_EQ(r.code, 2) << bad;
    EXPECT_TRUE(one_line(r.err)) << bad << ": " << r.err;
    EXPECT_NE(r.err.find(".xml"), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << bad << ": " << r.out;
  }
#endif
}

}  // namespace
