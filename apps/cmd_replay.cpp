// SPDX-License-Identifier: MIT
// `tgraph replay` (measure::replay_command) and `tgraph run` (measure::run_scene).
#include <algorithm>
#include <cstdint>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "commands.hpp"
#include "flags.hpp"
#include "ode_verbs.hpp"
#include "tgraph/measure/live.hpp"
#include "tgraph/measure/replay_command.hpp"
#include "tgraph/measure/verify.hpp"
#include "tgraph/viz/timeline.hpp"

namespace tgraph::app {
namespace {

namespace tr = tgraph::replay;
namespace meas = tgraph::measure;

using Words = std::map<std::string, bool>;  // a yes-or-no flag's words
// The flags `replay` and `run` share, bound to `exec`.
void add_exec_flags(CLI::App* cmd, tr::ExecOptions& exec, bool& json) {
  using enum CwMode;
  exec.threads = default_threads();
  exec.partition.timeout_exits = true;  // a body that never returns after the watchdog: exit 1
  cmd->add_option("--threads,-k", exec.threads, "Threads (processors)");
  cmd->add_option("--spin-ns", exec.spin_ns, "Spin this long before parking a waiting thread");
  auto timeout = [&exec](double s) {
    exec.partition.timeout_ms = s == 0.0 ? 0 : static_cast<std::int64_t>(std::max(s * 1e3, 1.0));
  };
  cmd->add_option_function<double>("--timeout", timeout, "Partition policy's watchdog (seconds)")
      ->check(CLI::Range(0.0, 1e6));
  auto cw = [&exec](bool serialize) { exec.cw = serialize ? kSerialize : kReduce; };
  cmd->add_option_function<bool>("--cw", cw, "CW writes across threads: reduce or serialize")
      ->transform(CLI::CheckedTransformer(Words{{"reduce", false}, {"serialize", true}}));
  auto rule = [&exec](const std::string& r) {
    exec.barrier.rule = barrier_rule_flag(r, "--barrier-rule");
  };
  cmd->add_option_function<std::string>("--barrier-rule", rule, "omp-for, level or operation");
  cmd->add_option_function<std::string>("--openmp-runtime", tr::use_openmp_runtime, "gnu or llvm");
  add_enum(cmd, "--reduce-scope", exec.reduce_scope,
           {ReduceScope::kPerWriter, ReduceScope::kPerThread},
           "Dynamic policies' CW temporaries: per-writer or per-thread");
  cmd->add_option("--omp-wait", exec.omp_tasks.wait_depend, "omp-tasks: all or depend")
      ->transform(CLI::CheckedTransformer(Words{{"all", false}, {"depend", true}}));
  cmd->add_option("--starpu-sched", exec.starpu.sched, "StarPU's scheduler (default lws)");
  cmd->add_option("--pin", exec.pin, "Bind thread p to the p-th core: on (default) or off")
      ->transform(CLI::CheckedTransformer(Words{{"on", true}, {"off", false}}));
  cmd->add_flag("--no-pin{false}", exec.pin, "Same as --pin off");
  cmd->add_flag("--no-combine{false}", exec.partition.combine, "A processor per reducer");
  cmd->add_flag("--no-steal{false}", exec.partition.steal, "No thread runs another's tasks");
  cmd->add_flag("--json", json, "Print one JSON object");
}

// A JSON report naming the timeline file written beside it ("timeline": what tgraph explain
// RESULT.json explains); text reports and runs without a timeline as they are.
std::string named_timeline(const std::string& report, const std::string& timeline, bool json) {
  if (!json || timeline.empty()) return report;
  nlohmann::json j = nlohmann::json::parse(report);
  j["timeline"] = timeline;
  return j.dump() + "\n";
}

}  // namespace

void add_replay_verbs(CLI::App& app) {
  auto c = std::make_shared<meas::ReplayCommand>();
  auto a = std::make_shared<Args>();  // policy, timeline, chrome
  auto* cmd = app.add_subcommand("replay", "Replay a trace's steps on threads (synthetic bodies)");
  cmd->add_option("trace", c->trace, "Trace file (.tgt)")->required();
  cmd->add_option("assignment", c->assignment, "Assignment file (.tga; default: --method)");
  add_exec_flags(cmd, c->replay.exec, c->json);
  cmd->add_option("--policy", a->policy, "Policy: " + tr::policy_list("or") + " (default partition)");
  cmd->add_option("--method", c->method, "Strategy without assignment (default: owner or list)");
  cmd->add_option("--steps", c->replay.steps, "Steps to replay (default: all)");
  cmd->add_option("--first-step", c->replay.first_step, "First step replayed");
  cmd->add_option("--repeat", c->replay.repeat, "Timed passes (medians reported; default 3)");
  cmd->add_option("--timeline", a->timeline,
                  "Write the observed pass's timeline (gzip-compressed JSON; tgraph explain, "
                  "timeline and report read it)");
  cmd->add_option("--chrome", a->chrome, "Write it as Chrome/Perfetto trace events");
  cmd->add_option("--scale", c->replay.synthetic.cost_scale, "Multiply every recorded cost");
  cmd->add_option("--model", c->model.model, "Prediction's cost model: calibrated or ideal")
      ->check(CLI::IsMember({"ideal", "calibrated"}));
  cmd->add_option("--calibration", c->model.calibration, "Calibration file for the prediction");
  cmd->add_flag("--no-touch{false}", c->replay.synthetic.touch, "Bodies only spin (no data)");
  cmd->add_flag("--no-baseline{false}", c->replay.sequential_baseline, "No sequential passes");
  cmd->callback([a, c] {
    c->replay.policy = policy_flag(a->policy.empty() ? "partition" : a->policy, "--policy");
    c->timeline = !a->timeline.empty() || !a->chrome.empty();
    const meas::ReplayReport r = meas::replay_command(*c);
    for (const std::string& w : r.result.warnings) warn(w);
    if (!a->timeline.empty()) write_timeline(a->timeline, *r.timeline);
    if (!a->chrome.empty()) write_file_atomic(a->chrome, viz::chrome_trace(*r.timeline));
    std::cout << named_timeline(r.report, a->timeline, c->json);
  });

  auto run = std::make_shared<meas::SceneRun>();
  meas::LiveOptions& live = run->live;
  a = std::make_shared<Args>();  // method and policy
  a->method = "owner";
  cmd = app.add_subcommand("run", "Run a scene live through the executor (engine bodies)");
  cmd->add_option("--scene", run->scene, "Built-in scene or scene file")->required();
  add_exec_flags(cmd, live.exec, run->json);
  cmd->add_option("--method", a->method, "Strategy (owner, metis...) or baseline (worksteal...)");
  cmd->add_option("--policy", a->policy, "Override the policy");
  cmd->add_option("--steps", run->steps, "Steps (default: the scene's)");
  cmd->add_option("--split", run->scene_options.split, "Force-field tasks per deformable object")
      ->check(CLI::Range(1, 1024));
  cmd->add_option("--repeat", live.repeat, "Timed passes (medians reported; default 1)");
  cmd->add_flag("--no-reuse{false}", live.reuse_structure, "Record every step");
  cmd->add_flag("--repartition-every-step", live.repartition_every_step, "Partition every step");
  cmd->add_option("--horizon", live.repartition_horizon, "Steps a repartition must pay off in")
      ->check(CLI::Range(1, 1000000));
  cmd->add_flag("--foreground-partition{false}", live.background_partition, "Steps wait for it");
  cmd->add_flag("--no-elide-waits{false}", live.exec.partition.elide_waits, "Keep implied waits");
  cmd->add_option("--cost-stride", live.cost_stride, "Time loop iterations 0, 1, every N-th");
  cmd->add_flag("--no-observe{false}", live.observe, "Skip the observed passes");
  cmd->add_option("--timeline", a->timeline,
                  "Write the observed pass's timeline, serial phases included (gzip-compressed "
                  "JSON; tgraph explain reads it)");
  auto check = std::make_shared<std::string>();
  cmd->add_option("--check", *check,
                  "Compare the final state with the twin (default: a sequential run with the "
                  "same reductions, bit for bit) or the plain run (the engine's own sequential "
                  "steps, within rounding)")
      ->expected(0, 1)
      ->default_str("twin")
      ->check(CLI::IsMember({"twin", "plain"}));
  auto verify = std::make_shared<bool>(false);
  cmd->add_flag("--verify-accesses", *verify,
                "Instead of timing: run every task between checksums of the state and again "
                "with its undeclared data perturbed, and list the writes and reads it does not "
                "declare (exit 1 when any; docs/instrumenting.md)");
  run->strategy.values.sticky_threshold = meas::live_sticky_threshold(live);  // unless --threshold
  add_strategy_flags(cmd, run->strategy);
  auto ode = std::make_shared<OdeFlags>();
  add_ode_flags(cmd, *ode);
  cmd->callback([a, run, verify, ode, check] {
    run->live.check = !check->empty();
    run->live.check_reference =
        *check == "plain" ? meas::CheckReference::kPlain : meas::CheckReference::kTwin;
    if (is_ode_scene(run->scene)) {  // ODE's scenes: tgraph::ode (apps/cmd_ode.cpp; plain always)
      // ODE posts calls with dependencies, never the data they touch: nothing to verify.
      if (*verify)
        throw UsageError("--verify-accesses: ODE's calls declare no data accesses (" +
                         run->scene + " is run through ODE's threading interface)");
      if (!a->timeline.empty())
        throw UsageError("--timeline: not written for ODE's scenes (" + run->scene +
                         "; tgraph capture --scene " + run->scene + " records the calls)");
      return run_ode(run->scene, run->steps, a->method, run->live.exec.threads, run->live.repeat,
                     run->live.check, run->json,
                     static_cast<double>(run->live.exec.partition.timeout_ms) / 1e3, *ode);
    }
    run->method = method_flags(a->method, a->policy);
    run->live.keep_timeline = !a->timeline.empty();
    if (!a->timeline.empty() && !run->live.observe)
      throw UsageError("--timeline needs the observed pass (drop --no-observe)");
    if (*verify) {
      const meas::VerifyRunReport v = meas::verify_scene(*run);
      std::cout << v.report << std::flush;
      if (!v.result.findings.empty())
        throw Failure(std::to_string(v.result.findings.size()) +
                      " wrong access declaration(s) found (listed in the report)");
      return;
    }
    const meas::SceneRunReport r = meas::run_scene(*run);
    if (!a->timeline.empty() && r.result.timeline) write_timeline(a->timeline, *r.result.timeline);
    std::cout << named_timeline(r.report, a->timeline, run->json) << std::flush;
    if (r.result.check == meas::Check::kDiffers)
      throw Failure("state differs from the " +
                    std::string(r.result.check_reference == meas::CheckReference::kPlain
                                    ? "plain run beyond rounding: "
                                    : "twin: ") +
                    to_string(*r.result.difference));
  });
}

}  // namespace tgraph::app
