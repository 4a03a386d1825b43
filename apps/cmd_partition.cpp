// SPDX-License-Identifier: MIT
// `tgraph partition | evaluate | compare | import | calibrate`: flags, one call into
// tgraph::partition (or libgraph's STG reader; measure's calibration, which adds the
// executor's time per task), and its report.
#include <iostream>

#include "commands.hpp"
#include "tgraph/graph/stg.hpp"
#include "tgraph/measure/calibrate.hpp"
#include "tgraph/partition/compare.hpp"
#include "tgraph/model/cost_model.hpp"
#include "tgraph/partition/evaluate.hpp"
#include "tgraph/partition/strategy.hpp"

namespace tgraph::app {

namespace tp = tgraph::partition;

void add_model_flags(CLI::App* cmd, tp::NamedOptions& n) {
  cmd->add_option("--model", n.model, "Cost model: calibrated (default) or ideal (free syncs)")
      ->check(CLI::IsMember({"ideal", "calibrated"}));
  cmd->add_option("--calibration", n.calibration,
                  "Calibration file (default: " + tgraph::model::default_calibration_path() + " if present)");
}

void add_strategy_flags(CLI::App* cmd, tp::NamedOptions& n) {
  tp::Options& o = n.values;
  cmd->add_option("--imbalance", o.imbalance, "METIS/Scotch max/mean load allowed (1.03)");
  cmd->add_option("--seed", o.seed, "METIS/Scotch/random seed (0: METIS's own, as gpmetis)");
  cmd->add_option("--objective", n.objective, "METIS objective: cut or vol")
      ->check(CLI::IsMember({"cut", "vol"}));
  cmd->add_option("--phases", o.phases,
                  "METIS: balance N graph phases (0: the method's default, off for metis, 2 for "
                  "sticky's partitions; 1: off)");
  cmd->add_option("--loop-share", o.loop_share,
                  "With phases: a dynamic loop with this share of the step's work is one more "
                  "balanced constraint (default 0.1; 0: off)")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--scotch-strategy", n.scotch_strategy, "Scotch flavour: default, quality, speed, balance")
      ->check(CLI::IsMember({"default", "quality", "speed", "balance"}));
  cmd->add_option("--sticky-base", o.sticky_base, "sticky: first step's method (metis)");
  cmd->add_option("--threshold", o.sticky_threshold,
                  "sticky: rebalance above this x the last partition's imbalance (1.2; run 1.05)");
  cmd->add_option("--rebalance", n.rebalance, "sticky: greedy (whole objects) or scotch")
      ->check(CLI::IsMember({"greedy", "scotch"}));
  cmd->add_option("--sticky-fallback", n.sticky_fallback,
                  "sticky, when solver loops merge or split: fresh (default; base method + "
                  "relabel), or from the incremental placement refine or repartition (Scotch)")
      ->check(CLI::IsMember({"fresh", "repartition", "refine"}));
  cmd->add_option("--migration-cost", o.migration_cost,
                  "sticky: Scotch migration cost ratio (emraval, quantised to 0.01; default 1)");
  cmd->add_option("--order", n.order,
                  "Each processor's task order but for list: program (the step's) or list (a list "
                  "schedule of the mapping, longest path to the end first)")
      ->check(CLI::IsMember({"program", "list"}));
  add_model_flags(cmd, n);
}

namespace {

// A verb with its own Args and --json.
CLI::App* verb(CLI::App& app, const char* name, const char* what, std::shared_ptr<Args>& a) {
  a = std::make_shared<Args>();
  auto* cmd = app.add_subcommand(name, what);
  cmd->add_flag("--json", a->json, "Print one JSON object");
  return cmd;
}

}  // namespace

void add_partition_verbs(CLI::App& app) {
  std::shared_ptr<Args> a;
  auto n = std::make_shared<tp::NamedOptions>();
  auto* cmd = verb(app, "partition", "Partition every step of a trace over K processors", a);
  cmd->add_option("trace", a->input, "Trace file (.tgt)")->required();
  a->method = "metis";
  cmd->add_option("--method,-m", a->method,
                  "Strategy: " + CLI::detail::join(tp::strategy_names(), ", "));
  cmd->add_option("-k", a->k, "Number of processors")->required();
  cmd->add_option("-o,--output", a->output, "Assignment file to write (.tga)");
  add_strategy_flags(cmd, *n);
  cmd->callback([a, n] {
    const tp::TracePartition r =
        tp::partition_file(a->input, a->method, a->k, n->options(), a->output);
    for (const std::string& w : r.warnings) warn(w);
    std::cout << (a->json ? tp::partition_json(r, a->output) + "\n"
                          : tp::partition_text(r, a->output));
  });

  n = std::make_shared<tp::NamedOptions>();
  cmd = verb(app, "evaluate", "Cut, imbalance, syncs, migrations and predicted makespan", a);
  cmd->add_option("trace", a->input, "Trace file (.tgt)")->required();
  cmd->add_option("assignment", a->assignment, "Assignment file (.tga)")->required();
  add_model_flags(cmd, *n);
  auto serial = std::make_shared<tgraph::model::SerialWork>();
  add_serial_flags(cmd, *serial);
  cmd->callback([a, n, serial] {
    std::cout << tp::evaluate_files(a->input, a->assignment, n->cost_model(), *serial, a->json);
  });

  n = std::make_shared<tp::NamedOptions>();
  cmd = verb(app, "compare", "Evaluate the method x K grid in one table", a);
  a->names = {"owner", "metis", "metis-relabel", "scotch", "sticky", "list", "roundrobin"};
  a->counts = {2, 4, 8, 16};
  cmd->add_option("trace", a->input, "Trace file (.tgt)")->required();
  cmd->add_option("--methods", a->names, "Comma-separated methods")->delimiter(',');
  cmd->add_option("-k", a->counts, "Comma-separated processor counts (default 2,4,8,16)")
      ->delimiter(',');
  cmd->add_option("--sticky-migration-cost", a->values,
                  "Sticky (repartition fallback) at these migration costs too, Pareto marked")
      ->delimiter(',');
  cmd->add_option("--csv", a->csv, "Also write the table as CSV");
  add_strategy_flags(cmd, *n);
  cmd->callback([a, n] {
    std::cout << tp::compare_file(a->input, a->names, a->counts, n->options(), a->values, a->csv,
                                  a->json);
  });

  cmd = verb(app, "import", "Turn a Standard Task Graph Set file into a one-step trace", a);
  a->format = "stg";
  cmd->add_option("--format", a->format, "Input format (stg)")->check(CLI::IsMember({"stg"}));
  cmd->add_option("input", a->input, "Input file")->required();
  cmd->add_option("-o,--output", a->output, "Trace file to write (.tgt)")->required();
  cmd->add_option("--unit-ns", a->unit_ns, "Nanoseconds per STG time unit (default 1000)")
      ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{1000000000}));
  cmd->add_option("--edge-bytes", a->edge_bytes, "Bytes of each edge's datum (default 8)");
  cmd->callback([a] {
    std::cout << import_stg(a->input, a->output, a->unit_ns, a->edge_bytes, a->json);
  });

  auto cal = std::make_shared<tgraph::model::CalibrateOptions>();
  cmd = verb(app, "calibrate", "Measure signal/wait latency and transfer costs for simulation", a);
  cmd->add_option("--out,-o", a->output,
                  "Output file (default " + tgraph::model::default_calibration_path() + ")");
  cmd->add_option("--rounds", cal->rounds, "Ping-pong round trips (default 20000)")
      ->check(CLI::Range(500, 10000000));
  cmd->add_option("--samples", cal->samples,
                  "Times each figure is measured, interleaved; medians kept (default 15)")
      ->check(CLI::Range(1, 1000));
  cmd->callback([a, cal] { std::cout << measure::calibrate_file(*cal, a->output, a->json); });
}

}  // namespace tgraph::app
