// SPDX-License-Identifier: MIT
// `tgraph replay` (a trace's steps on real threads, synthetic bodies: measure::replay_trace)
// and `tgraph run` (live: the engine's own bodies through the executor: measure::run_live).
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <vector>

#include "commands.hpp"
#include "flags.hpp"
#include "tgraph/partition/assignment_io.hpp"
#include "tgraph/partition/simulator.hpp"
#include "tgraph/partition/strategy.hpp"
#include "tgraph/measure/live.hpp"
#include "tgraph/measure/replay_trace.hpp"
#include "tgraph/measure/report.hpp"
#include "tgraph/viz/timeline.hpp"

namespace tgraph::app {
namespace {

namespace tp = tgraph::partition;
namespace tr = tgraph::replay;
namespace meas = tgraph::measure;

// --timeout SECONDS as PartitionOptions::timeout_ms.
std::int64_t timeout_ms(double seconds) {
  if (!(seconds >= 0.0) || seconds > 1e6)
    throw UsageError("--timeout " + std::to_string(seconds) + ": expected 0 (off) to 1e6 seconds");
  return seconds == 0.0 ? 0
                        : std::max<std::int64_t>(1, static_cast<std::int64_t>(seconds * 1000.0));
}

// `--openmp-runtime gnu|llvm`: the OpenMP runtime the barrier and omp-tasks policies run on.
// tgraph is built against GCC's libgomp; for LLVM's libomp the process starts again with
// libomp preloaded (its libgomp-compatible entry points then serve every OpenMP construct of
// the process; one runtime per process, docs/replay.md). Returns only when `want` runs.
void use_openmp_runtime(const std::string& want) {
  if (want != "gnu" && want != "llvm")
    throw UsageError("--openmp-runtime: expected gnu or llvm, got '" + want + "'");
  if (want == tr::openmp_runtime()) return;
  if (want == "gnu")
    throw UsageError(
        "--openmp-runtime gnu: this process was started with LLVM's OpenMP runtime preloaded "
        "(LD_PRELOAD); start it without");
  const std::string lib(tr::llvm_openmp_library());
  if (lib.empty() || access(lib.c_str(), R_OK) != 0)
    throw UsageError("--openmp-runtime llvm: LLVM's OpenMP runtime is not installed (Debian "
                     "libomp-dev)" + (lib.empty() ? std::string() : ": no " + lib));
  if (std::getenv("TGRAPH_OPENMP_RESTARTED") != nullptr)
    throw Failure("--openmp-runtime llvm: preloading " + lib + " did not replace libgomp");
  // The same command line again, from /proc (NUL-separated arguments).
  std::ifstream in("/proc/self/cmdline", std::ios::binary);
  const std::string line((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::string> args;
  for (std::size_t b = 0; b < line.size();) {
    const std::size_t e = line.find('\0', b);
    args.push_back(line.substr(b, e == std::string::npos ? std::string::npos : e - b));
    if (e == std::string::npos) break;
    b = e + 1;
  }
  std::vector<char*> argv;
  for (std::string& arg : args) argv.push_back(arg.data());
  argv.push_back(nullptr);
  const char* old = std::getenv("LD_PRELOAD");
  const std::string preload = old != nullptr && *old != '\0' ? lib + ":" + old : lib;
  setenv("LD_PRELOAD", preload.c_str(), 1);
  setenv("TGRAPH_OPENMP_RESTARTED", "1", 1);
  std::cout.flush();
  execv("/proc/self/exe", argv.data());
  throw Failure("--openmp-runtime llvm: could not restart tgraph with " + lib);
}

// The flags `replay` and `run` share, bound to `exec`.
void add_exec_flags(CLI::App* cmd, Args& a, tr::ExecOptions& exec) {
  exec.threads = default_threads();
  exec.partition.timeout_exits = true;  // a body that never returns after the watchdog fired: exit 1
  cmd->add_option("--threads,-k", exec.threads, "Threads (processors)");
  cmd->add_option("--spin-ns", exec.spin_ns, "Spin this long before parking a waiting thread");
  cmd->add_option_function<double>(
      "--timeout", [&exec](double s) { exec.partition.timeout_ms = timeout_ms(s); },
      "Watchdog (partition policy): end a step that makes no progress for this many seconds, "
      "naming what each thread waits for (0: off; default 300)");
  cmd->add_option("--cw", a.cw, "CW writes across threads: reduce (default) or serialize")
      ->check(CLI::IsMember({"reduce", "serialize"}))
      ->each([&exec](const std::string& cw) {
        exec.cw = cw == "serialize" ? tr::CwMode::kSerialize : tr::CwMode::kReduce;
      });
  cmd->add_option_function<std::string>(
      "--barrier-rule",
      [&exec](const std::string& r) { exec.barrier.rule = barrier_rule_flag(r, "--barrier-rule"); },
      "Barrier policy's phases: omp-for (default; an omp for per operation, static schedule, "
      "nowait where no other thread's result is read), level (one per dependency level) or "
      "operation (one per run of same-kind tasks in program order, the paper's rule)");
  cmd->add_option_function<std::string>(
      "--openmp-runtime", [](const std::string& r) { use_openmp_runtime(r); },
      "OpenMP runtime of the barrier and omp-tasks policies: gnu (default; GCC's libgomp) or "
      "llvm (LLVM's libomp, preloaded into a restarted process)");
  cmd->add_option_function<std::string>(
      "--omp-wait",
      [&exec](const std::string& v) {
        if (v != "all" && v != "depend")
          throw UsageError("--omp-wait: expected all or depend, got '" + v + "'");
        exec.omp_tasks.wait_depend = v == "depend";
      },
      "omp-tasks: after each loop iteration, wait for every task (all: taskwait) or for the "
      "break task only (depend: OpenMP 5.0 taskwait depend)");
  cmd->add_option("--starpu-sched", exec.starpu.sched,
                  "StarPU scheduler of --policy starpu (default lws; eager, ws, prio, dmda...)");
  cmd->add_option_function<std::string>(
      "--pin",
      [&exec](const std::string& v) {
        if (v != "on" && v != "off")
          throw UsageError("--pin: expected on or off, got '" + v + "'");
        exec.pin = v == "on";
      },
      "Bind thread p of every policy to the p-th core, once per run: on (default) or off");
  cmd->add_flag_callback(
      "--no-pin", [&exec] { exec.pin = false; }, "Same as --pin off");
  cmd->add_flag_callback(
      "--no-combine", [&exec] { exec.partition.combine = false; },
      "Partition policy: run every reducer on its own processor (default: a dot product's "
      "reducer and scalar run on the last of its processors to arrive)");
  cmd->add_flag_callback(
      "--no-steal", [&exec] { exec.partition.steal = false; },
      "Partition policy: every task on its own processor (default: a thread that would wait "
      "runs ready tasks of the programs, its own first, then the most loaded processor's)");
  cmd->add_flag("--json", a.json, "Print one JSON object");
}

void replay(const Args& a, meas::ReplayOptions& o, const tp::NamedOptions& model) {
  const Trace trace = read_trace(a.input);
  o.policy = policy_flag(a.policy.empty() ? "partition" : a.policy, "--policy");
  std::optional<TraceAssignment> as;
  std::vector<std::uint64_t> predicted;
  tp::PartitionNotes notes;
  if (o.policy == tr::Policy::kPartition) {
    as = tp::load_or_partition(trace, a.input, a.assignment, a.method, o.exec.threads, &notes);
    for (const std::string& w : notes.warnings) warn(w);
    predicted = tp::predicted_makespans(trace, *as, model.cost_model());
  } else if (!a.assignment.empty()) {
    throw UsageError("an assignment file is only used by --policy partition");
  }
  if (o.first_step >= trace.steps.size() && !trace.steps.empty())
    throw UsageError("--first-step " + std::to_string(o.first_step) + ": the trace has " +
                     std::to_string(trace.steps.size()) + " steps");
  if (o.repeat == 0) throw UsageError("--repeat must be at least 1");
  tr::TimelineObserver timeline;
  const bool observe = !a.timeline.empty() || !a.chrome.empty();
  meas::ReplayResult r = meas::replay_trace(
      trace, as ? &*as : nullptr, o, as ? &predicted : nullptr, observe ? &timeline : nullptr);
  r.warnings = notes.warnings;
  if (!a.timeline.empty()) write_file_atomic(a.timeline, timeline_json(timeline.timeline()));
  if (!a.chrome.empty()) write_file_atomic(a.chrome, viz::chrome_trace(timeline.timeline()));
  const std::string label = as ? tp::assignment_label(a.assignment, a.method, notes) : a.assignment;
  std::cout << (a.json ? meas::to_json(r, a.input, label) + "\n" : meas::to_text(r, a.input, o.repeat));
}

// The live loop tests/measure/live_test.cpp exercises: measure::run_live on the samples engine.
void run(const Args& a, meas::LiveOptions& o, const tp::NamedOptions& strategy) {
  if (a.steps && *a.steps < 1) throw UsageError("--steps must be at least 1");
  if (o.repeat == 0) throw UsageError("--repeat must be at least 1");
  const meas::MethodChoice m = method_flags(a.method, a.policy);
  std::optional<tp::StepPartitioner> part;
  if (m.policy == tr::Policy::kPartition) part = tp::step_partitioner(m.method, strategy.options());
  samples::SceneOptions scene_options;
  scene_options.split = a.split;
  const int scene_steps = samples::make_scene(a.input, scene_options)->default_steps();  // InputError if unknown
  o.policy = m.policy;
  o.loop_share = strategy.values.loop_share;
  o.steps = static_cast<std::uint32_t>(a.steps.value_or(scene_steps));
  const std::string scene = a.input, method = meas::method_name(m);
  const meas::LiveResult r =
      meas::run_live([scene, scene_options] { return meas::make_live_engine(scene, scene_options); },
                     part ? &*part : nullptr, o);
  std::cout << (a.json ? meas::to_json(r, scene, method) + "\n"
                       : meas::to_text(r, scene, method, o.repeat))
            << std::flush;
  if (r.difference)
    throw Failure("state differs from the sequential run: " + to_string(*r.difference));
}

}  // namespace

void add_replay_verbs(CLI::App& app) {
  auto a = std::make_shared<Args>();
  auto o = std::make_shared<meas::ReplayOptions>();
  auto model = std::make_shared<tp::NamedOptions>();
  auto* cmd =
      app.add_subcommand("replay", "Replay a trace's steps on real threads (synthetic bodies)");
  cmd->add_option("trace", a->input, "Trace file (.tgt)")->required();
  cmd->add_option("assignment", a->assignment,
                  "Assignment file (.tga; partition policy; default: --method)");
  add_exec_flags(cmd, *a, o->exec);
  cmd->add_option("--policy", a->policy,
                  "partition (default), worksteal, barrier, starpu, omp-tasks or sequential");
  cmd->add_option("--method", a->method,
                  "Strategy used when no assignment file is given (default: owner when the "
                  "trace's tasks work on objects, else list)");
  cmd->add_option("--steps", o->steps, "Steps to replay (default: all)");
  cmd->add_option("--first-step", o->first_step, "First step replayed");
  cmd->add_option("--repeat", o->repeat, "Timed passes (medians reported; default 3)");
  cmd->add_option("--timeline", a->timeline, "Write the observed pass's timeline (JSON)");
  cmd->add_option("--chrome", a->chrome, "Write the observed pass as Chrome/Perfetto trace events");
  cmd->add_option("--scale", o->synthetic.cost_scale, "Multiply every recorded cost");
  cmd->add_option("--model", model->model,
                  "Cost model of the prediction: calibrated (default) or ideal")
      ->check(CLI::IsMember({"ideal", "calibrated"}));
  cmd->add_option("--calibration", model->calibration, "Calibration file for the prediction");
  cmd->add_flag_callback(
      "--no-touch", [o] { o->synthetic.touch = false; },
      "Synthetic bodies only spin (no data buffers)");
  cmd->add_flag_callback(
      "--no-baseline", [o] { o->sequential_baseline = false; }, "Do not time sequential passes");
  cmd->callback([a, o, model] { replay(*a, *o, *model); });

  a = std::make_shared<Args>();
  auto live = std::make_shared<meas::LiveOptions>();
  auto strategy = std::make_shared<tp::NamedOptions>();
  a->method = "owner";
  cmd = app.add_subcommand("run", "Run a scene live through the executor (engine bodies)");
  cmd->add_option("--scene", a->input, "Built-in scene or scene file")->required();
  add_exec_flags(cmd, *a, live->exec);
  cmd->add_option("--method", a->method,
                  "Strategy (owner, metis, scotch, sticky, list, roundrobin) or a baseline "
                  "(worksteal, barrier, starpu, omp-tasks, sequential)");
  cmd->add_option("--policy", a->policy, "Override the policy");
  cmd->add_option("--steps", a->steps, "Steps (default: the scene's)");
  cmd->add_option("--split", a->split,
                  "Deformable objects: split each internal force field into N tasks (overrides split=)")
      ->check(CLI::Range(1, 1024));
  cmd->add_option("--repeat", live->repeat, "Timed passes (medians reported; default 1)");
  cmd->add_flag_callback(
      "--no-reuse", [live] { live->reuse_structure = false; },
      "Record every step (default: rerun the last program while it repeats)");
  cmd->add_flag("--repartition-every-step", live->repartition_every_step,
                "Call the partitioner at every step (default: on change, or when a drift's "
                "gain over --horizon steps exceeds the cost of new plans)");
  cmd->add_option("--horizon", live->repartition_horizon,
                  "Steps over which a repartition must pay for itself (default 10)")
      ->check(CLI::Range(1, 1000000));
  cmd->add_flag_callback(
      "--foreground-partition", [live] { live->background_partition = false; },
      "The step waits for the partitioner (default: it runs on a helper thread and its "
      "assignment applies at the next step boundary)");
  cmd->add_flag_callback(
      "--no-elide-waits", [live] { live->exec.partition.elide_waits = false; },
      "One wait per cross-processor producer (default: implied waits dropped)");
  cmd->add_option("--cost-stride", live->cost_stride,
                  "Cost feedback times loop iterations 0, 1 and every N-th (default 8)");
  cmd->add_flag_callback(
      "--no-observe", [live] { live->observe = false; },
      "Skip the observed passes (per-thread and per-kind figures)");
  cmd->add_flag("--check", live->check,
                "Compare the final state with a sequential run of the same reduction order, bit "
                "for bit");
  strategy->values.sticky_threshold = meas::live_sticky_threshold(*live);  // unless --threshold
  add_strategy_flags(cmd, *strategy);
  cmd->callback([a, live, strategy] { run(*a, *live, *strategy); });
}

}  // namespace tgraph::app
