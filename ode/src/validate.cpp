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

int leaf(void*, dcallindex_t, dCallReleaseeID) { return 1; }

constexpr int kCalls = 20000;
// validate records and simulates this many steps at a time.
constexpr std::uint32_t kChunk = 25;

// One flat round through `rt` on its one thread, recorded or not: kCalls trivial calls
// posted from the stepping thread, each releasing a last call that signals the wait (ODE's
// pattern of a stage's instances and their sync call).
struct FlatRound {
  double ns = 0;          ///< the whole round
  double post_ns = 0;     ///< its posts alone (the poster's part holds them)
  std::size_t parts = 0;  ///< the parts the recording made (0 unrecorded)
};

FlatRound flat_round(detail::Runtime& rt, dCallWaitID w, bool record) {
  const dThreadingFunctionsInfo* f = rt.functions();
  f->reset_call_wait(rt.id(), w);
  rt.set_recording(record);
  rt.begin_step("flat");
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  dCallReleaseeID last = nullptr;
  f->post_call(rt.id(), nullptr, &last, kCalls, nullptr, w, &leaf, nullptr, 0, "last");
  for (int i = 0; i < kCalls; ++i)
    f->post_call(rt.id(), nullptr, nullptr, 0, last, nullptr, &leaf, nullptr,
                 static_cast<dcallindex_t>(i), "leaf");
  const auto t1 = Clock::now();
  f->wait_call(rt.id(), nullptr, w, nullptr, "flat");
  const auto t2 = Clock::now();
  FlatRound r;
  r.ns = std::chrono::duration<double, std::nano>(t2 - t0).count();
  r.post_ns = std::chrono::duration<double, std::nano>(t1 - t0).count();
  for (const detail::SlotLog& s : rt.end_step().slots) r.parts += s.segments.size();
  rt.set_recording(false);
  return r;
}

// On one thread, medians of 3 rounds of flat calls, recorded and not, alternating:
// - the runtime's own time per call that no part's recorded cost holds: not recorded, the
//   round's time after its posts, per call (taking the call, running a trivial body,
//   completing it, its release); a post runs inside its poster's part, so its cost is in
//   that part's (the simulator charges hand-offs between threads apart);
// - the recording's own time per part: the recorded round against the one not recorded,
//   over the parts recorded (what each recorded part's cost holds beyond its body).
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
    const FlatRound plain = flat_round(rt, w, false);
    const FlatRound recorded = flat_round(rt, w, true);
    per_call.push_back((plain.ns - plain.post_ns) / kCalls);
    per_part.push_back((recorded.ns - plain.ns) /
                       static_cast<double>(std::max<std::size_t>(recorded.parts, 1)));
  }
  f->free_call_wait(rt.id(), w);
  return {std::max(0.0, median(per_call)), std::max(0.0, median(per_part))};
}

}  // namespace
ValidateOptions validate_options(const RunOptions& run, std::string calibration) {
  return {.scene = run.scene,
          .steps = run.steps.value_or(default_steps(run.scene)),
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
  // islands: its placement (a posted call on its poster's thread) is no assignment of a
  // captured step the simulator could be given before the step runs.
  if (options.method.policy != Policy::kWorksteal && options.method.policy != Policy::kPartition &&
      options.method.policy != Policy::kIslandsSerial)
    throw OptionError("method",
                      "validate predicts tgraph's runtime from a capture: worksteal, "
                      "islands-serial or a partition strategy, not '" +
                          method_name(options.method) + "'");
  if (options.threads == 0) throw OptionError("threads", "must be at least 1");
  if (options.repeat == 0) throw OptionError("repeat", "must be at least 1");
  if (options.steps == 0) throw OptionError("steps", "must be at least 1");
  ValidateReport report;
  report.options = options;
  report.strategy = options.method.policy == Policy::kPartition ? options.method.strategy : "list";
  model::CostModel costs = model::select_cost_model("calibrated", options.calibration);
  // The runtime's own time per call that no part's recorded cost holds (charged per part
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
  // The steps are recorded under the live run's policy (islands-serial: ODE's plan of
  // whole islands; worksteal and a strategy: its K-thread stages), their logs made before
  // their steps: no fresh page faulted in inside a part.
  const RecordingRoom room = recording_room(options.scene, options.stepper, options.threads,
                                            options.steps, options.method);
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
      a.method = options.method;
      a.record = true;
      a.reserve_room = room;
      Attachment attach(scene->world(), a);
      // Recorded and simulated kChunk steps at a time: the logs of one part of the steps
      // held at once, their room made between the parts.
      for (std::uint32_t done = 0; done < options.steps;) {
        const std::uint32_t n = std::min(kChunk, options.steps - done);
        attach.reserve_recording(n);
        const std::uint64_t calls_before = attach.stats().calls;
        for (std::uint32_t i = 0; i < n; ++i) scene->step(&attach);
        done += n;
        const double calls_per_step =
            static_cast<double>(attach.stats().calls - calls_before) / static_cast<double>(n);
        for (StepGraph& g : attach.take_steps()) {
          // Each part's recorded cost without the recording's own time (the live run records
          // none: it is measured in this run and removed, docs/ode.md "validate").
          for (Task& t : g.tasks) t.cost_ns = t.cost_ns > own ? t.cost_ns - own : 0;
          // The runtime's own time per call outside the parts, spread over the parts.
          model::CostModel step_costs = costs;
          step_costs.task_overhead_ns =
              runtime.ns_per_call * calls_per_step /
              static_cast<double>(std::max<std::size_t>(g.tasks.size(), 1));
          const partition::Result p = strategy->partition(g, options.threads, {}, {});
          v.predicted_ns +=
              static_cast<std::int64_t>(model::simulate(g, p.assignment, step_costs).makespan_ns);
        }
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
