// SPDX-License-Identifier: MIT
// Step graph pictures: golden DOT text, dot's acceptance, collapsed totals, refusals, the
// critical path.
#include "tgraph/viz/graph_view.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <regex>
#include <set>
#include <sstream>

#include "../option_error.hpp"
#include "../partition/test_graphs.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/graph/metrics.hpp"
#include "tgraph/viz/critical_path.hpp"
#include "tgraph/viz/graphviz.hpp"
#include "scene_traces.hpp"

namespace tgraph::viz {
namespace {

using partition::testing::Builder;
using M = AccessMode;

StepGraph capture_step(const std::string& scene_name, int step) {
  return testing::scene_step(scene_name, step);
}

// fig2's step 1 with costs replaced by 10 ns x (task + 1): captured costs are measured times,
// the golden files compare structure, labels and styles.
StepGraph fig2_fixed_costs() {
  StepGraph g = capture_step("fig2", 1);
  for (TaskId t = 0; t < g.tasks.size(); ++t) g.tasks[t].cost_ns = 10 * (t + 1);
  return g;
}

// fig2 on 2 processors: object A's tasks and the interaction on p0, object B's on p1.
Assignment fig2_assignment(const StepGraph& g) {
  Assignment a;
  a.k = 2;
  for (const Task& t : g.tasks) a.proc.push_back(g.objects[t.object].name == "B" ? 1 : 0);
  return a;
}

// A hand-made graph: two bodies accumulate (CW) into a shared force, then a loop of 3
// iterations (solve, dot product by CW into a scalar, the break reading the condition).
StepGraph cw_loop_graph() {
  Builder b;
  b.g.kinds = {"force", "solve", "dot", "check", "update"};
  const ObjectId o0 = b.object("body0"), o1 = b.object("body1");
  const DatumId f = b.datum("f", 96), x0 = b.datum("x0", 48, o0), x1 = b.datum("x1", 48, o1);
  const DatumId alpha = b.datum("alpha", 8), cond = b.datum("cond", 1);
  auto task = [&](std::uint32_t kind, ObjectId o, std::vector<Access> acc, std::uint64_t cost) {
    const auto t = static_cast<TaskId>(b.g.tasks.size());
    return b.g.add_task(kind, o, acc, cost, 100 + t);
  };
  task(0, o0, {{f, M::CW}, {x0, M::R}}, 30);
  task(0, o1, {{f, M::CW}, {x1, M::R}}, 40);
  const TaskId first = task(1, o0, {{x0, M::RW}, {f, M::R}}, 20);
  task(1, o1, {{x1, M::RW}, {f, M::R}}, 25);
  task(2, o0, {{alpha, M::CW}, {x0, M::R}}, 5);
  task(2, o1, {{alpha, M::CW}, {x1, M::R}}, 5);
  task(3, kNoObject, {{cond, M::W}, {alpha, M::R}}, 2);
  const TaskId brk = task(3, kNoObject, {{cond, M::R}}, 1);
  b.loop(cond, first, brk + 1, 3);
  task(4, o0, {{x0, M::RW}}, 10);
  return b.done();
}

Assignment by_object(const StepGraph& g) {
  Assignment a;
  a.k = 2;
  for (const Task& t : g.tasks) a.proc.push_back(t.object == 1 ? 1 : 0);
  return a;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Compares with tests/viz/golden/<name>.dot (TGRAPH_UPDATE_GOLDEN=1 rewrites it).
void expect_golden(const std::string& name, const std::string& dot) {
  const std::string path = std::string(TGRAPH_VIZ_GOLDEN) + "/" + name + ".dot";
  if (std::getenv("TGRAPH_UPDATE_GOLDEN")) write_file_atomic(path, dot);
  ASSERT_TRUE(std::filesystem::exists(path))
      << path << " missing (TGRAPH_UPDATE_GOLDEN=1 writes it)";
  EXPECT_EQ(dot, read_text(path)) << "DOT differs from " << path;
}

// `dot -Tsvg` accepts the text and writes an SVG document.
void expect_dot_accepts(const std::string& dot, const std::string& name) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("tgraph_viz_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string in = (dir / (name + ".dot")).string(), out = (dir / (name + ".svg")).string();
  write_file_atomic(in, dot);
  const std::string cmd =
      std::string(TGRAPH_DOT) + " -Tsvg '" + in + "' -o '" + out + "' 2>/dev/null";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << name;
  EXPECT_NE(read_text(out).find("<svg"), std::string::npos) << name;
  std::filesystem::remove_all(dir);
}

TEST(GraphView, Fig2MatchesItsGoldenDot) {
  const StepGraph g = fig2_fixed_costs();
  ViewOptions o;
  o.title = "fig2, step 1";
  const std::string dot = to_dot(make_graph_view(g, o));
  expect_golden("fig2", dot);
  expect_dot_accepts(dot, "fig2");
}

TEST(GraphView, Fig2OnTwoProcessorsHasTwoFillsAndRedCrossingEdges) {
  const StepGraph g = fig2_fixed_costs();
  const Assignment a = fig2_assignment(g);
  ViewOptions o;
  o.assignment = &a;
  o.title = "fig2, step 1, by object on 2 processors";
  const GraphView v = make_graph_view(g, o);
  std::set<ProcId> fills;
  std::size_t signals = 0, waits = 0, reducers = 0, cross = 0;
  for (const ViewNode& n : v.nodes) {
    if (n.kind == NodeKind::kTask) fills.insert(n.procs.at(0).proc);
    signals += n.kind == NodeKind::kSignal;
    waits += n.kind == NodeKind::kWait;
    reducers += n.kind == NodeKind::kReducer;
  }
  for (const ViewEdge& e : v.edges) cross += e.cross_deps > 0;
  EXPECT_EQ(fills, (std::set<ProcId>{0, 1}));
  // B.f's CW group (addForce@B on p1, addForce@AB on p0) spans both processors: one reducer.
  EXPECT_EQ(reducers, 1u);
  EXPECT_GT(signals, 0u);
  EXPECT_EQ(signals, waits);
  EXPECT_EQ(cross, waits);  // each crossing edge runs signal -> wait
  const std::string dot = to_dot(v);
  EXPECT_NE(dot.find("#E69F00"), std::string::npos);  // p0 fill
  EXPECT_NE(dot.find("#56B4E9"), std::string::npos);  // p1 fill
  EXPECT_NE(dot.find("#D55E00"), std::string::npos);  // crossing edges
  expect_golden("fig2_k2", dot);
  expect_dot_accepts(dot, "fig2_k2");
}

TEST(GraphView, CwLoopGraphMatchesItsGoldenDot) {
  const StepGraph g = cw_loop_graph();
  ASSERT_EQ(g.validate(), "");
  const Assignment a = by_object(g);
  ViewOptions o;
  o.assignment = &a;
  o.critical_path = true;
  o.title = "cw + loop";
  const GraphView v = make_graph_view(g, o);
  ASSERT_EQ(v.clusters.size(), 1u);
  EXPECT_EQ(v.clusters[0].label, "loop 0: 3 iterations (max 100)");
  const std::string dot = to_dot(v);
  expect_golden("cw_loop", dot);
  expect_dot_accepts(dot, "cw_loop");
  for (Collapse c : {Collapse::kObject, Collapse::kKind, Collapse::kProcessor, Collapse::kLoop}) {
    o.collapse = c;
    expect_dot_accepts(to_dot(make_graph_view(g, o)), "cw_loop_" + std::string(to_string(c)));
  }
}

TEST(GraphView, RendersSvgThroughLibgvc) {
  const StepGraph g = cw_loop_graph();
  ViewOptions o;
  const std::string svg = render_graph(make_graph_view(g, o), GraphFormat::kSvg);
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  EXPECT_NE(svg.find("loop 0: 3 iterations"), std::string::npos);
}

TEST(GraphView, TraceStepViewTitlesTheFileTheStepAndTheAssignment) {
  Trace trace;
  trace.steps = {fig2_fixed_costs(), fig2_fixed_costs()};
  TraceAssignment as;
  as.method = "owner";
  as.k = 2;
  as.steps = {fig2_assignment(trace.steps[0]), fig2_assignment(trace.steps[1])};
  const std::string path = "/data/run/fig2.tgt";
  GraphView v = trace_step_view(trace, path, 1, nullptr, {});
  EXPECT_EQ(v.title.at(0), "fig2.tgt, step 1");
  EXPECT_EQ(v.processors, 0u);
  v = trace_step_view(trace, path, 1, &as, {});
  EXPECT_EQ(v.title.at(0), "fig2.tgt, step 1, owner on 2 processors");
  EXPECT_EQ(v.processors, 2u);
  ViewOptions direct;  // the same picture as make_graph_view with step 1's assignment
  direct.assignment = &as.steps[1];
  direct.title = v.title.at(0);
  EXPECT_EQ(to_dot(v), to_dot(make_graph_view(trace.steps[1], direct)));
  try {
    trace_step_view(trace, path, 2, nullptr, {});
    FAIL() << "no error";
  } catch (const UsageError& e) {
    EXPECT_STREQ(e.what(), "step: trace /data/run/fig2.tgt has 2 steps, no step 2");
  }
  ViewOptions small;
  small.max_nodes = 3;
  try {
    trace_step_view(trace, path, 1, nullptr, small);
    FAIL() << "no error";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.option(), "max_nodes");
    EXPECT_EQ(e.problem().rfind("/data/run/fig2.tgt step 1: the picture would have ", 0), 0u)
        << e.what();
  }
}

// x of the SVG text element whose content is `label` (nullopt when absent).
std::optional<double> svg_text_x(const std::string& svg, const std::string& label) {
  const std::regex text("<text[^>]* x=\"(-?[0-9.]+)\"[^>]*>" + label + "</text>");
  std::smatch m;
  if (!std::regex_search(svg, m, text)) return std::nullopt;
  return std::stod(m[1].str());
}

TEST(GraphView, LegendListsProcessorsFromP0LeftToRight) {
  const StepGraph g = fig2_fixed_costs();
  Assignment a;
  a.k = 4;
  for (TaskId t = 0; t < g.tasks.size(); ++t) a.proc.push_back(t % 4);
  ViewOptions o;
  o.assignment = &a;
  const GraphView v = make_graph_view(g, o);
  // The laid-out picture: p0's sample left of p1's, p1's left of p2's...
  const std::string svg = render_graph(v, GraphFormat::kSvg);
  std::vector<double> xs;
  for (int p = 0; p < 4; ++p) {
    const std::optional<double> x = svg_text_x(svg, "p" + std::to_string(p));
    ASSERT_TRUE(x.has_value()) << "p" << p;
    xs.push_back(*x);
  }
  for (int p = 0; p < 3; ++p) EXPECT_LT(xs[p], xs[p + 1]) << "p" << p << " vs p" << p + 1;
  // DOT: the samples are chained p0 -> p1 -> p2 -> p3 by invisible edges.
  const std::string dot = to_dot(v);
  for (int p = 0; p < 3; ++p) {
    const std::string chain = "legend" + std::to_string(p) + " -> legend" + std::to_string(p + 1);
    const std::size_t at = dot.find(chain);
    ASSERT_NE(at, std::string::npos) << chain;
    EXPECT_EQ(dot.substr(at + chain.size(), 14), "\t[style=invis]") << chain;
  }
}

// Expected aggregates of --collapse object computed from the trace directly.
TEST(GraphView, CollapsedBars64HasOneNodePerObjectAndLoopWithSummedWork) {
  const StepGraph g = capture_step("bars64", 1);
  ASSERT_GT(g.tasks.size(), 900u);
  ASSERT_EQ(g.loops.size(), 1u);
  // key, loop, before (0) or after (1) the loop for tasks outside it -> work
  std::map<std::tuple<std::string, LoopId, int>, std::uint64_t> expected;
  std::uint64_t total = 0;
  for (TaskId t = 0; t < g.tasks.size(); ++t) {
    const Task& task = g.tasks[t];
    const std::string key = task.object == kNoObject ? "k" + std::to_string(task.kind)
                                                     : "o" + std::to_string(task.object);
    const int region = task.loop == kNoLoop && t >= g.loops[0].last ? 1 : 0;
    expected[{key, task.loop, region}] += task.cost_ns * g.runs(t);
    total += task.cost_ns * g.runs(t);
  }
  ViewOptions o;
  o.collapse = Collapse::kObject;
  const GraphView v = make_graph_view(g, o);
  std::size_t groups = 0;
  std::uint64_t work = 0;
  std::multiset<std::uint64_t> got_work, want_work;
  for (const ViewNode& n : v.nodes) {
    if (n.kind == NodeKind::kDatum) continue;
    ++groups;
    work += n.work_ns;
    got_work.insert(n.work_ns);
  }
  for (const auto& [key, w] : expected) want_work.insert(w);
  EXPECT_EQ(groups, expected.size());
  EXPECT_EQ(got_work, want_work);
  EXPECT_EQ(work, total);
  EXPECT_EQ(work, compute_metrics(g).work_ns);
  std::uint64_t tasks = 0;
  for (const ViewNode& n : v.nodes) tasks += n.tasks;
  EXPECT_EQ(tasks, g.tasks.size());
}

TEST(GraphView, CollapsedByKindAndProcessorSumTheWork) {
  const StepGraph g = capture_step("bars64", 1);
  Assignment a;
  a.k = 4;
  for (TaskId t = 0; t < g.tasks.size(); ++t) a.proc.push_back(t % 4);
  ViewOptions o;
  o.assignment = &a;
  const std::uint64_t total = compute_metrics(g).work_ns;
  for (Collapse c : {Collapse::kKind, Collapse::kProcessor, Collapse::kLoop}) {
    o.collapse = c;
    const GraphView v = make_graph_view(g, o);
    std::uint64_t work = 0, tasks = 0, shares = 0;
    for (const ViewNode& n : v.nodes) {
      work += n.work_ns;
      tasks += n.tasks;
      for (const ProcessorShare& s : n.procs) shares += s.work_ns;
    }
    EXPECT_EQ(work, total) << to_string(c);
    EXPECT_EQ(shares, total) << to_string(c);
    EXPECT_EQ(tasks, g.tasks.size()) << to_string(c);
  }
  o.collapse = Collapse::kProcessor;
  std::set<std::tuple<ProcId, LoopId, bool>> want;  // outside the loop: before or after it
  for (TaskId t = 0; t < g.tasks.size(); ++t)
    want.insert({a.proc[t], g.tasks[t].loop,
                 g.tasks[t].loop == kNoLoop && t >= g.loops.at(0).last});
  std::size_t groups = 0;
  for (const ViewNode& n : make_graph_view(g, o).nodes) groups += n.kind == NodeKind::kGroup;
  EXPECT_EQ(groups, want.size());
}

// body0 has tasks before, inside and after the loop: three nodes (one node for before and
// after would form a cycle with the loop's node); body1 has none after it.
TEST(GraphView, CollapsedViewsSplitTheTasksBeforeAndAfterALoop) {
  const StepGraph g = cw_loop_graph();
  ViewOptions o;
  o.collapse = Collapse::kObject;
  std::set<std::pair<std::string, std::string>> heads;
  for (const ViewNode& n : make_graph_view(g, o).nodes)
    if (n.kind == NodeKind::kGroup) heads.insert({n.lines.at(0), n.lines.at(1)});
  EXPECT_TRUE(heads.count({"body0", "before loop 0"}));
  EXPECT_TRUE(heads.count({"body0", "after loop 0"}));
  EXPECT_TRUE(heads.count({"body0", "2 tasks \xC3\x97 3 it."}));
  EXPECT_TRUE(heads.count({"body1", "before loop 0"}));
  EXPECT_FALSE(heads.count({"body1", "after loop 0"}));
}

// Two "integrate" tasks chained through x, then two "sum" readers: collapsed by kind, the
// chain is a self-loop of the integrate node, the title says so.
TEST(GraphView, CollapsedViewsCountTheDependenciesTheyHide) {
  Builder b;
  b.g.kinds = {"integrate", "sum"};
  const DatumId x = b.datum("x", 8), y = b.datum("y", 8);
  b.g.add_task(0, kNoObject, std::vector<Access>{{x, M::W}}, 1, 1);
  b.g.add_task(0, kNoObject, std::vector<Access>{{x, M::RW}}, 1, 2);
  b.g.add_task(1, kNoObject, std::vector<Access>{{x, M::R}}, 1, 3);
  b.g.add_task(1, kNoObject, std::vector<Access>{{x, M::R}, {y, M::W}}, 1, 4);
  const StepGraph g = b.done();
  ASSERT_EQ(g.edges.size(), 3u);  // 0 -> 1, 1 -> 2, 1 -> 3
  ViewOptions o;
  o.collapse = Collapse::kKind;
  const GraphView v = make_graph_view(g, o);
  EXPECT_EQ(v.hidden_deps, 1u);
  EXPECT_EQ(v.deps, 3u);
  ASSERT_EQ(v.edges.size(), 1u);
  EXPECT_EQ(v.edges[0].deps, 2u);  // drawn + hidden = all
  EXPECT_EQ(hidden_deps_note(v),
            "1 of 3 dependencies join tasks of one node (self-loops, not drawn)");
  EXPECT_NE(v.title.back().find(hidden_deps_note(v)), std::string::npos) << v.title.back();
  EXPECT_NE(to_dot(v).find("1 of 3 dependencies join tasks of one node"), std::string::npos);
  // One node per task: nothing hidden.
  o.collapse = Collapse::kLoop;
  EXPECT_EQ(make_graph_view(g, o).hidden_deps, 0u);
}

// On bars64 collapsed by object, the hidden dependencies are some of those inside one object
// and loop level (the others go through a datum node and are drawn).
TEST(GraphView, Bars64CollapsedByObjectHidesTheDependenciesInsideAnObject) {
  const StepGraph g = capture_step("bars64", 1);
  ViewOptions o;
  o.collapse = Collapse::kObject;
  const GraphView v = make_graph_view(g, o);
  auto key = [&](TaskId t) {
    const Task& task = g.tasks[t];
    return std::make_tuple(task.object, task.object == kNoObject ? task.kind : 0, task.loop,
                           task.loop == kNoLoop && t >= g.loops.at(0).last);
  };
  std::uint64_t inside = 0;
  for (const auto* edges : {&g.edges, &g.carried_edges})
    for (const Edge& e : *edges) inside += key(e.from) == key(e.to);
  EXPECT_GT(v.hidden_deps, 0u);
  EXPECT_LE(v.hidden_deps, inside);
  EXPECT_EQ(v.deps, g.edges.size() + g.carried_edges.size());
  EXPECT_NE(v.title.at(v.title.size() - 1).find(hidden_deps_note(v)), std::string::npos);
}

TEST(QuotientView, LabelsProcessorsWithLoadAndPairsWithCutAndSignals) {
  QuotientGraph q;
  q.load_ns = {3'000'000, 1'000'000, 0};
  q.tasks = {30, 10, 0};
  q.edges = {{0, 1, 4, 2, 2048, 5}, {1, 0, 1, 0, 512, 1}, {2, 0, 0, 0, 0, 3}};
  const GraphView v = quotient_view(q, "quotient graph, step 1");
  ASSERT_EQ(v.nodes.size(), 3u);
  EXPECT_EQ(v.nodes[0].lines, (std::vector<std::string>{"p0", "work 3 ms (75%)", "30 tasks"}));
  EXPECT_EQ(v.nodes[1].lines, (std::vector<std::string>{"p1", "work 1 ms (25%)", "10 tasks"}));
  EXPECT_EQ(v.nodes[2].lines, (std::vector<std::string>{"p2", "work 0 ns (0%)", "0 tasks"}));
  EXPECT_EQ(v.nodes[1].procs, (std::vector<ProcessorShare>{{1, 1'000'000}}));
  ASSERT_EQ(v.edges.size(), 3u);
  EXPECT_EQ(v.edges[0].lines,
            (std::vector<std::string>{"6 deps (2 carried)", "2 KiB", "5 signals"}));
  EXPECT_EQ(v.edges[1].lines, (std::vector<std::string>{"1 dep", "512 B", "1 signal"}));
  EXPECT_EQ(v.edges[2].style, EdgeStyle::kOrder);  // loop decisions only
  EXPECT_DOUBLE_EQ(v.edges[0].width, 6.0);         // the most bytes: the widest
  EXPECT_DOUBLE_EQ(v.edges[1].width, 1.0 + 5.0 * 512 / 2048);
  EXPECT_FALSE(v.legend);
  EXPECT_EQ(v.title,
            (std::vector<std::string>{
                "quotient graph, step 1", "3 processors \xC2\xB7 40 tasks \xC2\xB7 work 4 ms",
                "cut: 7 dependencies \xC2\xB7 2.5 KiB \xC2\xB7 9 signals per execution"}));
  const std::string svg = render_graph(v, GraphFormat::kSvg);
  for (const char* text : {">p0<", ">p2<", ">5 signals<", ">work 3 ms (75%)<"})
    EXPECT_NE(svg.find(text), std::string::npos) << text;
  EXPECT_EQ(svg.find("legend"), std::string::npos);
}

// What make_graph_view's OptionError says for `o`, or "accepted".
std::string view_error(const StepGraph& g, const ViewOptions& o) {
  return test::option_error([&] { make_graph_view(g, o); });
}

TEST(GraphView, Bars64WithoutCollapseIsRefusedWithAHint) {
  const StepGraph g = capture_step("bars64", 1);
  ViewOptions o;
  try {
    make_graph_view(g, o);
    FAIL() << "expected a refusal";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.option(), "max_edges");
    EXPECT_NE(e.problem().find("more than 4000: aggregate with {collapse} object"),
              std::string::npos)
        << e.what();
  }
  o.max_nodes = 100;
  o.max_edges = 0;
  EXPECT_EQ(view_error(g, o).rfind("max_nodes: the picture would have ", 0), 0u);
}

// A picture larger than dot lays out in about 15 s is refused before the layout, even with
// the limits off, naming the aggregate with the fewest edges; .dot (no layout) is written.
TEST(GraphView, DrawStepRefusesALayoutTooLargeAndNamesTheAggregate) {
  const Trace t = testing::scene_trace("bars64", 1);
  ViewOptions o;
  o.max_nodes = 0;
  o.max_edges = 0;
  const auto dir = std::filesystem::temp_directory_path() / "tgraph_viz_layout_test";
  std::filesystem::create_directories(dir);
  try {
    draw_step(t, "bars64.tgt", 0, nullptr, o, (dir / "b.svg").string());
    FAIL() << "expected a refusal";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.option(), "max_edges");
    const std::regex hint(
        "more than dot lays out in about 15 s \\(2500\\): aggregate with \\{collapse\\} "
        "(loop|object|kind) \\(([0-9]+) nodes, ([0-9]+) edges\\), or write a \\.dot file");
    std::smatch m;
    const std::string problem = e.problem();
    ASSERT_TRUE(std::regex_search(problem, m, hint)) << problem;
    EXPECT_LE(std::stoul(m[3].str()), kLayoutEdges);
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "b.svg"));
  draw_step(t, "bars64.tgt", 0, nullptr, o, (dir / "b.dot").string());
  EXPECT_GT(std::filesystem::file_size(dir / "b.dot"), 0u);
  std::filesystem::remove_all(dir);
}

