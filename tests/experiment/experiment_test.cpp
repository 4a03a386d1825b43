// SPDX-License-Identifier: MIT
// The pure parts of the experiments: thread counts, the measured/predicted split, plans,
// CSV and JSON writing, the progress lines.
#include "tgraph/experiment/experiment.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "../option_error.hpp"
#include "count_errors.hpp"
#include "tgraph/graph/error.hpp"

namespace tgraph::experiment {
namespace {

using Ks = std::vector<std::uint32_t>;

std::vector<std::string> split(const std::string& line, char sep = ',') {
  std::vector<std::string> out;
  std::stringstream in(line);
  std::string cell;
  while (std::getline(in, cell, sep)) out.push_back(cell);
  if (!line.empty() && line.back() == sep) out.emplace_back();
  return out;
}

// Lines of a text whose last line ends with a line break.
std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  std::string line;
  while (std::getline(in, line)) out.push_back(line);
  return out;
}

TEST(ThreadList, CountsAreSortedWithoutDuplicates) {
  EXPECT_EQ(thread_counts({8, 1, 2, 3, 4, 2}), (Ks{1, 2, 3, 4, 8}));
  EXPECT_EQ(thread_counts({16}), (Ks{16}));
  EXPECT_EQ(thread_counts({}), Ks{});
}

TEST(ThreadList, RejectsZeroAndCountsAboveTheLimitNamingTheField) {
  for (const Ks& bad : {Ks{0}, Ks{1, 0}, Ks{kMaxThreads + 1}})
    EXPECT_EQ(test::option_error([&bad] { thread_counts(bad); }).rfind("threads: ", 0), 0u)
        << bad.back();
  EXPECT_EQ(thread_counts({kMaxThreads}), (Ks{kMaxThreads}));
}

TEST(ThreadList, ParsesCountsAndRangesAndNamesTheFieldOfABadList) {
  EXPECT_EQ(parse_thread_list("2,1-3,8"), (Ks{2, 1, 2, 3, 8}));
  EXPECT_EQ(parse_thread_list("1024"), (Ks{1024}));
  const auto flag = [](const std::string& field) { return "--" + field; };
  for (const std::string bad : {"1,,2", "4-2", "0", "1025", "x", "", "2-"}) {
    try {
      parse_thread_list(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const UsageError& e) {
      EXPECT_EQ(e.render(flag), "--threads " + bad + ": expected counts from 1 to 1024, such as 1-4,8");
      EXPECT_EQ(std::string(e.what()).rfind("threads " + bad + ": ", 0), 0u) << e.what();
    }
  }
}

TEST(ThreadList, DefaultIsEveryCoreThenPowersOfTwoToSixtyFour) {
  EXPECT_EQ(default_thread_list(2), (Ks{1, 2, 4, 8, 16, 32, 64}));
  EXPECT_EQ(default_thread_list(1), (Ks{1, 2, 4, 8, 16, 32, 64}));
  EXPECT_EQ(default_thread_list(6), (Ks{1, 2, 3, 4, 5, 6, 8, 16, 32, 64}));
  Ks many(80);
  for (std::uint32_t i = 0; i < 80; ++i) many[i] = i + 1;
  EXPECT_EQ(default_thread_list(80), many);
}

TEST(ThreadList, SplitsMeasuredFromPredictedAtTheCores) {
  const Ks ks = {1, 2, 4, 8};
  const ThreadPlan p = split_threads(ks, 2);
  EXPECT_EQ(p.measured, (Ks{1, 2}));
  EXPECT_EQ(p.predicted, (Ks{4, 8}));
  EXPECT_EQ(p.all(), ks);
  EXPECT_TRUE(split_threads(ks, 16).predicted.empty());
  EXPECT_TRUE(split_threads(Ks{4, 8}, 2).measured.empty());
}

TEST(Plan, IndependentDefaultsAndQuick) {
  ExperimentOptions o;
  const ExperimentPlan p = plan_experiment(o, 2);
  ASSERT_EQ(p.scenes.size(), 1u);
  EXPECT_EQ(p.scenes[0].scene, "bars64");
  EXPECT_EQ(p.steps, 20u);
  EXPECT_EQ(p.repeat, 3u);
  EXPECT_TRUE(p.replay);
  EXPECT_EQ(p.threads.measured, (Ks{1, 2}));
  EXPECT_EQ(p.threads.predicted, (Ks{4, 8, 16, 32, 64}));
  EXPECT_EQ(p.out_dir, "tgraph-experiment-independent");
  for (const char* m : {"owner", "metis", "scotch", "sticky", "worksteal", "barrier"})
    EXPECT_NE(std::find(p.methods.begin(), p.methods.end(), m), p.methods.end()) << m;
#ifdef TGRAPH_HAVE_STARPU
  EXPECT_EQ(p.methods.back(), "starpu");
#endif
  // A live run per method and measured count, a replay at 2 threads but for starpu's.
  EXPECT_TRUE(p.replays("owner", 2));
  EXPECT_FALSE(p.replays("owner", 1));
  EXPECT_FALSE(p.replays("starpu", 2));
  const std::size_t starpu = std::count(p.methods.begin(), p.methods.end(), "starpu");
  EXPECT_EQ(p.runs(), p.methods.size() * 2 + p.methods.size() - starpu);
  o.quick = true;
  const ExperimentPlan q = plan_experiment(o, 2);
  EXPECT_LT(q.steps, p.steps);
  EXPECT_EQ(q.repeat, 1u);
}

TEST(Plan, FlagsOverrideTheDefaults) {
  ExperimentOptions o;
  o.name = ExperimentName::kMedical;
  o.threads = {8, 1, 2, 3};
  o.steps = 7;
  o.repeat = 5;
  o.methods = {"owner", "worksteal", "owner"};
  o.replay = false;
  o.out = "out";
  const ExperimentPlan p = plan_experiment(o, 2);
  EXPECT_EQ(p.scenes[0].scene, "torso");
  EXPECT_EQ(p.threads.measured, (Ks{1, 2}));
  EXPECT_EQ(p.threads.predicted, (Ks{3, 8}));
  EXPECT_EQ(p.methods, (std::vector<std::string>{"owner", "worksteal"}));
  EXPECT_EQ(p.steps, 7u);
  EXPECT_EQ(p.repeat, 5u);
  EXPECT_EQ(p.runs(), 4u);
  EXPECT_EQ(p.command(),
            "medical threads=1,2,3,8 steps=7 repeat=5 methods=owner,worksteal replay=off out=out");
  // A front end writes the same settings in its own words (the command line's flags).
  o.words = words_with("tgraph experiment", [](std::string field) {
    std::replace(field.begin(), field.end(), '_', '-');
    return "--" + field;
  });
  EXPECT_EQ(plan_experiment(o, 2).command(),
            "tgraph experiment medical --threads 1,2,3,8 --steps 7 --repeat 5 --methods "
            "owner,worksteal --no-replay --out out");
}

// --calibration: read when the experiment is planned (a bad file stops it before its first
// run, naming the file) and written into the command that reproduces it.
TEST(Plan, ACalibrationFileIsReadBeforeAnyRunAndWrittenInTheCommand) {
  const std::string dir = ::testing::TempDir();
  const std::string good = dir + "tgraph_plan_cal.json", bad = dir + "tgraph_plan_bad.json";
  std::ofstream(good) << R"({"sync_latency_ns": 80, "per_byte_ns": 0.02})";
  std::ofstream(bad) << R"({"sync_latency_ns": 80})";
  ExperimentOptions o;
  o.name = ExperimentName::kMedical;
  o.threads = {1, 2};
  o.steps = 7;
  o.repeat = 5;
  o.methods = {"owner"};
  o.replay = false;
  o.out = "out";
  o.calibration = good;
  EXPECT_EQ(plan_experiment(o, 2).command(),
            "medical threads=1,2 steps=7 repeat=5 methods=owner replay=off calibration=" + good +
                " out=out");
  for (const std::string& file : {bad, dir + "tgraph_no_such_calibration.json"}) {
    o.calibration = file;
    const std::string error = test::input_error([&o] { plan_experiment(o, 2); });
    EXPECT_NE(error.find(file), std::string::npos) << error;
  }
}

TEST(Plan, DomainHasEveryClothAndSubObjectCount) {
  ExperimentOptions o;
  o.name = ExperimentName::kDomain;
  o.subobjects = {4, 16, 4};
  const ExperimentPlan p = plan_experiment(o, 2);
  std::vector<std::string> labels;
  for (const SceneVariant& v : p.scenes) labels.push_back(v.label());
  EXPECT_EQ(labels, (std::vector<std::string>{"cloth128-s4", "cloth128-s16", "cloth256-s4",
                                              "cloth256-s16", "cloth512-s4", "cloth512-s16"}));
  EXPECT_EQ(p.methods, (std::vector<std::string>{"owner"}));
  EXPECT_FALSE(p.replay);
  EXPECT_NE(p.command().find(" subobjects=4,16 "), std::string::npos) << p.command();
}

TEST(Plan, HeterogeneousRepartitionsEveryStepOnTheLargestMeasuredCount) {
  ExperimentOptions o;
  o.name = ExperimentName::kHeterogeneous;
  o.threads = {1, 2, 16};
  const ExperimentPlan p = plan_experiment(o, 4);
  EXPECT_EQ(p.scenes[0].scene, "falling64");
  o.quick = true;  // the small scene, up to its first contacts
  EXPECT_EQ(plan_experiment(o, 4).scenes[0].scene, "falling");
  o.quick = false;
  EXPECT_EQ(p.series_methods, (std::vector<std::string>{"sticky", "metis", "metis-relabel"}));
  EXPECT_EQ(p.series_threads, 2u);
  o.threads = {8, 16};  // nothing measured: predictions only, no per-step runs
  const ExperimentPlan q = plan_experiment(o, 4);
  EXPECT_TRUE(q.series_methods.empty());
  EXPECT_EQ(q.runs(), 0u);
  EXPECT_FALSE(q.notes.empty());
}

TEST(Plan, RejectsBadOptionsNamingTheField) {
  ExperimentOptions o;
  const auto error = [&o] { return test::option_error([&o] { plan_experiment(o, 2); }); };
  o.methods = {"owner", "nonsense"};
  EXPECT_EQ(error().rfind("methods: unknown method 'nonsense'", 0), 0u) << error();
  o.methods = {"sequential"};
  EXPECT_EQ(error(), "methods: sequential is every run's reference, not a method");
  o.methods = {"partition"};
  EXPECT_EQ(error().rfind("methods: name the partitioning strategy", 0), 0u) << error();
  o = {};
  o.subobjects = {4};  // not the domain experiment
  EXPECT_EQ(error(), "subobjects: applies to the domain experiment only");
  o.name = ExperimentName::kDomain;
  for (int bad : {5, 0, -4, 8, 4225}) {
    o.subobjects = {4, bad};
    EXPECT_EQ(error(), "subobjects: " + std::to_string(bad) +
                            " is not a perfect square from 1 to 4096 (expected e.g. 4,16,64)");
  }
  test::expect_zero_counts_refused<ExperimentOptions>(
      [](const ExperimentOptions& x) { plan_experiment(x, 2); });
  o = {};
  o.threads = {2, 0};
  EXPECT_EQ(error().rfind("threads: 0 threads is out of range", 0), 0u) << error();
}

TEST(Named, RefusesTheOptionsAnExperimentDoesNotTake) {
  ExperimentOptions o;
  Progress quiet(nullptr, false);
  const auto error = [&](const char* name) {
    return test::option_error([&] { run_named(name, o, quiet); });
  };
  o.subobjects = {4};
  for (const char* name : {"independent", "metg", "scaling"})
    EXPECT_EQ(error(name), "subobjects: applies to the domain experiment only") << name;
  o = {};
  o.replay = false;
  EXPECT_EQ(error("scaling"), "replay: the scaling experiment makes live runs only");
  o = {};
  o.methods = {"owner"};  // metg's methods are replay policies
  EXPECT_EQ(error("metg").rfind("methods: unknown policy 'owner'", 0), 0u) << error("metg");
  EXPECT_THROW(run_named("nosuch", o, quiet), UsageError);
}

TEST(Names, RoundTrip) {
  EXPECT_EQ(all_experiment_names(), (std::vector<std::string>{"independent", "heterogeneous",
                                                              "domain", "medical", "metg",
                                                              "scaling"}));
  for (const std::string& n : experiment_names()) {
    const std::optional<ExperimentName> e = parse_experiment_name(n);
    ASSERT_TRUE(e.has_value()) << n;
    EXPECT_EQ(to_string(*e), n);
  }
  EXPECT_FALSE(parse_experiment_name("Independent").has_value());
}

TEST(Paper, SequentialTimesOfSectionFour) {
  const PaperFigure d = paper_figure(ExperimentName::kDomain);
  EXPECT_EQ(d.figure, "Fig. 7");
  EXPECT_EQ(d.sequential_ms, (std::vector<std::pair<std::string, double>>{
                                 {"cloth128", 125.0}, {"cloth256", 500.0}, {"cloth512", 2200.0}}));
  EXPECT_EQ(paper_figure(ExperimentName::kIndependent).sequential_ms.front().second, 150.0);
  EXPECT_EQ(paper_figure(ExperimentName::kMedical).sequential_ms.front().second, 50.0);
  EXPECT_NE(paper_figure(ExperimentName::kHeterogeneous).text.find("30 ms"), std::string::npos);
}

std::vector<ResultRow> sample_rows() {
  ResultRow measured;
  measured.experiment = "independent";
  measured.scene = "bars64";
  measured.method = "owner";
  measured.policy = "partition";
  measured.threads = 2;
  measured.measured = Measured{};
  measured.measured->live_speedup = 1.85;
  measured.measured->replay_speedup = 1.7;
  measured.measured->integration_speedup = 1.92;
  measured.measured->step_speedup = 1.85;
  measured.predicted = Predicted{};
  measured.predicted->speedup = 1.95;
  measured.predicted->step_speedup = 1.95;
  measured.predicted->integration_speedup = 1.99;
  ResultRow predicted = measured;
  predicted.threads = 16;
  predicted.measured.reset();
  predicted.predicted->speedup = 14.5;
  ResultRow baseline = measured;
  baseline.method = "worksteal";
  baseline.policy = "worksteal";
  baseline.predicted.reset();
  baseline.measured->replay_speedup.reset();
  baseline.failure = "replay: it broke, \"badly\"";
  return {measured, predicted, baseline};
}

TEST(Csv, KeepsMeasuredAndPredictedInTheirOwnColumns) {
  const std::vector<std::string> text = lines(results_csv(sample_rows(), 2));
  ASSERT_EQ(text.size(), 4u);
  const std::vector<std::string> columns = result_columns();
  EXPECT_EQ(split(text[0]), columns);
  const auto col = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(columns.begin(), columns.end(), name) -
                                    columns.begin());
  };
  // Every column is either the row's identity, measured_*, predicted_* or the failure.
  for (const std::string& c : columns)
    EXPECT_TRUE(c.rfind("measured_", 0) == 0 || c.rfind("predicted_", 0) == 0 ||
                c == "experiment" || c == "scene" || c == "subobjects" || c == "method" ||
                c == "policy" || c == "threads" || c == "threads_kind" || c == "failure")
        << c;
  const std::vector<std::string> m = split(text[1]), p = split(text[2]);
  ASSERT_EQ(m.size(), columns.size());
  ASSERT_EQ(p.size(), columns.size());
  EXPECT_EQ(m[col("threads_kind")], "measured");
  EXPECT_EQ(m[col("measured_live_speedup")], "1.85");
  EXPECT_EQ(m[col("measured_replay_speedup")], "1.7");
  EXPECT_EQ(m[col("predicted_speedup")], "1.95");
  EXPECT_EQ(p[col("threads_kind")], "predicted");
  EXPECT_EQ(p[col("predicted_speedup")], "14.5");
  // The time integration alone and the whole step: separate columns, never mixed.
  EXPECT_EQ(m[col("measured_integration_speedup")], "1.92");
  EXPECT_EQ(m[col("measured_step_speedup")], "1.85");
  EXPECT_EQ(m[col("predicted_integration_speedup")], "1.99");
  EXPECT_EQ(m[col("predicted_step_speedup")], "1.95");
  EXPECT_LT(col("measured_integration_speedup"), columns.size());
  EXPECT_NE(col("measured_integration_speedup"), col("measured_step_speedup"));
  for (std::size_t i = 0; i < columns.size(); ++i) {
    if (columns[i].rfind("measured_", 0) == 0) {
      EXPECT_EQ(p[i], "") << columns[i];
    }
  }
  // The baseline: no prediction, the failure quoted.
  EXPECT_NE(text[3].find(",\"replay: it broke, \"\"badly\"\"\""), std::string::npos) << text[3];
  EXPECT_NE(text[3].find("worksteal,worksteal,2,measured,"), std::string::npos);
}

