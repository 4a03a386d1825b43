// SPDX-License-Identifier: MIT
// The scaling sweep: per scene one reference run (the uninstrumented engine's sequential wall
// time, timed as run_live times it), then at each thread count every method's live run with
// its observed pass (threads' busy and waiting time) and the observed sequential pass of the
// same run (the task bodies' sequential time), reduced to one record each.
#include "tgraph/experiment/scaling.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <iomanip>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "common.hpp"
#include "scaling_ode.hpp"
#include "tgraph/experiment/threads.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/graph/fixed.hpp"
#include "tgraph/measure/capture.hpp"
#include "tgraph/measure/engine.hpp"
#include "tgraph/measure/live.hpp"
#include "tgraph/measure/method.hpp"
#include "tgraph/measure/validate.hpp"
#include "tgraph/model/cost_model.hpp"
#include "tgraph/model/simulator.hpp"
#include "tgraph/partition/strategy.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/policy.hpp"
#include "tgraph/samples/scene.hpp"
#include "tgraph/viz/series_chart.hpp"

namespace tgraph::experiment {
namespace {

using detail::join;

namespace tp = tgraph::partition;
namespace tr = tgraph::replay;
namespace meas = tgraph::measure;

// The partition strategies the issue measures, then every baseline policy.
const std::vector<std::string> kDefaultMethods = {"owner",   "metis",     "sticky", "worksteal",
                                                  "barrier", "omp-tasks", "starpu"};

// A record's policy and method names: ode::choose_method's for an ODE scene, else measure's.
std::pair<std::string, std::string> policy_and_method(const ScalingScene& s,
                                                      const std::string& method) {
  if (s.ode) return detail::ode_policy_and_method(method);
  const meas::MethodChoice m = meas::choose_method(method);
  return {std::string(tr::to_string(m.policy)), meas::method_name(m)};
}

samples::SceneOptions scene_options(const ScalingScene& s) {
  samples::SceneOptions so;
  so.subobjects = s.subobjects;
  return so;
}

meas::EngineFactory factory(const ScalingScene& s) {
  return [scene = s.scene, so = scene_options(s)] { return meas::make_live_engine(scene, so); };
}

// The scene's sequential wall time, as run_live times it beside a run at min(largest thread
// count, 4) threads: the uninstrumented engine pinned on each of that many cores, the fastest
// core's median. The run itself (work stealing: no partitioner) is not reported.
ScalingReference reference_of(const ScalingScene& s, const ScalingPlan& p) {
  meas::LiveOptions o =
      detail::live_options(std::min<std::uint32_t>(p.threads.empty() ? 1 : p.threads.back(), 4),
                           s.steps, p.repeat, false);
  o.policy = tr::Policy::kWorksteal;
  const meas::LiveResult r = meas::run_live(factory(s), nullptr, o);
  ScalingReference ref;
  ref.scene = s.label();
  ref.steps = s.steps;
  ref.cores_timed = static_cast<std::uint32_t>(r.baseline_core_pass_wall_ns.size());
  ref.sequential_wall_ns = r.baseline_wall_ns;
  return ref;
}

// One live run of METHOD on K threads, R timed passes (measure::run_live), without its
// own baseline (the scene's reference stands for it), with the observed passes.
meas::LiveResult live_run(const ScalingScene& s, const std::string& method, std::uint32_t k,
                          const ScalingPlan& p) {
  const meas::MethodChoice m = meas::choose_method(method);
  meas::LiveOptions o = detail::live_options(k, s.steps, p.repeat, true);
  o.baseline = false;
  o.keep_assignments = m.policy == tr::Policy::kPartition;
  const std::optional<tp::StepPartitioner> part =
      meas::live_partitioner(m, meas::live_strategy_options(o), o);  // as `tgraph run` partitions
  return meas::run_live(factory(s), part ? &*part : nullptr, o);
}

// The fields every record has: the scene, the method's names, threads and steps.
ScalingRecord record_head(const ScalingScene& s, const std::string& method, std::uint32_t k) {
  ScalingRecord rec;
  rec.scene = s.label();
  std::tie(rec.policy, rec.method) = policy_and_method(s, method);
  rec.threads = k;
  rec.steps = s.steps;
  return rec;
}

ScalingRecord record_of(const ScalingScene& s, const std::string& method, std::uint32_t k,
                        const meas::LiveResult& r, const ScalingReference& ref) {
  ScalingRecord rec = record_head(s, method, k);
  rec.wall_ns = r.wall_ns;
  rec.sequential_wall_ns = ref.sequential_wall_ns;
  const double sequential = static_cast<double>(ref.sequential_wall_ns);
  if (r.wall_ns > 0) rec.speedup = sequential / static_cast<double>(r.wall_ns);
  double serial = 0, busy = 0, thread_time = 0;
  for (std::uint64_t ns : meas::live_serial_work(r)) serial += static_cast<double>(ns);
  for (const meas::LiveStepMeasure& st : r.steps) {
    rec.partitioned_steps += st.partitioned ? 1 : 0;
    for (const tr::StatsObserver::Thread& t : st.threads) {
      busy += static_cast<double>(t.busy_ns);
      thread_time += static_cast<double>(t.busy_ns + t.wait_ns + t.idle_ns);
    }
  }
  if (sequential > 0) rec.serial_share = serial / sequential;
  double sequential_work = 0;
  for (const meas::KindTime& kt : r.kinds)
    sequential_work += static_cast<double>(kt.instances) * kt.sequential_mean_ns;
  if (sequential_work > 0) rec.inflation = busy / sequential_work;
  if (thread_time > 0) rec.wait_share = std::max(0.0, thread_time - busy) / thread_time;
  rec.parks_per_step = static_cast<double>(r.parks) / std::max<double>(s.steps, 1);
  rec.attribution = r.attribution;
  return rec;
}

// The simulator's speed-up of live run `r` (partition policy) on `capture`, the same steps:
// its assignments when they fit the capture's steps, else the strategy's partition of the
// capture; its serial work per step; its spin budget (validate's prediction). Over the
// simulated uninstrumented engine: one processor, the capture's host time as serial work
// (the live speed-up's reference has no recording, partitioning or plans either).
double predicted_speedup(const Trace& capture, const std::string& method, std::uint32_t k,
                         const meas::LiveResult& r, model::CostModel model) {
  const TraceAssignment a = meas::live_assignment(capture, r.assignments, method, k, nullptr);
  const std::vector<std::uint64_t> serial = meas::live_serial_work(r);
  model.spin_budget_ns = meas::live_spin_budget_ns(k, tr::kDefaultSpinNs);
  double parallel = 0, sequential = 0;
  for (std::uint64_t ns : model::predicted_makespans(capture, a, model, &serial))
    parallel += static_cast<double>(ns);
  for (std::uint64_t ns :
       model::predicted_makespans(capture, meas::one_processor(capture), model, nullptr))
    sequential += static_cast<double>(ns);
  return parallel > 0 ? sequential / parallel : 0.0;
}

ScalingReference scene_reference(const ScalingScene& s, const ScalingPlan& p) {
  if (s.ode) return detail::ode_reference(s, p);
  return reference_of(s, p);
}

// One run of the sweep as its record: an ODE scene's through ode::run_scene, else the live
// run, with the simulator's prediction under the partition policy (`capture` taken once per
// scene, at the first partition run).
ScalingRecord run_record(const ScalingScene& s, const std::string& method, std::uint32_t k,
                         const ScalingPlan& p, const ScalingReference& ref,
                         const model::CostModel& model, std::optional<Trace>& capture) {
  if (s.ode) return detail::ode_record(s, method, k, p, record_head(s, method, k));
  const meas::LiveResult r = live_run(s, method, k, p);
  ScalingRecord rec = record_of(s, method, k, r, ref);
  const meas::MethodChoice m = meas::choose_method(method);
  if (m.policy == tr::Policy::kPartition) {
    if (!capture) capture = meas::capture_trace(s.scene, s.steps, scene_options(s));
    rec.predicted_speedup = predicted_speedup(*capture, m.method, k, r, model);
    if (rec.speedup > 0) rec.predicted_over_live = rec.predicted_speedup / rec.speedup;
  }
  return rec;
}

ScalingMiss miss_of(const ScalingScene& s, const std::string& method, std::uint32_t k,
                    std::string reason) {
  const auto [policy, name] = policy_and_method(s, method);
  return {s.label(), policy, name, k, std::move(reason)};
}

viz::SeriesChart speedup_chart(const ScalingResult& res, const ScalingScene& sc) {
  const ScalingPlan& p = res.plan;
  const std::string scene = sc.label();
  viz::SeriesChart c;
  c.title = "Speed-up against threads: " + scene;
  std::uint32_t steps = 0;
  for (const ScalingReference& ref : res.references)
    if (ref.scene == scene) steps = ref.steps;
  c.subtitle = "live run (" + std::to_string(steps) + " steps) / uninstrumented engine, " +
               res.machine.summary();
  c.x_title = "threads";
  c.y_title = "speed-up over sequential (x)";
  c.log2_x = true;
  c.log2_y = true;
  viz::Series ideal{"ideal (= threads)", viz::SeriesKind::kReference, 0, {}};
  for (std::uint32_t k : p.threads)
    ideal.points.push_back({static_cast<double>(k), static_cast<double>(k)});
  c.series.push_back(std::move(ideal));
  std::uint32_t colour = 0;
  for (const std::string& method : p.methods_of(sc)) {
    viz::Series s{method, viz::SeriesKind::kMeasured, colour++, {}};
    for (const ScalingRecord& r : res.records)
      if (r.scene == scene && r.method == policy_and_method(sc, method).second && r.speedup > 0)
        s.points.push_back({static_cast<double>(r.threads), r.speedup});
    if (!s.points.empty()) c.series.push_back(std::move(s));
  }
  if (!p.threads.empty() && p.threads.back() > p.cores)
    c.marks.push_back(
        {static_cast<double>(p.cores), std::to_string(p.cores) + " cores: oversubscribed beyond"});
  return c;
}

std::string results_csv(const ScalingResult& res) {
  std::ostringstream csv;
  csv << "scene,policy,method,threads,speedup,serial_share,inflation,wait_share,parks_per_step,"
         "partitioned_steps,predicted_speedup,predicted_over_live,steps,wall_ns,"
         "sequential_wall_ns,world_speedup,check\n";
  csv << std::setprecision(6);
  for (const ScalingRecord& r : res.records) {
    csv << r.scene << ',' << r.policy << ',' << r.method << ',' << r.threads << ',' << r.speedup
        << ',' << r.serial_share << ',' << r.inflation << ',' << r.wait_share << ','
        << r.parks_per_step << ',' << r.partitioned_steps << ',' << r.predicted_speedup << ','
        << r.predicted_over_live << ',' << r.steps << ',' << r.wall_ns << ','
        << r.sequential_wall_ns << ',';
    if (r.world_speedup) csv << *r.world_speedup;
    csv << ',' << r.check << '\n';
  }
  return csv.str();
}

void write_outputs(ScalingResult& res) {
  namespace fs = std::filesystem;
  const std::string dir = res.plan.out_dir;
  std::vector<std::pair<std::string, std::string>> files;
  files.emplace_back("results.csv", results_csv(res));
  for (const ScalingScene& s : res.plan.scenes) {
    const viz::SeriesChart c = speedup_chart(res, s);
    if (c.series.size() < 2) continue;  // no measured line
    files.emplace_back("speedup-" + s.label() + ".svg",
                       viz::render_series_chart(c, viz::TimelineFormat::kSvg));
    files.emplace_back("speedup-" + s.label() + ".png",
                       viz::render_series_chart(c, viz::TimelineFormat::kPng));
  }
  res.files = {"results.json"};
  for (const auto& f : files) res.files.push_back(f.first);
  for (const auto& [name, content] : files)
    write_file_atomic((fs::path(dir) / name).string(), content);
  write_file_atomic((fs::path(dir) / "results.json").string(), scaling_json(res, 1) + "\n");
}

// ScalingOptions::scenes resolved: a default scene by its label, an ODE scene (its own step
// count, 40 when quick) in a build with tgraph::ode.
std::vector<ScalingScene> chosen_scenes(const std::vector<std::string>& names,
                                        const std::vector<ScalingScene>& defaults, bool quick) {
  std::vector<ScalingScene> out;
  std::vector<std::string> known;
  for (const ScalingScene& d : defaults) known.push_back(d.label());
  for (const std::string& name : names) {
    const auto d = std::find_if(defaults.begin(), defaults.end(),
                                [&](const ScalingScene& x) { return x.label() == name; });
    if (d != defaults.end()) {
      out.push_back(*d);
      continue;
    }
    if (const std::optional<ScalingScene> o = detail::ode_scene(name, quick)) {
      out.push_back(*o);
      continue;
    }
    for (const std::string& n : detail::ode_scene_names()) known.push_back(n);
    throw OptionError("scenes",
                      "unknown scene '" + name + "' (expected " + join(known, ", ") + ")");
  }
  return out;
}

}  // namespace

std::string ScalingScene::label() const {
  return subobjects ? scene + "-s" + std::to_string(*subobjects) : scene;
}

std::vector<std::uint32_t> scaling_thread_list(std::uint32_t cores) {
  cores = std::max(cores, 1u);
  std::vector<std::uint32_t> out;
  for (std::uint32_t k = 1; k <= cores; k *= 2) out.push_back(k);
  if (out.back() != cores) out.push_back(cores);
  return out;
}

std::size_t ScalingPlan::runs() const {
  std::size_t n = 0;
  for (const ScalingScene& s : scenes) n += 1 + methods_of(s).size() * threads.size();
  return n;
}

const std::vector<std::string>& ScalingPlan::methods_of(const ScalingScene& scene) const {
  return scene.ode ? ode_methods : methods;
}

Invocation ScalingPlan::invocation() const {
  Invocation inv{"scaling", {}};
  if (quick) inv.settings.push_back({"quick", std::nullopt});
  inv.settings.push_back({"threads", join(threads)});
  const bool any_ode =
      std::any_of(scenes.begin(), scenes.end(), [](const ScalingScene& x) { return x.ode; });
  const bool all_ode = any_ode && std::all_of(scenes.begin(), scenes.end(),
                                              [](const ScalingScene& x) { return x.ode; });
  // A mix of scenes under the default methods: each kind's own defaults, not one list.
  if (all_ode)
    inv.settings.push_back({"methods", join(ode_methods)});
  else if (!any_ode || methods_given)
    inv.settings.push_back({"methods", join(methods)});
  if (scenes_given) {
    std::vector<std::string> labels;
    for (const ScalingScene& x : scenes) labels.push_back(x.label());
    inv.settings.push_back({"scenes", join(labels)});
  }
  if (!scenes.empty() &&
      std::all_of(scenes.begin(), scenes.end(),
                  [&](const ScalingScene& x) { return x.steps == scenes.front().steps; }) &&
      scenes.size() > 1)
    inv.settings.push_back({"steps", std::to_string(scenes.front().steps)});
  inv.settings.push_back({"repeat", std::to_string(repeat)});
  if (!calibration.empty()) inv.settings.push_back({"calibration", calibration});
  inv.settings.push_back({"out", out_dir});
  return inv;
}

std::string ScalingPlan::command() const { return words_of(words, invocation()); }

ScalingPlan plan_scaling(const ScalingOptions& o, std::uint32_t cores) {
  ScalingPlan p;
  p.cores = std::max(cores, 1u);
  p.quick = o.quick;
  p.out_dir = o.out.empty() ? "tgraph-experiment-scaling" : o.out;
  p.words = o.words;
  // Read now, so that a bad file stops the sweep before its first run, not after hours.
  if (!o.calibration.empty()) (void)model::select_cost_model("calibrated", o.calibration);
  p.calibration = o.calibration;
  if (o.steps && *o.steps == 0) throw OptionError("steps", "must be at least 1");
  if (o.repeat && *o.repeat == 0) throw OptionError("repeat", "must be at least 1");
  if (!o.threads.empty())
    p.threads = thread_counts(o.threads);
  else if (o.quick)
    p.threads = {1, 2};
  else
    p.threads = scaling_thread_list(p.cores);
  // The step counts: bars64's 20 (the independent experiment's), falling64's 60 (up to
  // and past its first contacts), torso's 60, cloth256 cut 64 ways for 5 (a step is ~0.2 s).
  p.scenes = {{"bars64", std::nullopt, o.quick ? 2u : 20u},
              {"falling64", std::nullopt, o.quick ? 3u : 60u},
              {"torso", std::nullopt, o.quick ? 3u : 60u},
              {"cloth256", 64, o.quick ? 1u : 5u}};
  if (!o.scenes.empty()) p.scenes = chosen_scenes(o.scenes, p.scenes, o.quick);
  p.scenes_given = !o.scenes.empty();
  p.methods_given = !o.methods.empty();
  if (o.steps)
    for (ScalingScene& s : p.scenes) s.steps = *o.steps;
  if (std::any_of(p.scenes.begin(), p.scenes.end(), [](const ScalingScene& s) { return s.ode; }))
    p.ode_methods =
        o.methods.empty() ? detail::default_ode_methods() : detail::checked_ode_methods(o.methods);
  if (std::none_of(p.scenes.begin(), p.scenes.end(),
                   [](const ScalingScene& s) { return !s.ode; })) {
    // Only ODE scenes: the built-in scenes' methods are not run.
  } else if (o.methods.empty() && o.quick) {
    // A smoke run: a strategy that keeps its assignment, one that rebalances, and the two
    // baselines of the paper (the others cost the most per run here: StarPU's start-up,
    // METIS on every partitioned step).
    p.methods = {"owner", "sticky", "worksteal", "barrier"};
  } else if (o.methods.empty()) {
    p.methods = kDefaultMethods;
#ifndef TGRAPH_HAVE_STARPU
    p.methods.erase(std::find(p.methods.begin(), p.methods.end(), "starpu"));
    p.notes.push_back("starpu: not in this build (libstarpu-dev was not found), no starpu runs");
#endif
  } else {
    p.methods = detail::check_methods(o.methods);
  }
  p.repeat = o.repeat.value_or(1);
  if (p.threads.back() > p.cores)
    p.notes.push_back("thread counts above this machine's " + std::to_string(p.cores) +
                      " cores run oversubscribed: they measure the overheads, not scaling");
  return p;
}

ScalingResult run_scaling(const ScalingOptions& options, Progress& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  ScalingResult res = detail::start_experiment<ScalingResult>(options, plan_scaling, progress);
  const ScalingPlan& p = res.plan;
  std::set<std::string> methods;  // the built-in scenes' and the ODE scenes' that run
  for (const ScalingScene& s : p.scenes)
    methods.insert(p.methods_of(s).begin(), p.methods_of(s).end());
  progress.note("experiment scaling on " + res.machine.summary() + ": " +
                std::to_string(p.scenes.size()) + " scenes, " + std::to_string(methods.size()) +
                " methods, " + std::to_string(p.threads.size()) + " thread counts; " +
                std::to_string(p.runs()) + " runs");
  for (const std::string& n : p.notes) progress.note(n);
  // The partition runs' predictions: --calibration, else the default calibration file when
  // there is one.
  const model::CostModel model = model::select_cost_model("calibrated", p.calibration);
  progress.note("predictions: cost model " + model.source);

  for (const ScalingScene& s : p.scenes) {
    const std::string label = s.label();
    progress.begin(label + " reference");
    ScalingReference ref;
    try {
      ref = scene_reference(s, p);
      progress.end(label + " (" + std::to_string(s.steps) + " steps): sequential " +
                   fixed(static_cast<double>(ref.sequential_wall_ns) / 1e6, 1) +
                   (s.ode ? std::string(" ms (ODE self-threaded)")
                          : " ms (uninstrumented engine, fastest of " +
                                std::to_string(ref.cores_timed) + " cores)"));
    } catch (const std::exception& e) {
      progress.end(label + ": reference run failed: " + e.what());
      for (std::uint32_t k : p.threads)
        for (const std::string& method : p.methods_of(s))
          res.failed.push_back(miss_of(s, method, k, std::string("reference run: ") + e.what()));
      continue;
    }
    res.references.push_back(ref);
    // The capture the partition runs' predictions simulate (taken once per scene).
    std::optional<Trace> capture;
    // Every method at one thread count before the next count: drift of the machine over the
    // sweep falls on thread counts alike, not on one method.
    for (std::uint32_t k : p.threads)
      for (const std::string& method : p.methods_of(s)) {
        const std::string run = label + " " + method + " K=" + std::to_string(k);
        progress.begin(run);
        try {
          const ScalingRecord rec = run_record(s, method, k, p, ref, model, capture);
          progress.end(run + ": speed-up " + fixed(rec.speedup, 2) +
                       (rec.world_speedup
                            ? ", world " + fixed(*rec.world_speedup, 2) + ", check " + rec.check
                            : std::string()) +
                       ", serial " + fixed(rec.serial_share, 3) +
                       (rec.ode ? std::string()
                                : ", inflation " + fixed(rec.inflation, 2) + ", wait " +
                                      fixed(rec.wait_share, 2)) +
                       ", parks/step " + fixed(rec.parks_per_step, 1) + ", partitioned " +
                       std::to_string(rec.partitioned_steps) + "/" + std::to_string(s.steps) +
                       (rec.predicted_speedup > 0
                            ? ", predicted " + fixed(rec.predicted_speedup, 2) + " (x" +
                                  fixed(rec.predicted_over_live, 2) + ")"
                            : std::string()));
          res.records.push_back(rec);
        } catch (const UsageError& e) {
          // The policy refuses this configuration (StarPU above its CPU workers): not a failure.
          progress.end(run + ": skipped: " + e.what());
          res.skipped.push_back(miss_of(s, method, k, e.what()));
        } catch (const std::exception& e) {
          progress.end(run + ": failed: " + e.what());
          res.failed.push_back(miss_of(s, method, k, e.what()));
        }
      }
  }
  progress.finish();
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  write_outputs(res);
  return res;
}

std::string scaling_json(const ScalingResult& res, int indent) {
  nlohmann::json j;
  j["experiment"] = "scaling";
  j["command"] = res.plan.command();
  j["definitions"] = {
      {"speedup",
       "the scene's sequential wall time (uninstrumented engine, fastest of the first "
       "min(threads, 4) cores, median of the passes) / the live run's wall time (median pass)"},
      {"serial_share",
       "main thread's record + partition (waited for) + prepare, summed over the steps / the "
       "sequential wall time"},
      {"inflation",
       "threads' busy time in task bodies (observed pass) / the same task instances' "
       "sequential time (per kind: instances x mean of the observed sequential pass)"},
      {"wait_share",
       "threads' time outside task bodies (waiting, parked, searching, idle) / (threads x "
       "executor wall time), observed pass"},
      {"parks_per_step", "parks (futex waits) of all threads / steps, first timed pass"},
      {"partitioned_steps", "steps at which the partitioner was called, first timed pass"},
      {"predicted_speedup",
       "partition policy: the built-in simulator's makespan of a capture of the same steps "
       "with the live run's assignments and serial work per step (--calibration, else the "
       "default calibration), "
       "against its one-processor makespan with the capture's host time (the uninstrumented "
       "engine); null for the baselines"},
      {"predicted_over_live", "predicted_speedup / speedup; null for the baselines"},
      {"attribution",
       "the observed pass's lost processor time (threads x wall - sequential work) by cause, "
       "summed over the steps: {lost_ns, causes: {serial, imbalance, dependency_wait, handoff, "
       "interruption, inflation, runtime, starvation, residual}} (docs/explain.md)"},
      {"ode_scenes",
       "an ODE scene's record is ode::run_scene's (tgraph run --scene ode-* --check): speedup "
       "(whole step, collision included) and world_speedup (the world step alone) against ODE "
       "self-threaded timed in the same run, check and max_abs_diff against its final state; "
       "serial_share = collision + partitioning / that sequential wall time; parks_per_step "
       "and partitioned_steps of the first timed pass; inflation, wait_share, the prediction "
       "and attribution not measured (null); its reference is ODE self-threaded"}};
  j["machine"] = res.machine.summary();
  j["cores"] = res.plan.cores;
  j["date"] = res.date;
  j["seconds"] = res.seconds;
  j["threads"] = res.plan.threads;
  j["methods"] = res.plan.methods;
  if (!res.plan.ode_methods.empty()) j["ode_methods"] = res.plan.ode_methods;
  j["repeat"] = res.plan.repeat;
  j["notes"] = res.plan.notes;
  j["references"] = nlohmann::json::array();
  for (const ScalingReference& r : res.references)
    j["references"].push_back({{"scene", r.scene},
                               {"steps", r.steps},
                               {"cores_timed", r.cores_timed},
                               {"sequential_wall_ns", r.sequential_wall_ns}});
  j["scaling"] = nlohmann::json::array();
  for (const ScalingRecord& r : res.records) {
    j["scaling"].push_back(
        {{"scene", r.scene},
         {"policy", r.policy},
         {"method", r.method},
         {"threads", r.threads},
         {"speedup", r.speedup},
         {"serial_share", r.serial_share},
         {"inflation", r.ode ? nlohmann::json(nullptr) : nlohmann::json(r.inflation)},
         {"wait_share", r.ode ? nlohmann::json(nullptr) : nlohmann::json(r.wait_share)},
         {"parks_per_step", r.parks_per_step},
         {"partitioned_steps", r.partitioned_steps},
         {"predicted_speedup",
          r.predicted_speedup > 0 ? nlohmann::json(r.predicted_speedup) : nlohmann::json(nullptr)},
         {"predicted_over_live", r.predicted_over_live > 0 ? nlohmann::json(r.predicted_over_live)
                                                           : nlohmann::json(nullptr)},
         {"attribution", r.attribution
                             ? nlohmann::json::parse(explain::attribution_json(*r.attribution))
                             : nlohmann::json(nullptr)}});
    if (r.ode) {
      nlohmann::json& rec = j["scaling"].back();
      rec["world_speedup"] = r.world_speedup.value_or(0.0);
      rec["check"] = r.check;
      if (r.check != "identical") rec["max_abs_diff"] = r.max_abs_diff;
    }
  }
  for (const auto& [key, list] :
       {std::pair{"skipped", &res.skipped}, std::pair{"failed", &res.failed}}) {
    j[key] = nlohmann::json::array();
    for (const ScalingMiss& m : *list)
      j[key].push_back({{"scene", m.scene},
                        {"policy", m.policy},
                        {"method", m.method},
                        {"threads", m.threads},
                        {"reason", m.reason}});
  }
  j["files"] = res.files;
  return j.dump(indent);
}

std::string scaling_text(const ScalingResult& res) {
  std::ostringstream s;
  s << "Live scaling on " << res.machine.summary() << " (" << res.date << ")\n";
  for (const ScalingReference& r : res.references)
    s << "  " << r.scene << ": " << r.steps << " steps, sequential "
      << fixed(static_cast<double>(r.sequential_wall_ns) / 1e6, 1) << " ms\n";
  s << std::left << std::setw(14) << "scene" << std::setw(11) << "method" << std::right
    << std::setw(4) << "K" << std::setw(9) << "speed-up" << std::setw(8) << "serial"
    << std::setw(10) << "inflation" << std::setw(7) << "wait" << std::setw(12) << "parks/step"
    << std::setw(13) << "partitioned" << std::setw(11) << "predicted" << std::setw(11)
    << "pred/live"
    << "\n";
  for (const ScalingRecord& r : res.records)
    s << std::left << std::setw(14) << r.scene << std::setw(11) << r.method << std::right
      << std::setw(4) << r.threads << std::setw(9) << fixed(r.speedup, 2) << std::setw(8)
      << fixed(r.serial_share, 3) << std::setw(10)
      << (r.ode ? std::string("-") : fixed(r.inflation, 2)) << std::setw(7)
      << (r.ode ? std::string("-") : fixed(r.wait_share, 2)) << std::setw(12)
      << fixed(r.parks_per_step, 1) << std::setw(13)
      << (std::to_string(r.partitioned_steps) + "/" + std::to_string(r.steps)) << std::setw(11)
      << (r.predicted_speedup > 0 ? fixed(r.predicted_speedup, 2) : std::string("-"))
      << std::setw(11)
      << (r.predicted_over_live > 0 ? fixed(r.predicted_over_live, 2) : std::string("-"))
      << (r.ode ? "  world " + fixed(r.world_speedup.value_or(0.0), 2) + ", " + r.check
                : std::string())
      << "\n";
  for (const ScalingMiss& m : res.skipped)
    s << "skipped " << m.scene << " " << m.method << " K=" << m.threads << ": " << m.reason << "\n";
  for (const ScalingMiss& m : res.failed)
    s << "FAILED " << m.scene << " " << m.method << " K=" << m.threads << ": " << m.reason << "\n";
  s << "files in " << res.plan.out_dir << ":";
  for (const std::string& f : res.files) s << " " << f;
  s << "\n";
  return s.str();
}

}  // namespace tgraph::experiment
