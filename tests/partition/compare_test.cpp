// SPDX-License-Identifier: MIT
// The method x K grid: rows, sticky's moves against the METIS baselines, JSON/CSV/text.
#include "tgraph/partition/compare.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

#include "test_graphs.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/partition/assignment_io.hpp"

namespace tgraph::partition {
namespace {

using testing::grouped_scene;
using testing::objects_scene;

// Contacts come and go, collision groups merge and split.
Trace changing_trace() {
  Trace t;
  t.steps = {objects_scene(12, {}),
             objects_scene(12, {}),
             objects_scene(12, {{1, 2}}),
             objects_scene(12, {{1, 2}, {5, 9}}),
             grouped_scene(12, {{0, 1, 2, 3, 4, 5}, {6, 7, 8, 9, 10, 11}}),
             grouped_scene(12, {{0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11}}),
             grouped_scene(12, {{0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11}}),
             grouped_scene(12, {{0, 1, 2}, {3, 4, 5, 6, 7, 8, 9, 10, 11}})};
  return t;
}

TEST(Compare, GridRowsFollowTheMethodsAndKsGivenAndAddUpTheStats) {
  const Trace trace = changing_trace();
  const std::vector<std::string> methods = {"metis", "metis-relabel", "sticky", "owner"};
  const Comparison c = compare(trace, methods, {2, 3});
  ASSERT_EQ(c.rows.size(), 8u);
  EXPECT_EQ(c.model, "default");
  for (std::size_t i = 0; i < c.rows.size(); ++i) {
    const CompareRow& r = c.rows[i];
    EXPECT_EQ(r.method, methods[i / 2]);
    EXPECT_EQ(r.k, i % 2 == 0 ? 2u : 3u);
    EXPECT_EQ(r.report.method, r.method);
    EXPECT_EQ(r.report.steps.size(), trace.steps.size());
    EXPECT_EQ(r.partition.steps, trace.steps.size());
    // The strategy's moved tasks and the evaluation's migrations count the same thing.
    EXPECT_EQ(r.partition.moved_tasks, r.report.total.migrated_tasks) << r.method;
    // The same partitions as partition_trace gives.
    EXPECT_EQ(r.partition.moved_tasks,
              summarize(partition_trace(trace, r.method, r.k).stats).moved_tasks);
  }
  const CompareRow& sticky = c.rows[4];
  EXPECT_EQ(sticky.partition.reused_steps, 2u);    // steps 1 and 6
  EXPECT_EQ(sticky.partition.fallback_steps, 3u);  // solver loops appear (4), merge (5), split (7)
  EXPECT_EQ(c.rows[0].partition.fallback_steps + c.rows[0].partition.reused_steps, 0u);
  ASSERT_TRUE(c.rows[0].partition.edgecut.has_value());
  EXPECT_EQ(c.rows[0].partition.edgecut, c.rows[2].partition.edgecut);  // relabelling keeps the cut
  EXPECT_LE(c.rows[2].partition.moved_tasks, c.rows[0].partition.moved_tasks);

  ASSERT_EQ(c.sticky_moves.size(), 2u);
  for (const StickyMoves& s : c.sticky_moves) {
    const std::size_t col = s.k == 2 ? 0 : 1;
    EXPECT_EQ(s.sticky, c.rows[4 + col].partition.moved_tasks);
    EXPECT_EQ(s.metis, c.rows[0 + col].partition.moved_tasks);
    EXPECT_EQ(s.metis_relabel, c.rows[2 + col].partition.moved_tasks);
    if (*s.metis_relabel > 0) {
      ASSERT_TRUE(s.over_metis_relabel().has_value());
      EXPECT_DOUBLE_EQ(*s.over_metis_relabel(),
                       static_cast<double>(s.sticky) / static_cast<double>(*s.metis_relabel));
    }
  }
}

TEST(Compare, ReportsStickyMovesOnlyAgainstTheBaselinesInTheGrid) {
  const Trace trace = changing_trace();
  const Comparison without = compare(trace, {"owner", "metis"}, {2});
  EXPECT_TRUE(without.sticky_moves.empty());
  const Comparison only_metis = compare(trace, {"sticky", "metis"}, {2});
  ASSERT_EQ(only_metis.sticky_moves.size(), 1u);
  EXPECT_TRUE(only_metis.sticky_moves[0].metis.has_value());
  EXPECT_FALSE(only_metis.sticky_moves[0].metis_relabel.has_value());
  EXPECT_FALSE(only_metis.sticky_moves[0].over_metis_relabel().has_value());
  const nlohmann::json j = nlohmann::json::parse(comparison_json(only_metis, "t.tgt"));
  EXPECT_TRUE(j["sticky_moves"][0]["metis_relabel"].is_null());
  EXPECT_TRUE(j["rows"][0]["moved_over_metis_relabel"].is_null());
  EXPECT_FALSE(j["rows"][1].contains("moved_over_metis"));  // only sticky rows carry ratios
}

TEST(Compare, SweepsStickysMigrationCostAndMarksTheParetoPoints) {
  const Trace trace = changing_trace();
  const Comparison c = compare(trace, {"metis-relabel", "sticky"}, {2, 4}, {}, {0.01, 1.0, 10.0});
  ASSERT_EQ(c.rows.size(), 2u * 2 + 3u * 2);
  for (std::size_t i = 4; i < c.rows.size(); ++i) {
    EXPECT_EQ(c.rows[i].method, "sticky");
    ASSERT_TRUE(c.rows[i].migration_cost.has_value());
    // Each sweep row is sticky with the repartition fallback at that cost.
    Options o;
    o.sticky_fallback = StickyFallback::kRepartition;
    o.migration_cost = *c.rows[i].migration_cost;
    const TracePartition tp = partition_trace(trace, "sticky", c.rows[i].k, o);
    EXPECT_EQ(c.rows[i].partition.moved_tasks, summarize(tp.stats).moved_tasks);
    EXPECT_EQ(c.rows[i].partition.fallback_steps, 3u);
  }
  EXPECT_EQ(row_label(c.rows[4]), "sticky@0.01");
  EXPECT_EQ(row_label(c.rows[1]), "metis-relabel");
  // Pareto flags: exactly the rows no other row of the same K dominates.
  for (const CompareRow& r : c.rows) {
    bool dominated = false, dominated_cut = false;
    std::size_t same_k = 0;
    for (const CompareRow& o : c.rows) {
      if (o.k != r.k) continue;
      ++same_k;
      const auto m = o.partition.moved_tasks, mr = r.partition.moved_tasks;
      const auto f = o.report.total.makespan_ns, fr = r.report.total.makespan_ns;
      const auto b = o.report.total.cut_bytes, br = r.report.total.cut_bytes;
      dominated = dominated || (m <= mr && f <= fr && (m < mr || f < fr));
      dominated_cut = dominated_cut || (m <= mr && b <= br && (m < mr || b < br));
    }
    EXPECT_EQ(same_k, 5u);
    EXPECT_EQ(r.pareto_makespan, !dominated) << row_label(r) << " k " << r.k;
    EXPECT_EQ(r.pareto_cut, !dominated_cut) << row_label(r) << " k " << r.k;
  }
  // The fewest moves at each K are always a Pareto point.
  for (std::uint32_t k : {2u, 4u}) {
    const CompareRow* fewest = nullptr;
    for (const CompareRow& r : c.rows)
      if (r.k == k &&
          (fewest == nullptr || r.partition.moved_tasks < fewest->partition.moved_tasks ||
           (r.partition.moved_tasks == fewest->partition.moved_tasks &&
            r.report.total.makespan_ns < fewest->report.total.makespan_ns)))
        fewest = &r;
    EXPECT_TRUE(fewest->pareto_makespan);
  }
  const nlohmann::json j = nlohmann::json::parse(comparison_json(c, "t.tgt"));
  ASSERT_EQ(j["pareto"].size(), 2u);
  std::size_t listed = 0;
  for (const nlohmann::json& p : j["pareto"]) listed += p["makespan"].size();
  std::size_t flagged = 0;
  for (const CompareRow& r : c.rows) flagged += r.pareto_makespan ? 1 : 0;
  EXPECT_EQ(listed, flagged);
  EXPECT_EQ(j["rows"][4]["label"], "sticky@0.01");
  EXPECT_EQ(j["rows"][4]["migration_cost"], 0.01);
  EXPECT_TRUE(j["rows"][0]["migration_cost"].is_null());
  // Sticky's moves against the baselines use the plain sticky row, not the sweep's.
  ASSERT_EQ(c.sticky_moves.size(), 2u);
  EXPECT_EQ(c.sticky_moves[0].sticky, c.rows[2].partition.moved_tasks);
  const std::string table = comparison_table(c);
  EXPECT_NE(table.find("sticky@10 k=4:"), std::string::npos) << table;
  EXPECT_NE(table.find("pareto k=2, moved tasks vs predicted makespan:"), std::string::npos)
      << table;
  EXPECT_THROW(compare(trace, {"sticky"}, {2}, {}, {-1.0}), UsageError);
}

TEST(Compare, RejectsUnknownMethodsAndZeroProcessorsBeforeAnyWork) {
  const Trace trace = changing_trace();
  EXPECT_THROW(compare(trace, {"metis", "nope"}, {2}), UsageError);
  EXPECT_THROW(compare(trace, {"metis"}, {2, 0}), UsageError);
}

TEST(Compare, JsonCsvAndTableCarryEveryRowAndStickysStepKinds) {
  const Trace trace = changing_trace();
  const Comparison c = compare(trace, {"metis", "metis-relabel", "sticky"}, {2, 4});
  const nlohmann::json j = nlohmann::json::parse(comparison_json(c, "t.tgt"));
  EXPECT_EQ(j["trace"], "t.tgt");
  ASSERT_EQ(j["rows"].size(), 6u);
  for (std::size_t i = 0; i < 6; ++i) {
    const nlohmann::json& row = j["rows"][i];
    EXPECT_EQ(row["method"], c.rows[i].method);
    EXPECT_EQ(row["k"], c.rows[i].k);
    EXPECT_EQ(row["moved_tasks"], c.rows[i].partition.moved_tasks);
    EXPECT_EQ(row["fallback_steps"], c.rows[i].partition.fallback_steps);
    EXPECT_EQ(row["rebalanced_steps"], c.rows[i].partition.rebalanced_steps);
    EXPECT_EQ(row["reused_steps"], c.rows[i].partition.reused_steps);
    EXPECT_EQ(row["predicted_makespan_ns"], c.rows[i].report.total.makespan_ns);
    EXPECT_FALSE(row.contains("per_step"));
  }
  ASSERT_EQ(j["sticky_moves"].size(), 2u);
  EXPECT_EQ(j["sticky_moves"][1]["k"], 4);
  EXPECT_EQ(j["sticky_moves"][1]["sticky"], c.sticky_moves[1].sticky);
  EXPECT_EQ(j["sticky_moves"][1]["metis_relabel"], *c.sticky_moves[1].metis_relabel);

  std::istringstream csv(comparison_csv(c));
  std::string line;
  std::vector<std::string> lines;
  while (std::getline(csv, line)) lines.push_back(line);
  ASSERT_EQ(lines.size(), 7u);
  auto columns = [](const std::string& l) {
    std::vector<std::string> out(1);
    for (char ch : l) {
      if (ch == ',')
        out.emplace_back();
      else
        out.back().push_back(ch);
    }
    return out;
  };
  const std::vector<std::string> header = columns(lines[0]);
  EXPECT_EQ(header[14], "fallback_steps");
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const std::vector<std::string> row = columns(lines[i]);
    ASSERT_EQ(row.size(), header.size()) << lines[i];
    EXPECT_EQ(row[0], c.rows[i - 1].method);
    EXPECT_EQ(row[14], std::to_string(c.rows[i - 1].partition.fallback_steps));
    EXPECT_EQ(row[17].empty(), c.rows[i - 1].method != "sticky");
  }

