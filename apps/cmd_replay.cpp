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
  for (const auto& m : r.steps) measured_nobuild += m.wall_ns - m.build_ns;
  std::printf("replay %s: %zu steps, policy %s, %u threads\n", c.trace.c_str(), r.steps.size(),
              std::string(tr::to_string(r.policy)).c_str(), r.threads);
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
  std::string scene, method = "owner", policy, starpu_sched = "lws";
  std::uint32_t threads = default_threads();
  std::optional<int> steps;
  std::int64_t spin_ns = tr::kDefaultSpinNs;
  bool check = false, no_pin = false, json = false;
};

/// Mean measured duration of each original task in the last step (feeds the next step's
/// costs, which deferred recording leaves at zero, to the partitioner).
class CostObserver : public tr::Observer {
 public:
  void on_step_begin(const tr::ExecGraph& exec, std::uint32_t threads, std::int64_t) override {
    exec_ = &exec;
    begin_.assign(threads * 8, 0);
    sum_.assign(exec.graph.tasks.size(), 0);
    runs_.assign(exec.graph.tasks.size(), 0);
  }
  void on_begin(std::uint32_t thread, TaskId, std::uint32_t, std::int64_t t) override {
    begin_[thread * 8] = t;
  }
  void on_end(std::uint32_t thread, TaskId task, std::uint32_t, std::int64_t t) override {
    sum_[task] += static_cast<std::uint64_t>(t - begin_[thread * 8]);  // one writer per task
    ++runs_[task];
  }
  /// Stable key -> mean cost of the last step.
  std::unordered_map<StableKey, std::uint64_t> costs(const StepGraph& g) const {
    std::unordered_map<StableKey, std::uint64_t> m;
    for (TaskId t = 0; t < sum_.size(); ++t) {
      const TaskId o = exec_->origin[t];
      if (o != kNoTask && runs_[t] > 0) m[g.tasks[o].key] = sum_[t] / runs_[t];
    }
    return m;
  }

 private:
  const tr::ExecGraph* exec_ = nullptr;
  std::vector<std::int64_t> begin_;
  std::vector<std::uint64_t> sum_, runs_;
};

