// SPDX-License-Identifier: MIT
// `tgraph replay` (a trace's steps on real threads, synthetic bodies) and `tgraph run`
// (live: the engine's own bodies through the executor, optionally checked bit for bit).
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "commands.hpp"
#include "tgraph/capture/recorder.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/partition/assignment_io.hpp"
#include "tgraph/partition/cost_model.hpp"
#include "tgraph/partition/evaluate.hpp"
#include "tgraph/partition/simulator.hpp"
#include "tgraph/partition/strategy.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/live.hpp"
#include "tgraph/replay/measure.hpp"
#include "tgraph/samples/live_engine.hpp"
#include "tgraph/samples/scene.hpp"

namespace tgraph::app {
namespace {

namespace tp = tgraph::partition;
namespace tr = tgraph::replay;

tr::Policy policy_from(const std::string& name, const char* flag) {
  const auto p = tr::parse_policy(name);
  if (!p)
    throw UsageError(std::string(flag) + " " + name +
                     ": expected partition, worksteal, barrier, starpu or sequential");
  return *p;
}

// ---- replay -----------------------------------------------------------------------------

struct ReplayCmd {
  std::string trace, assignment, policy = "partition", method = "owner", timeline, chrome;
  std::string cw, model = "calibrated", calibration, starpu_sched = "lws";
  std::uint32_t threads = default_threads();
  std::uint32_t steps = 0, first_step = 0, repeat = 3;
  std::int64_t spin_ns = tr::kDefaultSpinNs;
  double scale = 1.0;
  bool no_pin = false, no_touch = false, no_baseline = false, json = false;
};

void run_replay(const ReplayCmd& c) {
  const Trace trace = load_trace(c.trace);
  tr::ReplayOptions o;
  o.policy = policy_from(c.policy, "--policy");
  o.exec.threads = c.threads;
  o.exec.pin = !c.no_pin;
  o.exec.spin_ns = c.spin_ns;
  o.exec.starpu_sched = c.starpu_sched;
  if (c.cw == "reduce") o.exec.cw = tr::CwMode::kReduce;
  if (c.cw == "serialize") o.exec.cw = tr::CwMode::kSerialize;
  o.synthetic.cost_scale = c.scale;
  o.synthetic.touch = !c.no_touch;
  o.steps = c.steps;
  o.first_step = c.first_step;
  o.repeat = c.repeat;
  o.sequential_baseline = !c.no_baseline && o.policy != tr::Policy::kSequential;
  if (c.threads == 0) throw UsageError("--threads must be at least 1");
  if (o.policy == tr::Policy::kSequential && c.threads != 1) o.exec.threads = 1;

  std::optional<TraceAssignment> assignment;
  if (o.policy == tr::Policy::kPartition) {
    if (!c.assignment.empty()) {
      assignment = tp::read_assignment(c.assignment);
      tp::check_fits(trace, *assignment, c.assignment);
      if (assignment->k != c.threads)
        throw UsageError(c.assignment + ": assignment has k = " + std::to_string(assignment->k) +
                         " but --threads is " + std::to_string(c.threads));
    } else {
      assignment = tp::partition_trace(trace, c.method, c.threads, tp::Options{}).assignment;
    }
  } else if (!c.assignment.empty()) {
    throw UsageError("an assignment file is only used by --policy partition");
  }
  std::vector<std::uint64_t> predicted;
  if (assignment) {
    const tp::CostModel model = tp::select_cost_model(c.model, c.calibration);
    for (std::size_t s = 0; s < trace.steps.size(); ++s)
      predicted.push_back(tp::simulate(trace.steps[s], assignment->steps[s], model).makespan_ns);
  }
  tr::TimelineObserver timeline;
  const bool want_timeline = !c.timeline.empty() || !c.chrome.empty();
  const tr::ReplayResult r =
      tr::replay_trace(trace, assignment ? &*assignment : nullptr, o,
                       assignment ? &predicted : nullptr, want_timeline ? &timeline : nullptr);
  if (!c.timeline.empty()) write_file_atomic(c.timeline, timeline.to_json());
  if (!c.chrome.empty()) write_file_atomic(c.chrome, timeline.to_chrome_json());
  if (c.json) {
    auto j = nlohmann::json::parse(tr::to_json(r));
    j["trace"] = c.trace;
    j["assignment"] = c.assignment.empty() ? (assignment ? "owner (computed)" : "") : c.assignment;
    if (assignment && c.assignment.empty()) j["assignment"] = c.method + " (computed)";
    print_json(j);
    return;
  }
  const auto pred = r.predicted_makespan_ns();
  std::int64_t measured_nobuild = 0;
  for (const auto& m : r.steps) measured_nobuild += m.run_ns;
  std::printf("replay %s: %zu steps, policy %s, %u threads, cw %s\n", c.trace.c_str(),
              r.steps.size(), std::string(tr::to_string(r.policy)).c_str(), r.threads,
              std::string(tr::to_string(r.cw)).c_str());
  std::printf("  wall            %10.3f ms (median of %u passes)\n",
              static_cast<double>(r.wall_ns) / 1e6, c.repeat);
  if (r.sequential_wall_ns > 0)
    std::printf("  sequential      %10.3f ms   speed-up %.2f   efficiency %.2f (bound %.2f)\n",
                static_cast<double>(r.sequential_wall_ns) / 1e6, r.speedup, r.efficiency, r.bound);
  std::printf("  work / span     %10.3f / %.3f ms\n", static_cast<double>(r.work_ns) / 1e6,
              static_cast<double>(r.span_ns) / 1e6);
  std::printf("  signals %llu, waits %llu, wait time %.3f ms, plan builds %llu (%.3f ms)\n",
              static_cast<unsigned long long>(r.signals()),
              static_cast<unsigned long long>(r.waits()), static_cast<double>(r.wait_ns()) / 1e6,
              static_cast<unsigned long long>(r.plans_built),
              static_cast<double>(r.build_ns()) / 1e6);
  std::printf("  remote bytes %llu, migrated bytes %llu\n",
              static_cast<unsigned long long>(r.remote_bytes()),
              static_cast<unsigned long long>(r.migrated_bytes()));
  if (pred)
    std::printf("  predicted       %10.3f ms   measured/predicted %.3f\n",
                static_cast<double>(*pred) / 1e6,
                *pred ? static_cast<double>(measured_nobuild) / static_cast<double>(*pred) : 0.0);
  std::printf("  cache misses    %s\n", r.cache_misses ? std::to_string(*r.cache_misses).c_str()
                                                       : r.cache_misses_note.c_str());
}

// ---- run (live) -------------------------------------------------------------------------

struct RunCmd {
  std::string scene, method = "owner", policy, cw, starpu_sched = "lws";
  std::uint32_t threads = default_threads();
  std::optional<int> steps;
  std::uint32_t repeat = 1, cost_stride = 8;
  std::int64_t spin_ns = tr::kDefaultSpinNs;
  bool check = false, no_pin = false, no_observe = false, json = false;
  bool no_reuse = false, repartition_every_step = false, no_elide_waits = false;
};

void run_live(const RunCmd& c) {
  if (c.threads == 0) throw UsageError("--threads must be at least 1");
  if (c.steps && *c.steps < 1) throw UsageError("--steps must be at least 1");
  // --method is a partitioning strategy (partition policy) or a baseline policy name.
  tr::Policy policy = tr::Policy::kPartition;
  std::string method = c.method;
  if (const auto p = tr::parse_policy(c.method); p && *p != tr::Policy::kPartition) {
    policy = *p;
  } else if (c.method == "partition") {
    method = "owner";
  }
  if (!c.policy.empty()) policy = policy_from(c.policy, "--policy");
  std::shared_ptr<tp::Strategy> strategy;
  if (policy == tr::Policy::kPartition) strategy = tp::make_strategy(method);  // UsageError if unknown
  const int scene_steps = samples::make_scene(c.scene)->default_steps();  // InputError if unknown

  tr::LiveOptions o;
  o.policy = policy;
  o.exec.threads = policy == tr::Policy::kSequential ? 1 : c.threads;
  o.exec.pin = !c.no_pin;
  o.exec.spin_ns = c.spin_ns;
  o.exec.starpu_sched = c.starpu_sched;
  if (c.cw == "serialize") o.exec.cw = tr::CwMode::kSerialize;
  o.steps = static_cast<std::uint32_t>(c.steps.value_or(scene_steps));
  o.repeat = c.repeat;
  o.observe = !c.no_observe;
  o.check = c.check;
  o.reuse_structure = !c.no_reuse;
  o.repartition_every_step = c.repartition_every_step;
  o.cost_stride = c.cost_stride;
  o.exec.elide_waits = !c.no_elide_waits;
  const std::string scene = c.scene;
  const tr::EngineFactory make = [scene] { return samples::make_live_engine(scene); };
  tr::LivePartitioner partitioner = [strategy](const StepGraph& g, std::uint32_t k,
                                               const StepGraph* prev_g, const Assignment* prev) {
    return strategy->partition(g, k, tp::Previous{prev_g, prev}, tp::Options{}).assignment;
  };
  const tr::LiveResult r = tr::run_live(make, strategy ? &partitioner : nullptr, o);
  auto j = nlohmann::json::parse(tr::to_json(r));
  j["scene"] = c.scene;
  j["method"] = policy == tr::Policy::kPartition ? method : std::string(tr::to_string(policy));
  if (c.json) {
    print_json(j);
  } else {
    std::printf("run %s: %zu steps, %s (%s), %u threads, cw %s: %.3f ms (median of %u)\n",
                c.scene.c_str(), r.steps.size(), std::string(tr::to_string(policy)).c_str(),
                j["method"].get<std::string>().c_str(), r.threads,
                std::string(tr::to_string(r.cw)).c_str(), static_cast<double>(r.wall_ns) / 1e6,
                c.repeat);
    if (r.baseline_wall_ns > 0)
      std::printf("  uninstrumented engine %.3f ms   speed-up %.2f\n",
                  static_cast<double>(r.baseline_wall_ns) / 1e6, r.speedup);
    const auto& b = j["breakdown"];
    std::printf("  record %.3f ms, partition %.3f ms, plans %.3f ms, execute %.3f ms\n",
                b["record_ns"].get<double>() / 1e6, b["partition_ns"].get<double>() / 1e6,
                b["prepare_ns"].get<double>() / 1e6, b["execute_ns"].get<double>() / 1e6);
    if (c.check)
      std::printf("  check against %s: %s (%zu data compared)\n", r.check_reference.c_str(),
                  r.difference ? "DIFFERS" : "identical bit for bit", r.data_compared);
  }
  if (r.difference)
    throw Failure("state differs from the sequential run: first differing datum " +
                  r.difference->datum + " (byte " + std::to_string(r.difference->offset) + ", " +
                  std::to_string(r.difference->differing_bytes) + " bytes differ)");
}

}  // namespace

void add_replay_verbs(CLI::App& app) {
  {
    auto c = std::make_shared<ReplayCmd>();
    auto* cmd =
        app.add_subcommand("replay", "Replay a trace's steps on real threads (synthetic bodies)");
    cmd->add_option("trace", c->trace, "Trace file (.tgt)")->required();
    cmd->add_option("assignment", c->assignment,
                    "Assignment file (.tga; partition policy; default: --method)");
    cmd->add_option("--threads,-k", c->threads, "Threads (processors)");
    cmd->add_option("--policy", c->policy,
                    "partition (default), worksteal, barrier, starpu or sequential");
    cmd->add_option("--method", c->method,
                    "Strategy used when no assignment file is given (default owner)");
    cmd->add_option("--steps", c->steps, "Steps to replay (default: all)");
    cmd->add_option("--first-step", c->first_step, "First step replayed");
    cmd->add_option("--repeat", c->repeat, "Timed passes (medians reported; default 3)");
    cmd->add_option("--timeline", c->timeline, "Write the observed pass's timeline (JSON)");
    cmd->add_option("--chrome", c->chrome,
                    "Write the observed pass as Chrome/Perfetto trace events");
    cmd->add_option("--spin-ns", c->spin_ns, "Spin this long before parking a waiting thread");
    cmd->add_option("--cw", c->cw, "CW writes across threads: reduce or serialize")
        ->check(CLI::IsMember({"reduce", "serialize"}));
    cmd->add_option("--scale", c->scale, "Multiply every recorded cost");
    cmd->add_option("--model", c->model,
                    "Cost model of the prediction: calibrated (default) or ideal")
        ->check(CLI::IsMember({"ideal", "calibrated"}));
    cmd->add_option("--calibration", c->calibration, "Calibration file for the prediction");
    cmd->add_option("--starpu-sched", c->starpu_sched,
                    "StarPU scheduler of --policy starpu (default lws; eager, ws, prio, dmda...)");
    cmd->add_flag("--no-pin", c->no_pin, "Do not bind threads to cores");
    cmd->add_flag("--no-touch", c->no_touch, "Synthetic bodies only spin (no data buffers)");
    cmd->add_flag("--no-baseline", c->no_baseline, "Do not time sequential passes");
    cmd->add_flag("--json", c->json, "Print one JSON object");
    cmd->callback([c] { run_replay(*c); });
  }
  {
    auto c = std::make_shared<RunCmd>();
    auto* cmd = app.add_subcommand("run", "Run a scene live through the executor (engine bodies)");
    cmd->add_option("--scene", c->scene, "Built-in scene or scene file")->required();
    cmd->add_option("--threads,-k", c->threads, "Threads");
    cmd->add_option(
        "--method", c->method,
        "Partitioning strategy (owner, metis, scotch, sticky, list, roundrobin) or a baseline "
        "(worksteal, barrier, starpu, sequential)");
    cmd->add_option("--policy", c->policy, "Override the policy");
    cmd->add_option("--steps", c->steps, "Steps (default: the scene's)");
    cmd->add_option("--spin-ns", c->spin_ns, "Spin this long before parking a waiting thread");
    cmd->add_option("--repeat", c->repeat, "Timed passes (medians reported; default 1)");
    cmd->add_option("--cw", c->cw, "CW writes across threads: reduce (default) or serialize")
        ->check(CLI::IsMember({"reduce", "serialize"}));
    cmd->add_flag("--no-reuse", c->no_reuse,
                  "Record every step (default: rerun the last program while the structure repeats)");
    cmd->add_flag("--repartition-every-step", c->repartition_every_step,
                  "Call the partitioner at every step (default: on change or imbalance)");
    cmd->add_flag("--no-elide-waits", c->no_elide_waits,
                  "One wait per cross-processor producer (default: waits implied by program "
                  "order dropped)");
    cmd->add_option("--cost-stride", c->cost_stride,
                    "Cost feedback times loop iterations 0, 1 and every N-th (default 8)");
    cmd->add_flag("--no-observe", c->no_observe,
                  "Skip the observed passes (per-thread and per-kind figures)");
    cmd->add_flag("--check", c->check,
                  "Compare the final state with a sequential run using the same reduction "
                  "order, bit for bit");
    cmd->add_option("--starpu-sched", c->starpu_sched,
                    "StarPU scheduler of --policy starpu (default lws; eager, ws, prio, dmda...)");
    cmd->add_flag("--no-pin", c->no_pin, "Do not bind threads to cores");
    cmd->add_flag("--json", c->json, "Print one JSON object");
    cmd->callback([c] { run_live(*c); });
  }
}

}  // namespace tgraph::app