  const std::string table = comparison_table(c);
  EXPECT_NE(table.find("metis-relabel"), std::string::npos);
  const std::string sticky_line =
      "sticky k=4: " + std::to_string(c.rows[5].partition.reused_steps) + " steps reused, " +
      std::to_string(c.rows[5].partition.fallback_steps) + " fallback";
  EXPECT_NE(table.find(sticky_line), std::string::npos) << table;
  EXPECT_NE(table.find("x metis-relabel ("), std::string::npos) << table;
}

TEST(Compare, PartitionJsonSeparatesFallbackFromRebalancedSteps) {
  const Trace trace = changing_trace();
  const TracePartition tp = partition_trace(trace, "sticky", 2);
  const nlohmann::json j = nlohmann::json::parse(partition_json(tp, "a.tga"));
  EXPECT_EQ(j["method"], "sticky");
  EXPECT_EQ(j["output"], "a.tga");
  ASSERT_EQ(j["per_step"].size(), trace.steps.size());
  std::uint64_t fallback = 0, rebalanced = 0;
  for (std::size_t s = 0; s < trace.steps.size(); ++s) {
    EXPECT_EQ(j["per_step"][s]["fallback"], tp.stats[s].fallback);
    EXPECT_EQ(j["per_step"][s]["rebalanced"], tp.stats[s].rebalanced);
    fallback += tp.stats[s].fallback ? 1 : 0;
    rebalanced += tp.stats[s].rebalanced ? 1 : 0;
  }
  EXPECT_EQ(j["fallback_steps"], fallback);
  EXPECT_EQ(j["rebalanced_steps"], rebalanced);
  EXPECT_EQ(fallback, 3u);
}

TEST(PartitionFile, WritesTheAssignmentPartitionTraceComputes) {
  const std::string dir = ::testing::TempDir();
  const std::string trace_path = dir + "tgraph_partition_file.tgt", out = dir + "tgraph_pf.tga";
  const Trace trace = changing_trace();
  write_trace(trace_path, trace);
  const TracePartition r = partition_file(trace_path, "list", 3, Options{}, out);
  EXPECT_EQ(r.assignment.steps, partition_trace(trace, "list", 3, Options{}).assignment.steps);
  EXPECT_EQ(load_assignment(out, trace, trace_path).steps, r.assignment.steps);
  try {
    partition_file(trace_path, "list", 0, Options{}, "");
    ADD_FAILURE() << "accepted k = 0";
  } catch (const OptionError& e) {
    EXPECT_STREQ(e.what(), "k: expected at least 1");
  }
  std::remove(trace_path.c_str());
  std::remove(out.c_str());
}

}  // namespace
}  // namespace tgraph::partition
