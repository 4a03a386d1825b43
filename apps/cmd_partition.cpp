// SPDX-License-Identifier: MIT
// `tgraph partition | evaluate | compare | import | calibrate`: thin wrappers over
// tgraph::partition (strategies, .tga files, evaluation, STG import, calibration).
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/graph/stg.hpp"
#include "tgraph/partition/assignment_io.hpp"
#include "tgraph/partition/compare.hpp"
#include "tgraph/partition/cost_model.hpp"
#include "tgraph/partition/evaluate.hpp"
#include "tgraph/partition/strategy.hpp"

namespace tgraph::app {
namespace {

namespace tp = tgraph::partition;

// Flags shared by `partition` and `compare`.
struct StrategyFlags {
  double imbalance = 1.03;
  std::uint64_t seed = 0;
  std::string objective = "cut";
  std::uint32_t phases = 0;
  std::string scotch = "quality";
  std::string sticky_base = "metis";
  double threshold = 1.20;
  double migration_cost = 1.0;
  std::string rebalance = "greedy";
  std::string sticky_fallback = "fresh";

  void add(CLI::App* cmd) {
    cmd->add_option("--imbalance", imbalance, "Tolerated max/mean load for METIS and Scotch (default 1.03)");
    cmd->add_option("--seed", seed, "Seed of METIS, Scotch and random (default 0: METIS's own, as gpmetis)");
    cmd->add_option("--objective", objective, "METIS objective: cut or vol")
        ->check(CLI::IsMember({"cut", "vol"}));
    cmd->add_option("--phases", phases,
                    "METIS multi-constraint mode: balance each of N graph phases (0 = off)");
    cmd->add_option("--scotch-strategy", scotch, "Scotch flavour: default, quality, speed, balance")
        ->check(CLI::IsMember({"default", "quality", "speed", "balance"}));
    cmd->add_option("--sticky-base", sticky_base, "sticky: method for the first step (default metis)");
    cmd->add_option("--threshold", threshold, "sticky: rebalance when imbalance exceeds this x the last partition's (default 1.20)");
    cmd->add_option("--rebalance", rebalance, "sticky: greedy (move whole objects) or scotch (graphRepart)")
        ->check(CLI::IsMember({"greedy", "scotch"}));
    cmd->add_option("--sticky-fallback", sticky_fallback,
                    "sticky, when solver loops merge or split: fresh (base method + relabel) or "
                    "repartition (Scotch graphRepart from the incremental placement)")
        ->check(CLI::IsMember({"fresh", "repartition"}));
    cmd->add_option("--migration-cost", migration_cost,
                    "sticky: Scotch migration cost ratio (emraval, quantised to 0.01; default 1)");
  }
  tp::Options options(const tp::CostModel& model) const {
    tp::Options o;
    o.imbalance = imbalance;
    o.seed = seed;
    o.objective = tp::parse_objective(objective);
    o.phases = phases;
    o.scotch = tp::parse_scotch_flavour(scotch);
    o.sticky_base = sticky_base;
    o.sticky_threshold = threshold;
    o.migration_cost = migration_cost;
    o.rebalance = tp::parse_rebalance(rebalance);
    o.sticky_fallback = tp::parse_sticky_fallback(sticky_fallback);
    o.model = model;
    return o;
  }
};

// --model / --calibration, shared by evaluate, compare and partition (list's estimate).
struct ModelFlags {
  std::string model = "calibrated";
  std::string calibration;

