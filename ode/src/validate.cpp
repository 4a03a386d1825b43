// SPDX-License-Identifier: MIT
#include <algorithm>
#include <chrono>
#include <nlohmann/json.hpp>
#include <sstream>

#include "runtime.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/median.hpp"
#include "tgraph/model/cost_model.hpp"
#include "tgraph/model/simulator.hpp"
#include "tgraph/ode/run.hpp"
#include "tgraph/ode/scenes.hpp"

namespace tgraph::ode {
namespace {

int chained(void* context, dcallindex_t, dCallReleaseeID self);

struct Chain {
  const dThreadingFunctionsInfo* f;
  dThreadingImplementationID impl;
  int left;
};

// ODE's pattern: a running call adds a dependency to itself and posts the next call.
int chained(void* context, dcallindex_t, dCallReleaseeID self) {
  auto* c = static_cast<Chain*>(context);
  if (--c->left > 0) {
    c->f->alter_call_dependencies_count(c->impl, self, 1);
    c->f->post_call(c->impl, nullptr, nullptr, 0, self, nullptr, &chained, c, 0, "chain");
  }
  return 1;
}

int leaf(void*, dcallindex_t, dCallReleaseeID) { return 1; }

constexpr int kCalls = 20000;

// ODE's other pattern, flat: kCalls trivial calls posted from the stepping thread, each
// releasing a last call that signals the wait. Through `rt` on its one thread, recorded or
// not: its time, and the parts the recording made (0 unrecorded).
std::pair<double, std::size_t> flat_ns(detail::Runtime& rt, dCallWaitID w, bool record) {
  const dThreadingFunctionsInfo* f = rt.functions();
  f->reset_call_wait(rt.id(), w);
  rt.set_recording(record);
  rt.begin_step("flat");
  const auto t0 = std::chrono::steady_clock::now();
  dCallReleaseeID last = nullptr;
  f->post_call(rt.id(), nullptr, &last, kCalls, nullptr, w, &leaf, nullptr, 0, "last");
  for (int i = 0; i < kCalls; ++i)
    f->post_call(rt.id(), nullptr, nullptr, 0, last, nullptr, &leaf, nullptr,
                 static_cast<dcallindex_t>(i), "leaf");
  f->wait_call(rt.id(), nullptr, w, nullptr, "flat");
  const double ns =
      std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count();
  std::size_t parts = 0;
  for (const detail::SlotLog& s : rt.end_step().slots) parts += s.segments.size();
  rt.set_recording(false);
  return {ns, parts};
}

// On one thread, medians of 3 rounds: the runtime's own time per call (a chain of trivial
// calls, ODE's pattern of a running call posting the next: post, dispatch, completion,
// release; the simulator charges hand-offs between threads apart), and the recording's own
// time per part (flat calls recorded against the same not recorded, alternating, over the
// parts recorded: what each recorded part's cost holds beyond its body).
struct RuntimeCosts {
  double ns_per_call = 0;
  double recording_ns_per_part = 0;
};

RuntimeCosts runtime_costs() {
  detail::RuntimeOptions o;
  o.threads = 1;
  o.watchdog_s = 0;
  detail::Runtime rt(o);
  const dThreadingFunctionsInfo* f = rt.functions();
  dCallWaitID w = f->alloc_call_wait(rt.id());
  std::vector<double> per_call, per_part;
  for (int round = 0; round < 3; ++round) {
    Chain chain{f, rt.id(), kCalls};
    f->reset_call_wait(rt.id(), w);
    const auto t0 = std::chrono::steady_clock::now();
    f->post_call(rt.id(), nullptr, nullptr, 0, nullptr, w, &chained, &chain, 0, "chain");
    f->wait_call(rt.id(), nullptr, w, nullptr, "chain");
    per_call.push_back(
        std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count() /
        kCalls);
    const double plain = flat_ns(rt, w, false).first;
    const auto [recorded, parts] = flat_ns(rt, w, true);
    per_part.push_back((recorded - plain) / static_cast<double>(std::max<std::size_t>(parts, 1)));
  }
  f->free_call_wait(rt.id(), w);
  return {median(per_call), std::max(0.0, median(per_part))};
}

}  // namespace
ValidateOptions validate_options(const RunOptions& run, std::string calibration) {
  return {.scene = run.scene,
          .steps = run.steps.value_or(ValidateOptions{}.steps),
          .threads = run.threads,
          .method = run.method,
          .repeat = run.repeat,
          .stepper = run.stepper,
          .calibration = std::move(calibration)};
}

ValidateReport validate_scene(const ValidateOptions& options) {
  if (!is_scene(options.scene))
    throw InputError(options.scene, std::nullopt,
                     "unknown ODE scene (ode-piles, ode-heap, ode-chains)");
  if (options.method.policy == Policy::kSequential || options.method.policy == Policy::kOde)
    throw OptionError("method",
                      "validate predicts tgraph's runtime from a capture: worksteal or a "
                      "partition strategy, not '" +
                          method_name(options.method) + "'");
  if (options.threads == 0) throw OptionError("threads", "must be at least 1");
  if (options.repeat == 0) throw OptionError("repeat", "must be at least 1");
  if (options.steps == 0) throw OptionError("steps", "must be at least 1");
  ValidateReport report;
  report.options = options;
  report.strategy = options.method.policy == Policy::kPartition ? options.method.strategy : "list";
  model::CostModel costs = model::select_cost_model("calibrated", options.calibration);
  // The runtime's own time per call, which no part's recorded cost holds (charged per part
  // below, scaled by the step's calls per part), and its spin before a thread parks.
  const RuntimeCosts runtime = runtime_costs();
  report.runtime_ns_per_call = runtime.ns_per_call;
  report.recording_ns_per_part = runtime.recording_ns_per_part;
  costs.spin_budget_ns = static_cast<double>(AttachOptions{}.spin_ns);
  const auto own = static_cast<std::uint64_t>(runtime.recording_ns_per_part);
  auto strategy = partition::make_strategy(report.strategy);
  dInitODE2(0);
  struct Close {
    ~Close() { dCloseODE(); }
  } close;
  std::vector<double> live, predicted, over;
  // The recordings' logs made before their steps: no fresh page faulted in inside a part.
  const RecordingRoom room =
      recording_room(options.scene, options.stepper, options.threads, options.steps);
  for (std::uint32_t round = 0; round < options.repeat; ++round) {
    const RunResult r = run_scene(run_options(options.scene, options.steps, options.method,
                                              options.threads, 1, options.stepper));
    ValidateRound v;
    v.live_ns = r.wall_ns;
    v.sequential_ns = r.sequential_wall_ns;
    {
      auto scene = Scene::make(options.scene, options.stepper, 0);
      AttachOptions a;
      a.threads = options.threads;
      a.record = true;
      a.reserve_steps = options.steps;
      a.reserve_room = room;
      Attachment attach(scene->world(), a);
      for (std::uint32_t i = 0; i < options.steps; ++i) scene->step(&attach);
      const double calls_per_step =
          static_cast<double>(attach.stats().calls) / static_cast<double>(options.steps);
      for (StepGraph& g : attach.take_steps()) {
        // Each part's recorded cost without the recording's own time (the live run records
        // none: it is measured in this run and removed, docs/ode.md "validate").
        for (Task& t : g.tasks) t.cost_ns = t.cost_ns > own ? t.cost_ns - own : 0;
        // The runtime's own time per call, which no part's cost holds, spread over the parts.
        model::CostModel step_costs = costs;
        step_costs.task_overhead_ns = runtime.ns_per_call * calls_per_step /
                                      static_cast<double>(std::max<std::size_t>(g.tasks.size(), 1));
        const partition::Result p = strategy->partition(g, options.threads, {}, {});
        v.predicted_ns +=
            static_cast<std::int64_t>(model::simulate(g, p.assignment, step_costs).makespan_ns);
      }
    }
    report.rounds.push_back(v);
    const auto d = [](std::int64_t x) { return static_cast<double>(std::max<std::int64_t>(x, 1)); };
    live.push_back(d(v.sequential_ns) / d(v.live_ns));
    predicted.push_back(d(v.sequential_ns) / d(v.predicted_ns));
    over.push_back(d(v.predicted_ns) / d(v.live_ns));
  }
  report.live_speedup = median(live);
  report.predicted_speedup = median(predicted);
  report.predicted_over_live = median(over);
  return report;
}

std::string to_json(const ValidateReport& r) {
  const ValidateOptions& o = r.options;
  nlohmann::ordered_json j = {{"scene", o.scene},
                              {"stepper", std::string(to_string(o.stepper))},
                              {"method", method_name(o.method)},
                              {"predicted_with", r.strategy},
                              {"threads", o.threads},
                              {"steps", o.steps},
                              {"repeat", o.repeat},
                              {"live_speedup", r.live_speedup},
                              {"predicted_speedup", r.predicted_speedup},
                              {"predicted_over_live", r.predicted_over_live},
                              {"runtime_ns_per_call", r.runtime_ns_per_call},
                              {"recording_ns_per_part", r.recording_ns_per_part},
                              {"within_15_percent", std::abs(r.predicted_over_live - 1.0) <= 0.15}};
  nlohmann::ordered_json rounds = nlohmann::ordered_json::array();
  for (const ValidateRound& v : r.rounds)
    rounds.push_back({{"live_ns", v.live_ns},
                      {"sequential_ns", v.sequential_ns},
                      {"predicted_ns", v.predicted_ns}});
  j["rounds"] = std::move(rounds);
  return j.dump() + "\n";
}

std::string to_text(const ValidateReport& r) {
  std::ostringstream out;
  out << r.options.scene << ", " << r.options.steps << " steps, " << method_name(r.options.method)
      << " at " << r.options.threads << " threads, " << r.options.repeat << " round(s)\n"
      << "  live speed-up " << r.live_speedup << ", predicted " << r.predicted_speedup << " ("
      << r.strategy << " schedule of the capture)\n"
      << "  predicted / live time: " << r.predicted_over_live << "\n";
  return out.str();
}

}  // namespace tgraph::ode