TEST(Csv, QuotesOnlyWhatNeedsIt) {
  EXPECT_EQ(csv_cell("owner"), "owner");
  EXPECT_EQ(csv_cell("a,b"), "\"a,b\"");
  EXPECT_EQ(csv_cell("say \"x\""), "\"say \"\"x\"\"\"");
  EXPECT_EQ(csv_cell("two\nlines"), "\"two\nlines\"");
  EXPECT_EQ(number_text(0.5), "0.5");
  EXPECT_EQ(number_text(1234567.0), "1.23457e+06");
  EXPECT_EQ(number_text(1.0 / 0.0), "");
}

TEST(Csv, StepsHaveOneLinePerStep) {
  StepRow r;
  r.method = "sticky";
  r.threads = 2;
  r.step = 44;
  r.structure_changed = true;
  r.migrated_tasks = 12;
  const std::vector<std::string> text = lines(steps_csv({r, r}));
  ASSERT_EQ(text.size(), 3u);
  EXPECT_EQ(split(text[0]), step_columns());
  const std::vector<std::string> cells = split(text[1]);
  ASSERT_EQ(cells.size(), step_columns().size());
  EXPECT_EQ(cells[0], "sticky");
  EXPECT_EQ(cells[2], "44");
  EXPECT_EQ(cells[3], "1");
  EXPECT_EQ(cells.back(), "12");
}

