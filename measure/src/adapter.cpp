// SPDX-License-Identifier: MIT
// An outside engine's callbacks behind LiveEngine, and its live run; the verification of an
// engine's declared accesses live (verify.hpp).
#include "tgraph/measure/adapter.hpp"

#include <nlohmann/json.hpp>
#include <optional>
#include <unordered_map>
#include <utility>

#include "recorded_step.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/measure/report.hpp"
#include "tgraph/measure/verify.hpp"
#include "tgraph/partition/strategy.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/program_workload.hpp"
#include "tgraph/replay/thread_binding.hpp"
#include "tgraph/samples/tiled_heat.hpp"

namespace tgraph::measure {
namespace {


// The engine's state regions as the checker's storage, by datum of `g` (matched by name, in
// order for repeated names, sizes equal).
std::size_t set_storage(AccessChecker& checker, const StepGraph& g,
                        const std::vector<StateRegion>& regions) {
  std::unordered_map<std::string, std::vector<DatumId>> by_name;
  for (auto d = static_cast<DatumId>(g.data.size()); d-- > 0;) by_name[g.data[d].name].push_back(d);
  checker.clear_storage();
  std::size_t n = 0;
  for (const StateRegion& r : regions) {
    auto it = by_name.find(r.name);
    if (it == by_name.end() || it->second.empty()) continue;
    const DatumId d = it->second.back();
    it->second.pop_back();
    if (g.data[d].bytes != r.bytes || r.ptr == nullptr) continue;
    checker.set_storage(d, const_cast<void*>(r.ptr), r.bytes);  // the engine's own, mutable
    ++n;
  }
  return n;
}


class CallbackEngine final : public LiveEngine {
 public:
  explicit CallbackEngine(EngineCallbacks c) : c_(std::move(c)) {
    if (!c_.declare || !c_.step)
      throw UsageError("engine callbacks: declare and step are required");
  }

  LiveStep record_step(bool allow_reuse) override {
    capture::Recorder& rec = recorder(capture::Mode::kDeferred);
    if (allow_reuse && c_.same_every_step && recorded_) {
      LiveStep same;
      same.reuse_previous = true;
      return same;
    }
    rec.begin_step();
    c_.step(rec);
    LiveStep step = detail::take_recorded_step(rec, "engine");
    recorded_ = true;
    last_graph_ = step.graph;
    return step;
  }

  void plain_step() override {
    capture::Recorder& rec = recorder(capture::Mode::kOff);
    rec.begin_step();
    c_.step(rec);
    rec.end_step();
  }

  std::vector<StateRegion> state() const override {
    std::vector<StateRegion> r = c_.state ? c_.state()
                                 : rec_   ? detail::recorded_state(*rec_)
                                          : std::vector<StateRegion>{};
    if (recorded_) set_write_order(r, last_graph_);  // the first difference in program order
    return r;
  }

 private:
  // The engine's recorder, made (and the engine declared on it) at the first step.
  capture::Recorder& recorder(capture::Mode mode) {
    if (!rec_) {
      rec_.emplace(mode);
      c_.declare(*rec_);
    } else if (rec_->mode() != mode) {
      throw UsageError("engine: stepped both recorded and plainly (make a fresh engine for each)");
    }
    return *rec_;
  }