  void add(CLI::App* cmd) {
    cmd->add_option("--model", model, "Cost model: calibrated (default) or ideal (no sync/transfer cost)")
        ->check(CLI::IsMember({"ideal", "calibrated"}));
    cmd->add_option("--calibration", calibration,
                    "Calibration file (default: " + tp::default_calibration_path() + " if present)");
  }
  tp::CostModel load() const { return tp::select_cost_model(model, calibration); }
};

// ---- partition ----------------------------------------------------------------------

struct PartitionCmd {
  std::string trace, method = "metis", out;
  std::uint32_t k = 2;
  bool json = false;
  StrategyFlags flags;
  ModelFlags model;
};

void run_partition(const PartitionCmd& c) {
  const Trace trace = load_trace(c.trace);
  if (c.k == 0) throw UsageError("-k: expected at least 1");
  const tp::TracePartition tp = tp::partition_trace(trace, c.method, c.k, c.flags.options(c.model.load()));
  if (!c.out.empty()) tp::write_assignment(c.out, tp.assignment, trace);
  if (c.json) {
    std::cout << tp::partition_json(tp, c.out) << std::endl;
    return;
  }
  const tp::PartitionSummary s = tp::summarize(tp.stats);
  std::printf("method %s, k = %u, %zu steps: %.3f ms partitioning", c.method.c_str(), c.k, s.steps,
              s.partition_ms);
  if (s.edgecut) std::printf(", edgecut %lld", static_cast<long long>(*s.edgecut));
  std::printf(", %llu tasks moved", static_cast<unsigned long long>(s.moved_tasks));
  if (c.method == "sticky")
    std::printf(" (steps: %llu reused, %llu fallback to a fresh partition + relabel, %llu rebalanced)",
                static_cast<unsigned long long>(s.reused_steps), static_cast<unsigned long long>(s.fallback_steps),
                static_cast<unsigned long long>(s.rebalanced_steps));
  std::printf("\n");
  if (!c.out.empty()) std::printf("wrote %s\n", c.out.c_str());
}

// ---- evaluate -----------------------------------------------------------------------

struct EvaluateCmd {
  std::string trace, assignment;
  bool json = false;
  ModelFlags model;
};

void run_evaluate(const EvaluateCmd& c) {
  const Trace trace = load_trace(c.trace);
  const TraceAssignment a = tp::load_assignment(c.assignment, trace, c.trace);
  const tp::Report rep = tp::evaluate(trace, a, c.model.load(), c.assignment);
  if (c.json)
    std::cout << tp::report_json(rep) << std::endl;
  else
    std::fputs(tp::report_text(rep).c_str(), stdout);
}

// ---- compare ------------------------------------------------------------------------

struct CompareCmd {
  std::string trace, csv;
  std::vector<std::string> methods = {"owner", "metis", "metis-relabel", "scotch", "sticky", "list", "roundrobin"};
  std::vector<std::uint32_t> ks = {2, 4, 8, 16};
  std::vector<double> migration_costs;
  bool json = false;
  StrategyFlags flags;
  ModelFlags model;
};

void run_compare(const CompareCmd& c) {
  const Trace trace = load_trace(c.trace);
  const tp::Comparison cmp =
      tp::compare(trace, c.methods, c.ks, c.flags.options(c.model.load()), c.migration_costs);
  if (!c.csv.empty()) write_file_atomic(c.csv, tp::comparison_csv(cmp));
  if (c.json)
    std::cout << tp::comparison_json(cmp, c.trace) << std::endl;
  else
    std::fputs(tp::comparison_table(cmp).c_str(), stdout);
}

// ---- import -------------------------------------------------------------------------

struct ImportCmd {
  std::string format = "stg", input, out;
  std::uint64_t unit_ns = 1000, edge_bytes = 8;
  bool json = false;
};

void run_import(const ImportCmd& c) {
  const StgGraph stg = read_stg(c.input, c.unit_ns, c.edge_bytes);
  write_trace(c.out, stg.trace);
  const StepGraph& g = stg.trace.steps[0];
  if (c.json) {
    nlohmann::json j = {{"input", c.input},   {"output", c.out},           {"tasks", g.tasks.size()},
                        {"edges", g.edges.size()}, {"unit_ns", c.unit_ns}};
    j["cp_length"] = stg.cp_length ? nlohmann::json(*stg.cp_length) : nlohmann::json(nullptr);
    print_json(j);
    return;
  }
  std::printf("imported %s: %zu tasks, %zu edges", c.input.c_str(), g.tasks.size(), g.edges.size());
  if (stg.cp_length)
    std::printf(", stated critical path %llu units = %llu ns", static_cast<unsigned long long>(*stg.cp_length),
                static_cast<unsigned long long>(*stg.cp_length * c.unit_ns));
  std::printf("\nwrote %s\n", c.out.c_str());
}

// ---- calibrate ----------------------------------------------------------------------

struct CalibrateCmd {
  std::string out;
  bool json = false;
  int rounds = 20000;
};

void run_calibrate(const CalibrateCmd& c) {
  tp::CalibrateOptions o;
  o.rounds = c.rounds;
  tp::Calibration cal;
  try {
    cal = tp::measure_calibration(o);
  } catch (const Error& e) {
    throw Failure(e.what());
  }
  const std::string path = c.out.empty() ? tp::default_calibration_path() : c.out;
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  std::error_code ec;
  if (!parent.empty()) std::filesystem::create_directories(parent, ec);
  write_file_atomic(path, tp::calibration_json(cal));
  if (c.json) {
    print_json({{"sync_latency_ns", cal.sync_latency_ns}, {"per_byte_ns", cal.per_byte_ns},
                {"cpus", {cal.cpu_a, cal.cpu_b}}, {"output", path}});
    return;
  }
  std::printf("signal/wait latency %.1f ns, transfer %.4f ns/byte (CPUs %d and %d)\nwrote %s\n",
              cal.sync_latency_ns, cal.per_byte_ns, cal.cpu_a, cal.cpu_b, path.c_str());
}

}  // namespace

void add_partition_verbs(CLI::App& app) {
  {
    auto c = std::make_shared<PartitionCmd>();
    auto* cmd = app.add_subcommand("partition", "Partition every step of a trace over K processors");
    cmd->add_option("trace", c->trace, "Trace file (.tgt)")->required();
    cmd->add_option("--method,-m", c->method, "Strategy: " + [] {
      std::string s;
      for (const auto& n : tp::strategy_names()) s += (s.empty() ? "" : ", ") + n;
      return s;
    }());
    cmd->add_option("-k", c->k, "Number of processors")->required();
    cmd->add_option("-o,--output", c->out, "Assignment file to write (.tga)");
    cmd->add_flag("--json", c->json, "Print one JSON object");
    c->flags.add(cmd);
    c->model.add(cmd);
    cmd->callback([c] { run_partition(*c); });
  }
  {
    auto c = std::make_shared<EvaluateCmd>();
    auto* cmd = app.add_subcommand("evaluate", "Cut, imbalance, syncs, migrations and predicted makespan");
    cmd->add_option("trace", c->trace, "Trace file (.tgt)")->required();
    cmd->add_option("assignment", c->assignment, "Assignment file (.tga)")->required();
    cmd->add_flag("--json", c->json, "Print one JSON object");
    c->model.add(cmd);
    cmd->callback([c] { run_evaluate(*c); });
  }
  {
    auto c = std::make_shared<CompareCmd>();
    auto* cmd = app.add_subcommand("compare", "Evaluate the method x K grid in one table");
    cmd->add_option("trace", c->trace, "Trace file (.tgt)")->required();
    cmd->add_option("--methods", c->methods, "Comma-separated methods")->delimiter(',');
    cmd->add_option("-k", c->ks, "Comma-separated processor counts (default 2,4,8,16)")->delimiter(',');
    cmd->add_option("--sticky-migration-cost", c->migration_costs,
                    "Also run sticky with --sticky-fallback repartition at each of these migration "
                    "costs (comma-separated) and mark the Pareto points")
        ->delimiter(',');
    cmd->add_option("--csv", c->csv, "Also write the table as CSV");
    cmd->add_flag("--json", c->json, "Print one JSON object");
    c->flags.add(cmd);
    c->model.add(cmd);
    cmd->callback([c] { run_compare(*c); });
  }
  {
    auto c = std::make_shared<ImportCmd>();
    auto* cmd = app.add_subcommand("import", "Turn a Standard Task Graph Set file into a one-step trace");
    cmd->add_option("--format", c->format, "Input format (stg)")->check(CLI::IsMember({"stg"}));
    cmd->add_option("input", c->input, "Input file")->required();
    cmd->add_option("-o,--output", c->out, "Trace file to write (.tgt)")->required();
    cmd->add_option("--unit-ns", c->unit_ns, "Nanoseconds per STG time unit (default 1000)")
        ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{1000000000}));
    cmd->add_option("--edge-bytes", c->edge_bytes, "Bytes of the datum each edge carries (default 8)");
    cmd->add_flag("--json", c->json, "Print one JSON object");
    cmd->callback([c] { run_import(*c); });
  }
  {
    auto c = std::make_shared<CalibrateCmd>();
    auto* cmd = app.add_subcommand("calibrate", "Measure signal/wait latency and transfer cost for the simulator");
    cmd->add_option("--out,-o", c->out, "Output file (default " + tp::default_calibration_path() + ")");
    cmd->add_option("--rounds", c->rounds, "Ping-pong round trips (default 20000)")
        ->check(CLI::Range(500, 10000000));
    cmd->add_flag("--json", c->json, "Print one JSON object");
    cmd->callback([c] { run_calibrate(*c); });
  }
}

}  // namespace tgraph::app
