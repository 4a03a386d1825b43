// SPDX-License-Identifier: MIT
#include "tgraph/ode/run.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "messages.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/measure/passes.hpp"
#include "tgraph/ode/scenes.hpp"

namespace tgraph::ode {
namespace {

// Positions that differ by less than a nanometre differ by the rounding of sums taken in
// another order: seven orders of magnitude below the boxes and the contacts' softness.
constexpr double kRounding = 1e-9;
// The tolerance over the seeds' spread (docs/ode.md, "The check": twice gave 2.9 % false
// alarms on correct 2-thread runs, five times 0.003 %).
constexpr double kToleranceFactor = 5.0;
// What RunResult::tolerance is: the perturbations a K-thread run makes, applied to ODE
// self-threaded (run --json's tolerance_basis, differs_line).
constexpr const char* kToleranceBasis =
    "five times the farthest ODE self-threaded's final positions move with another seed of its "
    "random constraint reordering, its contacts made in another order or the world moved by "
    "1e-12 m";

struct Pass {
  std::vector<StepTime> steps;
  std::vector<std::int64_t> partition_ns;
  std::vector<double> state;
  std::vector<double> positions;
  AttachStats stats;
};

std::vector<double> positions_of(const std::vector<double>& state) {
  std::vector<double> p;
  for (std::size_t b = 0; b + 13 <= state.size(); b += 13)
    p.insert(p.end(), &state[b], &state[b] + 3);
  return p;
}

// One pass of `steps` steps on a fresh scene: attached under `method` (or not at all for
// ODE self-threaded, the reference).
Pass run_pass(const RunOptions& o, std::uint32_t steps, bool reference, unsigned long seed,
              double nudge = 0, unsigned long shuffle = 0) {
  auto scene = Scene::make(o.scene, o.stepper, seed);
  if (nudge != 0) scene->nudge(nudge);
  if (shuffle != 0) scene->shuffle_contacts(shuffle);
  Pass p;
  p.steps.reserve(steps);
  if (reference) {
    for (std::uint32_t i = 0; i < steps; ++i) p.steps.push_back(scene->step(nullptr));
    p.partition_ns.assign(steps, 0);
  } else {
    Attachment attach(scene->world(), attach_options(o));
    std::int64_t partitioned = 0;
    for (std::uint32_t i = 0; i < steps; ++i) {
      p.steps.push_back(scene->step(&attach));
      const std::int64_t now = attach.stats().partition_ns;
      p.partition_ns.push_back(now - partitioned);
      p.steps.back().world_ns -= now - partitioned;  // the world step alone
      partitioned = now;
    }
    p.stats = attach.stats();
  }
  p.state = scene->state();
  p.positions = positions_of(p.state);
  return p;
}

// The largest difference; a position that is not a number is infinitely far (std::max would
// drop a NaN and call a blown-up run within tolerance).
double max_abs(const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0;
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) {
    const double e = std::abs(a[i] - b[i]);
    d = std::isnan(e) ? std::numeric_limits<double>::infinity() : std::max(d, e);
  }
  return d;
}

}  // namespace

RunOptions run_options(std::string scene, std::optional<std::uint32_t> steps, Method method,
                       std::uint32_t threads, std::uint32_t repeat, Stepper stepper) {
  return {.scene = std::move(scene),
          .steps = steps,
          .method = std::move(method),
          .threads = threads,
          .repeat = repeat,
          .stepper = stepper};
}

AttachOptions attach_options(const RunOptions& o) {
  return {.method = o.method,
          .threads = o.threads,
          .repartition_interval = o.repartition_interval,
          .strategy = o.strategy,
          .watchdog_s = o.watchdog_s};
}