  EngineCallbacks c_;
  std::optional<capture::Recorder> rec_;
  bool recorded_ = false;
  StepGraph last_graph_;  // the last step recorded: the state's write order
};

}  // namespace

std::unique_ptr<LiveEngine> make_live_engine(EngineCallbacks callbacks) {
  return std::make_unique<CallbackEngine>(std::move(callbacks));
}

LiveResult run_engine_live(const CallbacksFactory& make, const MethodChoice& method,
                           LiveOptions options) {
  options.policy = method.policy;
  std::optional<partition::StepPartitioner> part;
  if (method.policy == replay::Policy::kPartition) {
    partition::Options po;
    po.sticky_threshold = live_sticky_threshold(options);
    po.loop_share = options.loop_share;
    part = partition::step_partitioner(method.method, po);
  }
  return run_live([make] { return make_live_engine(make()); }, part ? &*part : nullptr, options);
}

VerifyResult verify_engine_accesses(const CallbacksFactory& make, const MethodChoice& method,
                                    LiveOptions options) {
  options.policy = method.policy;
  std::optional<partition::StepPartitioner> part;
  if (method.policy == replay::Policy::kPartition)
    part = partition::step_partitioner(method.method, partition::Options{});
  return verify_accesses([make] { return make_live_engine(make()); }, part ? &*part : nullptr,
                         options);
}

std::string to_json(const LiveResult& r, const std::string& engine, const std::string& method,
                    const std::vector<std::pair<std::string, double>>& extra) {
  auto j = nlohmann::json::parse(to_json(r, engine, method));
  for (const auto& [key, value] : extra) j[key] = value;
  return j.dump();
}

VerifyResult verify_accesses(const EngineFactory& make_engine,
                             const partition::StepPartitioner* partitioner, const LiveOptions& o) {
  if (o.steps == 0) throw OptionError("steps", "must be at least 1");
  const bool partition = o.policy == replay::Policy::kPartition;
  if (partition && (partitioner == nullptr || !*partitioner))
    throw UsageError("the partition policy needs a partitioning method");
  replay::ExecOptions eo = o.exec;
  eo.cw = CwMode::kSerialize;  // a body that runs twice writes its datum itself
  std::unique_ptr<replay::Executor> ex = replay::make_executor(o.policy, eo);
  VerifyResult res;
  res.policy = o.policy;
  res.threads = ex->threads();
  res.steps = o.steps;
  AccessChecker checker;
  AccessFindings findings;
  replay::ProgramWorkload w;
  w.set_access_checker(&checker, &findings);
  {
    std::unique_ptr<LiveEngine> engine = make_engine();
    LiveStep cur;
    Assignment assignment;
    const std::int64_t t0 = replay::now_ns();
    for (std::uint32_t s = 0; s < o.steps; ++s) {
      LiveStep next = engine->record_step(o.reuse_structure && s > 0);
      if (!next.reuse_previous) {
        cur = std::move(next);
        res.data_checked = set_storage(checker, cur.graph, engine->state());
        if (partition) {
          StepGraph g = cur.graph;
          for (Task& t : g.tasks) t.cost_ns = 1;
          for (Loop& l : g.loops) l.iterations = 1;
          assignment = (*partitioner)(g, res.threads, nullptr, nullptr);
        }
      }
      checker.sync();  // the engine's work between steps (recording, collision detection)
      w.set_program(cur.bodies, cur.conditions, cur.accumulators);
      ex->run_step(cur.graph, partition ? &assignment : nullptr, w);
    }
    res.wall_ns = replay::now_ns() - t0;
  }
  res.findings = findings.list();
  res.counts = checker.counts();
  ex.reset();
  std::unique_ptr<LiveEngine> plain = make_engine();
  const std::int64_t t0 = replay::now_ns();
  for (std::uint32_t s = 0; s < o.steps; ++s) plain->plain_step();
  res.plain_wall_ns = replay::now_ns() - t0;
  return res;
}

std::string verify_json(const VerifyResult& r, const std::string& engine, const std::string& method) {
  nlohmann::json j;
  j["scene"] = engine;
  j["method"] = method;
  j["policy"] = std::string(replay::to_string(r.policy));
  j["threads"] = r.threads;
  j["steps"] = r.steps;
  nlohmann::json f = nlohmann::json::array();
  for (const AccessFinding& a : r.findings)
    f.push_back({{"task", a.task},
                 {"datum", a.datum},
                 {"found", std::string(to_string(a.found))},
                 {"declared", a.declared}});
  j["access_findings"] = f;
  j["access_check"] = {{"runs", r.counts.runs},
                       {"reruns", r.counts.reruns},
                       {"reads_unchecked", r.counts.reads_unchecked},
                       {"data_checked", r.data_checked}};
  j["wall_ns"] = r.wall_ns;
  j["plain_wall_ns"] = r.plain_wall_ns;
  j["cost"] = r.plain_wall_ns > 0
                  ? static_cast<double>(r.wall_ns) / static_cast<double>(r.plain_wall_ns)
                  : 0.0;
  return j.dump();
}

std::string verify_text(const VerifyResult& r, const std::string& engine, const std::string& method) {
  char line[512];
  std::snprintf(line, sizeof line,
                "verify-accesses %s, %s on %u threads, %u steps: %llu task runs checked, %llu "
                "reruns, %zu data with storage, %.2f s (the plain engine %.3f s): %zu finding(s)\n",
                engine.c_str(), method.c_str(), r.threads, r.steps,
                static_cast<unsigned long long>(r.counts.runs),
                static_cast<unsigned long long>(r.counts.reruns), r.data_checked,
                static_cast<double>(r.wall_ns) * 1e-9, static_cast<double>(r.plain_wall_ns) * 1e-9,
                r.findings.size());
  std::string out = line;
  for (const AccessFinding& a : r.findings) out += "  " + to_string(a) + "\n";
  return out;
}

VerifyRunReport verify_scene(const SceneRun& run) {
  std::optional<partition::StepPartitioner> part;
  if (run.method.policy == replay::Policy::kPartition)
    part = partition::step_partitioner(run.method.method, run.strategy.options());
  LiveOptions o = run.live;
  o.policy = run.method.policy;
  const std::string scene = run.scene, method = method_name(run.method);
  const samples::SceneOptions scene_options = run.scene_options;
  o.steps = run.steps.value_or(
      samples::is_tiled_heat(scene)
          ? 4u
          : static_cast<std::uint32_t>(samples::make_scene(scene, scene_options)->default_steps()));
  const VerifyResult v = verify_accesses(
      [scene, scene_options] { return make_live_engine(scene, scene_options); },
      part ? &*part : nullptr, o);
  VerifyRunReport r;
  r.result = v;
  r.report = run.json ? verify_json(v, scene, method) + "\n" : verify_text(v, scene, method);
  return r;
}

}  // namespace tgraph::measure