TEST(GraphView, RejectsAnAssignmentThatDoesNotFit) {
  const StepGraph g = cw_loop_graph();
  Assignment a = by_object(g);
  a.proc.pop_back();
  ViewOptions o;
  o.assignment = &a;
  EXPECT_EQ(view_error(g, o).rfind("assignment: has ", 0), 0u) << view_error(g, o);
  a = by_object(g);
  a.proc[0] = 7;
  EXPECT_EQ(view_error(g, o), "assignment: processor 7 out of range (k = 2)");
  ViewOptions p;
  p.collapse = Collapse::kProcessor;
  EXPECT_EQ(view_error(g, p), "collapse: processor needs an assignment (.tga)");
  EXPECT_THROW(parse_collapse("objects"), UsageError);
  EXPECT_THROW(graph_format_of("x.jpeg"), UsageError);
}

TEST(CriticalPath, LengthIsTheSpanOnRandomGraphsWithLoops) {
  for (std::uint64_t seed = 1; seed <= 200; ++seed) {
    const StepGraph g =
        partition::testing::random_graph(seed, 6 + static_cast<int>(seed % 20), 5, seed % 2 == 0);
    const CriticalPath cp = critical_path(g);
    EXPECT_EQ(cp.length_ns, compute_metrics(g).span_ns) << "seed " << seed;
    std::uint64_t sum = 0;
    for (const TaskInstance& i : cp.instances) sum += g.tasks[i.task].cost_ns;
    EXPECT_EQ(sum, cp.length_ns) << "seed " << seed;  // a path: its costs add up to its length
  }
}