RunResult run_scene(const RunOptions& options) {
  if (!is_scene(options.scene))
    throw InputError(options.scene, std::nullopt,
                     "unknown ODE scene (ode-piles, ode-heap, ode-chains)");
  if (options.threads == 0) throw OptionError("threads", "must be at least 1");
  if (options.repeat == 0) throw OptionError("repeat", "must be at least 1");
  if (options.steps && *options.steps == 0) throw OptionError("steps", "must be at least 1");
  dInitODE2(0);
  detail::acquire_message_handlers();  // ODE's warnings counted, not printed, in every pass
  struct Close {
    ~Close() {
      detail::release_message_handlers();
      dCloseODE();
    }
  } close;
  RunResult r;
  r.options = options;
  r.steps = options.steps.value_or(Scene::make(options.scene, options.stepper)->default_steps());
  const bool self = options.method.policy == Policy::kSequential;
  // Warm-up: caches, the threads' first wake-ups, ODE's step memory.
  const std::uint32_t warm = std::min<std::uint32_t>(r.steps, 20);
  run_pass(options, warm, true, 0);
  if (!self) run_pass(options, warm, false, 0);

  measure::PassTimes wall(r.steps), world(r.steps), collide(r.steps), part(r.steps);
  measure::PassTimes seq_wall(r.steps), seq_world(r.steps), seq_collide(r.steps);
  Pass first, first_reference;
  for (std::uint32_t pass = 0; pass < options.repeat; ++pass) {
    Pass ref = run_pass(options, r.steps, true, 0);
    Pass run = self ? ref : run_pass(options, r.steps, false, 0);
    for (std::uint32_t s = 0; s < r.steps; ++s) {
      seq_wall.add(s, ref.steps[s].collide_ns + ref.steps[s].world_ns);
      seq_world.add(s, ref.steps[s].world_ns);
      seq_collide.add(s, ref.steps[s].collide_ns);
      wall.add(s, run.steps[s].collide_ns + run.steps[s].world_ns + run.partition_ns[s]);
      world.add(s, run.steps[s].world_ns);
      collide.add(s, run.steps[s].collide_ns);
      part.add(s, run.partition_ns[s]);
    }
    for (measure::PassTimes* t :
         {&wall, &world, &collide, &part, &seq_wall, &seq_world, &seq_collide})
      t->end_pass();
    if (pass == 0) {
      first = std::move(run);
      first_reference = std::move(ref);
    }
  }
  r.wall_ns = wall.median_total();
  r.world_ns = world.median_total();
  r.collide_ns = collide.median_total();
  r.partition_ns = part.median_total();
  r.sequential_wall_ns = seq_wall.median_total();
  r.sequential_world_ns = seq_world.median_total();
  r.sequential_collide_ns = seq_collide.median_total();
  r.pass_wall_ns = wall.pass_totals();
  r.sequential_pass_wall_ns = seq_wall.pass_totals();
  r.speedup = r.wall_ns > 0
                  ? static_cast<double>(r.sequential_wall_ns) / static_cast<double>(r.wall_ns)
                  : 0;
  r.world_speedup =
      r.world_ns > 0 ? static_cast<double>(r.sequential_world_ns) / static_cast<double>(r.world_ns)
                     : 0;
  r.stats = self ? AttachStats{} : first.stats;
  for (std::uint32_t s = 0; s < r.steps; ++s) {
    RunStep st;
    st.wall_ns = wall.step_median(s);
    st.world_ns = world.step_median(s);
    st.collide_ns = collide.step_median(s);
    st.partition_ns = part.step_median(s);
    st.sequential_wall_ns = seq_wall.step_median(s);
    st.sequential_world_ns = seq_world.step_median(s);
    r.per_step.push_back(st);
  }
  if (options.check) {
    const Pass& a = self ? first_reference : first;
    const Pass& b = first_reference;
    if (a.state.size() == b.state.size() &&
        std::memcmp(a.state.data(), b.state.data(), a.state.size() * sizeof(double)) == 0) {
      r.check = "identical";
    } else {
      r.max_abs_diff = max_abs(a.positions, b.positions);
      for (std::size_t i = 0; i < a.state.size() && i < b.state.size(); ++i) {
        const double scale = std::max(std::abs(a.state[i]), std::abs(b.state[i]));
        if (scale > 0)
          r.max_rel_diff = std::max(r.max_rel_diff, std::abs(a.state[i] - b.state[i]) / scale);
      }
      // ODE self-threaded perturbed as a K-thread run perturbs it: other orders of its random
      // constraint reordering (two other seeds); the same contacts made in other orders, each
      // pair's geoms either way round (two shuffles: K island jobs mark their geoms moved in
      // the order they step them, the sweep-and-prune space then reports the next step's
      // pairs in that order); the world moved by 1e-12 m (rounding alone). The farthest a
      // body then moves, times kToleranceFactor (docs/ode.md, "The check": a 2-thread run's
      // distance has a heavier tail than another seed's).
      double spread = 0;
      for (unsigned long seed : {1ul, 2ul})
        spread = std::max(spread,
                          max_abs(run_pass(options, r.steps, true, seed).positions, b.positions));
      for (unsigned long shuffle : {1ul, 2ul})
        spread = std::max(spread, max_abs(run_pass(options, r.steps, true, 0, 0, shuffle).positions,
                                          b.positions));
      {
        Pass nudged = run_pass(options, r.steps, true, 0, 1e-12);
        for (std::size_t i = 0; i < nudged.positions.size(); i += 3) nudged.positions[i] -= 1e-12;
        spread = std::max(spread, max_abs(nudged.positions, b.positions));
      }
      r.tolerance = kToleranceFactor * spread;
      r.check = r.max_abs_diff <= kRounding     ? "within-rounding"
                : r.max_abs_diff <= r.tolerance ? "within-tolerance"
                                                : "differs";
    }
  }
  return r;
}