std::vector<tr::StateRegion> regions(const capture::Recorder& rec, const StepGraph& g) {
  std::vector<tr::StateRegion> r;
  for (DatumId d = 0; d < g.data.size(); ++d)
    if (rec.datum_ptr(d)) r.push_back({g.data[d].name, rec.datum_ptr(d), g.data[d].bytes});
  return r;
}

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
  } else {
    (void)tp::make_strategy(method);  // UsageError for an unknown name
  }
  if (!c.policy.empty()) policy = policy_from(c.policy, "--policy");
  const std::uint32_t threads = policy == tr::Policy::kSequential ? 1 : c.threads;

  std::uint64_t fallbacks = 0;
  auto run_scene = [&](tr::Policy pol, std::uint32_t k, bool observe_costs,
                       std::vector<double>* step_ms, tr::StateSnapshot* final_state,
                       std::uint64_t* signals, std::uint32_t* cg) {
    std::unique_ptr<samples::Scene> scene = samples::make_scene(c.scene);
    const int steps = c.steps.value_or(scene->default_steps());
    capture::Recorder rec(capture::Mode::kDeferred);
    tr::ExecOptions eo;
    eo.threads = k;
    eo.pin = !c.no_pin;
    eo.spin_ns = c.spin_ns;
    eo.starpu_sched = c.starpu_sched;
    eo.cw = tr::CwMode::kSerialize;  // the engine's bodies write through their own pointers
    auto ex = tr::make_executor(pol, eo);
    CostObserver costs;
    if (observe_costs) ex->add_observer(costs);
    std::unique_ptr<tp::Strategy> strategy =
        pol == tr::Policy::kPartition ? tp::make_strategy(method) : nullptr;
    StepGraph prev_graph;
    Assignment prev_assignment;
    bool have_prev = false;
    std::unordered_map<StableKey, std::uint64_t> last_costs;
    StepGraph last_graph;
    for (int s = 0; s < steps; ++s) {
      scene->step(rec);
      capture::StepProgram prog = rec.end_step_program();
      if (rec.errors() != 0)
        throw Failure("the recorder counted " + std::to_string(rec.errors()) + " API misuses");
      for (Task& t : prog.graph.tasks) {
        auto it = last_costs.find(t.key);
        t.cost_ns = it != last_costs.end() ? std::max<std::uint64_t>(1, it->second) : 1;
      }
      tr::ProgramWorkload w(prog.bodies, prog.conditions);
      Assignment a;
      if (strategy) {
        tp::Previous prev;
        if (have_prev) prev = {&prev_graph, &prev_assignment};
        a = strategy->partition(prog.graph, k, prev, tp::Options{}).assignment;
      }
      const tr::StepStats st = ex->run_step(prog.graph, strategy ? &a : nullptr, w);
      if (step_ms) step_ms->push_back(static_cast<double>(st.wall_ns) / 1e6);
      if (signals) *signals += st.signals();
      if (cg && !st.loop_iterations.empty()) *cg += st.loop_iterations[0];
      if (observe_costs) last_costs = costs.costs(prog.graph);
      if (strategy) {
        prev_graph = prog.graph;
        prev_assignment = a;
        have_prev = true;
      }
      last_graph = std::move(prog.graph);
    }
    if (final_state) *final_state = tr::snapshot(regions(rec, last_graph));
    fallbacks += ex->order_fallbacks();
  };

  std::vector<double> step_ms;
  tr::StateSnapshot state;
  std::uint64_t signals = 0;
  std::uint32_t cg = 0;
  run_scene(policy, threads, policy == tr::Policy::kPartition, &step_ms, c.check ? &state : nullptr,
            &signals, &cg);
  double total = 0;
  for (double ms : step_ms) total += ms;
  nlohmann::json j = {
      {"scene", c.scene},
      {"policy", std::string(tr::to_string(policy))},
      {"method", policy == tr::Policy::kPartition ? method : std::string(tr::to_string(policy))},
      {"threads", threads},
      {"steps", step_ms.size()},
      {"wall_ns", static_cast<std::int64_t>(total * 1e6)},
      {"signals", signals},
      {"first_loop_iterations", cg},
      {"order_fallbacks", fallbacks}};
  nlohmann::json per_step = nlohmann::json::array();
  for (double ms : step_ms) per_step.push_back({{"wall_ns", static_cast<std::int64_t>(ms * 1e6)}});
  j["per_step"] = per_step;
  std::optional<tr::StateDifference> diff;
  if (c.check) {
    tr::StateSnapshot reference;
    std::vector<double> seq_ms;
    run_scene(tr::Policy::kSequential, 1, false, &seq_ms, &reference, nullptr, nullptr);
    diff = tr::compare(reference, state);
    double seq_total = 0;
    for (double ms : seq_ms) seq_total += ms;
    j["sequential_wall_ns"] = static_cast<std::int64_t>(seq_total * 1e6);
    j["check"] = diff ? "differs" : "identical";
    j["data_compared"] = reference.names.size();
    if (diff)
      j["first_difference"] = {{"datum", diff->datum},
                               {"offset", diff->offset},
                               {"differing_bytes", diff->differing_bytes}};
  }
  if (c.json) {
    print_json(j);
  } else {
    std::printf("run %s: %zu steps, %s (%s), %u threads: %.3f ms\n", c.scene.c_str(),
                step_ms.size(), std::string(tr::to_string(policy)).c_str(),
                j["method"].get<std::string>().c_str(), threads, total);
    if (c.check)
      std::printf("  check against sequential: %s (%zu data compared)\n",
                  diff ? "DIFFERS" : "identical bit for bit",
                  static_cast<std::size_t>(j["data_compared"]));
  }
  if (diff)
    throw Failure("state differs from the sequential run: first differing datum " + diff->datum +
                  " (byte " + std::to_string(diff->offset) + ", " +
                  std::to_string(diff->differing_bytes) + " bytes differ)");
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
    cmd->add_flag("--check", c->check,
                  "Compare the final state with a sequential run, bit for bit");
    cmd->add_option("--starpu-sched", c->starpu_sched,
                    "StarPU scheduler of --policy starpu (default lws; eager, ws, prio, dmda...)");
    cmd->add_flag("--no-pin", c->no_pin, "Do not bind threads to cores");
    cmd->add_flag("--json", c->json, "Print one JSON object");
    cmd->callback([c] { run_live(*c); });
  }
}

}  // namespace tgraph::app