TEST(CriticalPath, CountsLoopIterations) {
  const StepGraph g = cw_loop_graph();
  const CriticalPath cp = critical_path(g);
  EXPECT_EQ(cp.length_ns, compute_metrics(g).span_ns);
  // Iterations 0 and 1 end with body1's solve (25) -> dot -> check -> break; the last one
  // ends with body0's solve -> dot -> the update after the loop (20 + 5 + 10 > 25 + 5 + 2 + 1).
  EXPECT_EQ(cp.task_hits[3], 2u);  // solve@body1
  EXPECT_EQ(cp.task_hits[7], 2u);  // the break, gating iterations 1 and 2
  EXPECT_EQ(cp.task_hits[2], 1u);  // solve@body0
  ASSERT_FALSE(cp.instances.empty());
  EXPECT_EQ(cp.instances.back().task, 8u);
  EXPECT_EQ(cp.instances.front().task, 1u);  // the heavier force (40)
}

TEST(Format, RoundsWithUnits) {
  EXPECT_EQ(format_bytes(96), "96 B");
  EXPECT_EQ(format_bytes(1536), "1.5 KiB");
  EXPECT_EQ(format_ns(850), "850 ns");
  EXPECT_EQ(format_ns(4474820), "4.47 ms");
}

}  // namespace
}  // namespace tgraph::viz