namespace {

// The per-step record's fields beside its index, in the order `run --json` writes them.
constexpr std::pair<const char*, std::int64_t RunStep::*> kStepFields[] = {
    {"wall_ns", &RunStep::wall_ns},
    {"world_ns", &RunStep::world_ns},
    {"collide_ns", &RunStep::collide_ns},
    {"partition_ns", &RunStep::partition_ns},
    {"sequential_wall_ns", &RunStep::sequential_wall_ns},
    {"sequential_world_ns", &RunStep::sequential_world_ns}};

// `check` and, when the states differ, by how much and against which tolerance.
void check_json(const RunResult& r, nlohmann::ordered_json& j) {
  if (r.check.empty()) {
    j["check"] = nullptr;
    return;
  }
  j["check"] = r.check;
  j["check_reference"] = "plain";
  if (r.check == "identical") return;
  j.update(nlohmann::ordered_json{{"max_abs_diff", r.max_abs_diff},
                                  {"max_rel_diff", r.max_rel_diff},
                                  {"tolerance", r.tolerance},
                                  {"tolerance_basis", kToleranceBasis}});
}

}  // namespace

std::string differs_line(const RunResult& r) {
  return "final state differs from ODE self-threaded's by " + std::to_string(r.max_abs_diff) +
         " m, more than the tolerance (" + std::to_string(r.tolerance) + " m: " + kToleranceBasis +
         ")";
}

std::string to_json(const RunResult& r) {
  const RunOptions& o = r.options;
  nlohmann::ordered_json j = {{"scene", o.scene},
                              {"stepper", std::string(to_string(o.stepper))},
                              {"method", method_name(o.method)},
                              {"policy", std::string(to_string(o.method.policy))},
                              {"threads", o.threads},
                              {"steps", r.steps},
                              {"repeat", o.repeat},
                              {"wall_ns", r.wall_ns},
                              {"sequential_wall_ns", r.sequential_wall_ns},
                              {"world_ns", r.world_ns},
                              {"sequential_world_ns", r.sequential_world_ns},
                              {"speedup", r.speedup},
                              {"world_speedup", r.world_speedup}};
  check_json(r, j);
  j["breakdown"] = {{"collide_ns", r.collide_ns},
                    {"world_ns", r.world_ns},
                    {"partition_ns", r.partition_ns},
                    {"sequential_collide_ns", r.sequential_collide_ns},
                    {"sequential_world_ns", r.sequential_world_ns}};
  const double steps = std::max<double>(r.steps, 1);
  j["calls_per_step"] = static_cast<double>(r.stats.calls) / steps;
  j["steals_per_step"] = static_cast<double>(r.stats.steals) / steps;
  j["parks_per_step"] = static_cast<double>(r.stats.parks) / steps;
  j["ode_messages"] = r.stats.messages;
  if (r.stats.messages) j["first_ode_message"] = r.stats.first_message;
  j["pass_wall_ns"] = r.pass_wall_ns;
  j["sequential_pass_wall_ns"] = r.sequential_pass_wall_ns;
  nlohmann::ordered_json steps_json = nlohmann::ordered_json::array();
  for (std::size_t s = 0; s < r.per_step.size(); ++s) {
    nlohmann::ordered_json step = {{"step", s}};
    for (const auto& [key, field] : kStepFields) step[key] = r.per_step[s].*field;
    steps_json.push_back(std::move(step));
  }
  j["per_step"] = std::move(steps_json);
  return j.dump() + "\n";
}

std::string to_text(const RunResult& r) {
  std::ostringstream out;
  const RunOptions& o = r.options;
  out << o.scene << " (" << to_string(o.stepper) << "), " << r.steps << " steps, "
      << method_name(o.method) << " at " << o.threads << " threads, " << o.repeat
      << " timed pass(es)\n";
  out << "  whole step: " << static_cast<double>(r.wall_ns) / 1e6 << " ms against "
      << static_cast<double>(r.sequential_wall_ns) / 1e6 << " ms ODE self-threaded: speed-up "
      << r.speedup << "\n";
  out << "  world step: " << static_cast<double>(r.world_ns) / 1e6 << " ms against "
      << static_cast<double>(r.sequential_world_ns) / 1e6 << " ms: speed-up " << r.world_speedup
      << "\n";
  if (!r.check.empty()) {
    out << "  check: " << r.check;
    if (r.check != "identical")
      out << " (largest position difference " << r.max_abs_diff << " m; tolerance " << r.tolerance
          << " m)";
    out << "\n";
  }
  return out.str();
}

}  // namespace tgraph::ode