TEST(Json, MeasuredAndPredictedAreSeparateObjects) {
  ExperimentResult r;
  r.plan = plan_experiment({}, 2);
  r.rows = sample_rows();
  const nlohmann::json j = nlohmann::json::parse(experiment_json(r));
  ASSERT_EQ(j["rows"].size(), 3u);
  EXPECT_EQ(j["rows"][0]["threads_kind"], "measured");
  EXPECT_EQ(j["rows"][0]["measured"]["live_speedup"], 1.85);
  EXPECT_EQ(j["rows"][1]["threads_kind"], "predicted");
  EXPECT_TRUE(j["rows"][1]["measured"].is_null());
  EXPECT_EQ(j["rows"][1]["predicted"]["speedup"], 14.5);
  EXPECT_TRUE(j["rows"][2]["predicted"].is_null());
  EXPECT_TRUE(j["rows"][2]["measured"]["replay_speedup"].is_null());
  EXPECT_EQ(j["failures"], 1);
  EXPECT_EQ(j["paper"]["figure"], "Fig. 5");
  EXPECT_EQ(j["plan"]["threads_measured"], nlohmann::json({1, 2}));
}

TEST(Progress, WritesOneNumberedLinePerRunWithoutABarWhenNotATerminal) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    Progress p(f, Progress::is_terminal(f));
    p.set_total(2);
    p.note("starting");
    p.begin("a");
    p.end("a done");
    p.begin("b");
    p.end("b done");
    p.finish();
    EXPECT_EQ(p.done(), 2u);
  }
  std::rewind(f);
  std::string text;
  char buf[256];
  while (std::fgets(buf, sizeof buf, f)) text += buf;
  std::fclose(f);
  const std::vector<std::string> l = lines(text);
  ASSERT_EQ(l.size(), 3u) << text;
  EXPECT_EQ(l[0], "starting");
  EXPECT_EQ(l[1].rfind("[1/2 ", 0), 0u) << l[1];
  EXPECT_NE(l[1].find("] a done"), std::string::npos);
  EXPECT_EQ(l[2].rfind("[2/2 ", 0), 0u);
  EXPECT_EQ(text.find('\r'), std::string::npos);  // no bar drawn
}

}  // namespace
}  // namespace tgraph::experiment
