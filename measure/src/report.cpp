// SPDX-License-Identifier: MIT
// The JSON and text of the three measurements (replay, live run, validation), with one
// writer of the per-step record they share.
#include "tgraph/measure/report.hpp"

#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "tgraph/graph/json_util.hpp"

namespace tgraph::measure {

namespace tr = tgraph::replay;
using nlohmann::json;

namespace {

json threads_json(const std::vector<tr::StatsObserver::Thread>& threads) {
  json a = json::array();
  for (const auto& t : threads)
    a.push_back({{"busy_ns", t.busy_ns},
                 {"wait_ns", t.wait_ns},
                 {"idle_ns", t.idle_ns},
                 {"tasks", t.tasks}});
  return a;
}

// The keys every per-step record has (replays and live runs alike).
json attribution_json(const std::optional<explain::Attribution>& a) {
  return a ? json::parse(explain::attribution_json(*a)) : json(nullptr);
}

json step_record_json(const StepRecord& m) {
  return {
      {"wall_ns", m.wall_ns},
      {"build_ns", m.build_ns},
      {"rebuild_ns", m.rebuild_ns},
      {"rebuilt_procs", m.rebuilt_procs},
      {"rebuild_over_wall",
       m.wall_ns > 0 ? static_cast<double>(m.rebuild_ns) / static_cast<double>(m.wall_ns) : 0.0},
      {"threads", threads_json(m.threads)},
      {"attribution", attribution_json(m.attribution)}};
}

}  // namespace

// ---- replay ------------------------------------------------------------------------------

std::string to_json(const ReplayResult& r) {
  json per_step = json::array();
  for (const StepMeasure& m : r.steps) {
    json s = step_record_json(m);
    s.update({{"step", m.step},
              {"sequential_wall_ns", m.sequential_wall_ns},
              {"run_ns", m.run_ns},
              {"signals", m.signals},
              {"waits", m.waits},
              {"blocked_waits", m.blocked_waits},
              {"parks", m.parks},
              {"wait_ns", m.wait_ns},
              {"remote_bytes", m.remote_bytes},
              {"migrated_bytes", m.migrated_bytes},
              {"work_ns", m.work_ns},
              {"span_ns", m.span_ns},
              {"host_ns", m.host_ns}});
    s["predicted_makespan_ns"] =
        optional_json(m.predicted_makespan_ns);
    per_step.push_back(std::move(s));
  }
  json j = {{"policy", std::string(to_string(r.policy))},
            {"threads", r.threads},
            {"cw", std::string(to_string(r.cw))},
            {"reduce_scope", std::string(to_string(r.scope))},
            {"steps", r.steps.size()},
            {"wall_ns", r.wall_ns},
            {"sequential_wall_ns", r.sequential_wall_ns},
            {"pass_wall_ns", r.pass_wall_ns},
            {"sequential_pass_wall_ns", r.sequential_pass_wall_ns},
            {"speedup", r.speedup},
            {"bound", r.bound},
            {"efficiency", r.efficiency},
            {"work_ns", r.work_ns},
            {"span_ns", r.span_ns},
            {"host_ns", r.host_ns},
            {"signals", r.signals()},
            {"waits", r.waits()},
            {"wait_ns", r.wait_ns()},
            {"build_ns", r.build_ns()},
            {"rebuild_ns", r.rebuild_ns()},
            {"plans_built", r.plans_built},
            {"order_fallbacks", r.order_fallbacks},
            {"remote_bytes", r.remote_bytes()},
            {"migrated_bytes", r.migrated_bytes()},
            {"calibration",
             {{"spin_iterations_per_ns", r.calibration.spin_iterations_per_ns},
              {"touch_ns_per_byte_in_cache", r.calibration.touch_ns_per_byte},
              {"touch_ns_per_byte", r.touch_ns_per_byte},
              {"spin_offset_ns", r.spin_offset_ns},
              {"working_set_bytes", r.working_set_bytes}}},
            {"attribution", attribution_json(r.attribution)},
            {"per_step", per_step}};
  j["cache_misses"] = r.cache_misses ? json(*r.cache_misses) : json(r.cache_misses_note);
  j["warnings"] = r.warnings;
  // The OpenMP policies: which runtime ran them; barrier: barrier-separated phases per step
  // (the barriers each thread passed, averaged over the replayed steps).
  const bool openmp = r.policy == tr::Policy::kOmpTasks || r.policy == tr::Policy::kBarrier;
  j["openmp_runtime"] = openmp ? json(std::string(tr::openmp_runtime())) : json(nullptr);
  j["phases_per_step"] =
      r.policy == tr::Policy::kBarrier && !r.steps.empty()
          ? json(static_cast<double>(r.waits()) / static_cast<double>(r.threads * r.steps.size()))
          : json(nullptr);
  const auto pred = r.predicted_makespan_ns();
  j["predicted_makespan_ns"] = pred ? json(*pred) : json(nullptr);
  // Ratio of measured to predicted, both without plan builds: the sum over steps of the
  // median over passes of (wall - that pass's build).
  if (pred && *pred > 0) {
    std::int64_t measured = 0;
    for (const auto& m : r.steps) measured += m.run_ns;
    j["measured_over_predicted"] = static_cast<double>(measured) / static_cast<double>(*pred);
  } else {
    j["measured_over_predicted"] = nullptr;
  }
  return j.dump();
}

std::string to_json(const ReplayResult& r, const std::string& trace_name,
                    const std::string& assignment) {
  auto j = nlohmann::json::parse(to_json(r));
  j["trace"] = trace_name;
  j["assignment"] = assignment;
  return j.dump();
}

std::string to_text(const ReplayResult& r, const std::string& trace_name, std::uint32_t repeat) {
  std::string out;
  char line[512];
  const auto add = [&](int n) {
    out.append(line, static_cast<std::size_t>(std::clamp(n, 0, 511)));
  };
  const auto ms = [](auto ns) { return static_cast<double>(ns) / 1e6; };
  const auto pred = r.predicted_makespan_ns();
  std::int64_t measured_nobuild = 0;
  for (const auto& m : r.steps) measured_nobuild += m.run_ns;
  add(std::snprintf(line, sizeof line, "replay %s: %zu steps, policy %s, %u threads, cw %s\n",
                    trace_name.c_str(), r.steps.size(), std::string(to_string(r.policy)).c_str(),
                    r.threads, std::string(to_string(r.cw)).c_str()));
  add(std::snprintf(line, sizeof line, "  wall            %10.3f ms (median of %u passes)\n",
                    ms(r.wall_ns), repeat));
  if (r.sequential_wall_ns > 0)
    add(std::snprintf(
        line, sizeof line,
        "  sequential      %10.3f ms   speed-up %.2f   efficiency %.2f (bound %.2f)\n",
        ms(r.sequential_wall_ns), r.speedup, r.efficiency, r.bound));
  add(std::snprintf(line, sizeof line, "  work / span     %10.3f / %.3f ms\n", ms(r.work_ns),
                    ms(r.span_ns)));
  add(std::snprintf(line, sizeof line,
                    "  signals %llu, waits %llu, wait time %.3f ms, plan builds %llu (%.3f ms)\n",
                    static_cast<unsigned long long>(r.signals()),
                    static_cast<unsigned long long>(r.waits()), ms(r.wait_ns()),
                    static_cast<unsigned long long>(r.plans_built), ms(r.build_ns())));
  add(std::snprintf(line, sizeof line, "  remote bytes %llu, migrated bytes %llu\n",
                    static_cast<unsigned long long>(r.remote_bytes()),
                    static_cast<unsigned long long>(r.migrated_bytes())));
  if (pred)
    add(std::snprintf(
        line, sizeof line, "  predicted       %10.3f ms   measured/predicted %.3f\n", ms(*pred),
        *pred ? static_cast<double>(measured_nobuild) / static_cast<double>(*pred) : 0.0));
  add(std::snprintf(
      line, sizeof line, "  cache misses    %s\n",
      r.cache_misses ? std::to_string(*r.cache_misses).c_str() : r.cache_misses_note.c_str()));
  return out;
}

// ---- live run ----------------------------------------------------------------------------

std::string to_json(const LiveResult& r) {
  json per_step = json::array();
  std::int64_t record = 0, part = 0, background = 0, prepare = 0, build = 0, execute = 0;
  std::vector<tr::StatsObserver::Thread> totals;
  for (const LiveStepMeasure& m : r.steps) {
    if (totals.size() < m.threads.size()) totals.resize(m.threads.size());
    for (std::size_t i = 0; i < m.threads.size(); ++i) {
      const auto& t = m.threads[i];
      totals[i].busy_ns += t.busy_ns;
      totals[i].wait_ns += t.wait_ns;
      totals[i].idle_ns += t.idle_ns;
      totals[i].tasks += t.tasks;
    }
    record += m.record_ns;
    part += m.partition_ns;
    background += m.background_partition_ns;
    prepare += m.prepare_ns;
    build += m.build_ns;
    execute += m.execute_ns;
    json s = step_record_json(m);
    s.update({{"engine_wall_ns", m.baseline_ns},
              {"record_ns", m.record_ns},
              {"partition_ns", m.partition_ns},
              {"background_partition_ns", m.background_partition_ns},
              {"prepare_ns", m.prepare_ns},
              {"graph_update_ns", m.graph_update_ns},
              {"execute_ns", m.execute_ns},
              {"rebuilt", m.rebuilt},
              {"recorded", m.recorded},
              {"partitioned", m.partitioned},
              {"reassigned", m.reassigned},
              {"loop_iterations", m.loop_iterations}});
    per_step.push_back(std::move(s));
  }
  const json threads = threads_json(totals);
  json kinds = json::array();
  for (const KindTime& k : r.kinds) {
    json e = {{"kind", k.kind}, {"instances", k.instances}, {"mean_ns", k.mean_ns}};
    e["sequential_mean_ns"] = k.sequential_mean_ns > 0 ? json(k.sequential_mean_ns) : json(nullptr);
    e["ratio"] = k.sequential_mean_ns > 0 ? json(k.mean_ns / k.sequential_mean_ns) : json(nullptr);
    kinds.push_back(std::move(e));
  }
  json j = {{"policy", std::string(to_string(r.policy))},
            {"threads", r.threads},
            {"cw", std::string(to_string(r.cw))},
            {"reduce_scope", std::string(to_string(r.scope))},
            {"steps", r.steps.size()},
            {"repeat", r.pass_wall_ns.size()},
            {"wall_ns", r.wall_ns},
            {"pass_wall_ns", r.pass_wall_ns},
            {"engine_wall_ns", r.baseline_wall_ns},
            {"engine_core_pass_wall_ns", r.baseline_core_pass_wall_ns},
            {"sequential_wall_ns", r.baseline_wall_ns},
            {"speedup", r.speedup},
            {"core_bound", r.core_bound},
            {"breakdown",
             {{"record_ns", record},
              {"partition_ns", part},
              {"background_partition_ns", background},
              {"prepare_ns", prepare},
              {"build_ns", build},
              {"execute_ns", execute}}},
            {"threads_total", threads},
            {"kinds", kinds},
            {"signals", r.signals},
            {"waits", r.waits},
            {"blocked_waits", r.blocked_waits},
            {"parks", r.parks},
            {"plans_built", r.plans_built},
            {"order_fallbacks", r.order_fallbacks},
            {"attribution", attribution_json(r.attribution)},
            {"per_step", per_step}};
  if (r.check) {
    j["check"] = std::string(to_string(*r.check));
    j["check_reference"] = std::string(to_string(r.check_reference));
    j["reference"] = r.reference;
    j["data_compared"] = r.data_compared;
    if (r.difference)
      j["first_difference"] = {{"datum", r.difference->datum},
                               {"offset", r.difference->offset},
                               {"differing_bytes", r.difference->differing_bytes},
                               {"writer", r.difference->writer}};
    if (r.values) {
      j["max_abs_diff"] = r.values->max_abs_diff;
      j["max_rel_diff"] = r.values->max_rel_diff;
      j["max_abs_datum"] = r.values->max_abs_datum;
      j["max_rel_datum"] = r.values->max_rel_datum;
      j["differing_values"] = r.values->differing_values;
      if (!r.values->incomparable.empty()) j["incomparable"] = r.values->incomparable;
    }
    if (r.iterations)
      j["iterations_differ"] = {{"step", r.iterations->step},
                                {"loop", r.iterations->loop},
                                {"in_order", r.iterations->in_order},
                                {"live", r.iterations->live}};
    if (r.check_reference == CheckReference::kPlain)
      j["rounding_bound"] = {{"max_rel_diff", r.rounding_bound},
                             {"longest_reduction", r.longest_reduction},
                             {"rounds", r.reduction_rounds}};
  }
  return j.dump();
}

std::string to_json(const LiveResult& r, const std::string& scene, const std::string& method) {
  auto j = nlohmann::json::parse(to_json(r));
  j["scene"] = scene;
  j["method"] = method;
  return j.dump();
}

std::string to_text(const LiveResult& r, const std::string& scene, const std::string& method,
                    std::uint32_t repeat) {
  std::string out;
  char line[512];
  const auto add = [&](int n) {
    out.append(line, static_cast<std::size_t>(std::clamp(n, 0, 511)));
  };
  const auto ms = [](auto ns) { return static_cast<double>(ns) / 1e6; };
  add(std::snprintf(
      line, sizeof line, "run %s: %zu steps, %s (%s), %u threads, cw %s: %.3f ms (median of %u)\n",
      scene.c_str(), r.steps.size(), std::string(to_string(r.policy)).c_str(), method.c_str(),
      r.threads, std::string(to_string(r.cw)).c_str(), ms(r.wall_ns), repeat));
  if (r.baseline_wall_ns > 0)
    add(std::snprintf(line, sizeof line, "  uninstrumented engine %.3f ms   speed-up %.2f\n",
                      ms(r.baseline_wall_ns), r.speedup));
  const auto b = nlohmann::json::parse(to_json(r))["breakdown"];
  add(std::snprintf(line, sizeof line,
                    "  record %.3f ms, partition waited %.3f ms (%.3f ms in the background), "
                    "plans %.3f ms, execute %.3f ms\n",
                    b["record_ns"].get<double>() / 1e6, b["partition_ns"].get<double>() / 1e6,
                    b["background_partition_ns"].get<double>() / 1e6,
                    b["prepare_ns"].get<double>() / 1e6, b["execute_ns"].get<double>() / 1e6));
  if (r.check) {
    const char* status = *r.check == Check::kIdentical        ? "identical bit for bit"
                         : *r.check == Check::kWithinRounding ? "within rounding"
                                                              : "DIFFERS";
    add(std::snprintf(line, sizeof line, "  check against %s: %s (%zu data compared)\n",
                      r.reference.c_str(), status, r.data_compared));
    if (r.values)
      add(std::snprintf(line, sizeof line,
                        "    %llu values differ: max |diff| %.3g (%s), max relative %.3g (%s)\n",
                        static_cast<unsigned long long>(r.values->differing_values),
                        r.values->max_abs_diff, r.values->max_abs_datum.c_str(),
                        r.values->max_rel_diff, r.values->max_rel_datum.c_str()));
    if (r.values && !r.values->incomparable.empty())
      add(std::snprintf(line, sizeof line, "    not within rounding: %s\n",
                        r.values->incomparable.c_str()));
    if (r.iterations)
      add(std::snprintf(line, sizeof line,
                        "    not within rounding: the runs took different paths, loop %u of step "
                        "%u ran %u iterations in program order, %u live (its convergence test "
                        "decided otherwise)\n",
                        r.iterations->loop, r.iterations->step, r.iterations->in_order,
                        r.iterations->live));
    if (r.values && r.check_reference == CheckReference::kPlain)
      add(std::snprintf(line, sizeof line,
                        "    rounding bound %.3g relative (2 gamma(%llu) x %llu reductions in "
                        "sequence)\n",
                        r.rounding_bound,
                        static_cast<unsigned long long>(r.longest_reduction > 0
                                                            ? r.longest_reduction - 1
                                                            : 0),
                        static_cast<unsigned long long>(r.reduction_rounds)));
  }
  return out;
}

// ---- validation --------------------------------------------------------------------------

std::string to_json(const Validation& v, const ValidateOptions& o) {
  const bool pred = v.predicted_ns != 0;
  nlohmann::json rounds = nlohmann::json::array();
  for (const ValidationRound& r : v.rounds)
    rounds.push_back(
        {{"live_wall_ns", r.live_ns},
         {"engine_wall_ns", r.engine_ns},
         {"replay_wall_ns", r.replay_ns},
         {"predicted_ns", pred ? nlohmann::json(r.predicted_ns) : nlohmann::json(nullptr)},
         {"host_ns", r.host_ns},
         {"serial_ns", r.serial_ns},
         {"replay_sequential_ns", r.replay_sequential_ns},
         {"predicted_sequential_ns",
          pred ? nlohmann::json(r.predicted_sequential_ns) : nlohmann::json(nullptr)},
         {"live_body_ns", pred ? nlohmann::json(r.live_body_ns) : nlohmann::json(nullptr)},
         {"live_wait_ns", pred ? nlohmann::json(r.live_wait_ns) : nlohmann::json(nullptr)},
         {"live_idle_ns", pred ? nlohmann::json(r.live_idle_ns) : nlohmann::json(nullptr)},
         {"predicted_body_ns", pred ? nlohmann::json(r.predicted_body_ns) : nlohmann::json(nullptr)},
         {"predicted_wait_ns", pred ? nlohmann::json(r.predicted_wait_ns) : nlohmann::json(nullptr)},
         {"predicted_overhead_ns",
          pred ? nlohmann::json(r.predicted_overhead_ns) : nlohmann::json(nullptr)},
         {"live_inflation", pred ? nlohmann::json(r.live_inflation) : nlohmann::json(nullptr)},
         {"predicted_inflation",
          pred ? nlohmann::json(r.predicted_inflation) : nlohmann::json(nullptr)}});
  nlohmann::json j = {
      {"scene", o.scene},
      {"policy", std::string(to_string(v.choice.policy))},
      {"method", method_name(v.choice)},
      {"threads", v.threads},
      {"steps", o.steps},
      {"rounds", rounds},
      {"live_wall_ns", v.live_ns},
      {"engine_wall_ns", v.engine_ns},
      {"live_speedup", v.live_speedup},
      {"replay_wall_ns", v.replay_ns},
      {"replay_over_live", v.replay_over_live},
      {"replay_speedup", v.replay_speedup},
      {"replay_speedup_over_live", v.replay_speedup_over_live}};
  j["predicted_ns"] = pred ? nlohmann::json(v.predicted_ns) : nlohmann::json(nullptr);
  j["predicted_over_live"] = pred ? nlohmann::json(v.predicted_over_live) : nlohmann::json(nullptr);
  j["predicted_over_replay"] =
      pred ? nlohmann::json(v.predicted_over_replay) : nlohmann::json(nullptr);
  j["predicted_speedup"] = pred ? nlohmann::json(v.predicted_speedup) : nlohmann::json(nullptr);
  j["predicted_speedup_over_live"] =
      pred ? nlohmann::json(v.predicted_speedup_over_live) : nlohmann::json(nullptr);
  // Where the prediction departs from the live run: the bodies' time, the waits, and the
  // bodies' slow-down (over all kinds and per kind).
  const auto or_null = [pred](double x) { return pred && x > 0 ? nlohmann::json(x) : nlohmann::json(nullptr); };
  j["body_predicted_over_live"] = or_null(v.body_predicted_over_live);
  j["wait_predicted_over_live"] = or_null(v.wait_predicted_over_live);
  j["live_inflation"] = or_null(v.live_inflation);
  j["predicted_inflation"] = or_null(v.predicted_inflation);
  nlohmann::json kinds = nlohmann::json::array();
  for (const KindInflation& k : v.kinds)
    kinds.push_back({{"kind", k.kind},
                     {"instances", k.instances},
                     {"live_inflation", or_null(k.live)},
                     {"predicted_inflation", or_null(k.predicted)},
                     {"live_mean_ns", or_null(k.live_mean_ns)},
                     {"sequential_mean_ns", or_null(k.sequential_mean_ns)},
                     {"captured_mean_ns", or_null(k.captured_mean_ns)}});
  j["kinds"] = kinds;
  j["model"] = v.model;
  j["model_terms"] = v.model_terms;
  j["rounds_with_live_assignments"] = v.rounds_with_live_assignments;
  return j.dump() + "\n";
}

std::string to_text(const Validation& v, const ValidateOptions& o) {
  char line[512];
  std::string out;
  std::snprintf(line, sizeof line,
                "validate %s, %s (%s), %u threads, %u steps (medians of %zu rounds; ratios: "
                "medians of each round's)\n",
                o.scene.c_str(), std::string(to_string(v.choice.policy)).c_str(),
                method_name(v.choice).c_str(), v.threads, o.steps, v.rounds.size());
  out += line;
  std::snprintf(
      line, sizeof line,
      "  live run        %10.3f ms   (uninstrumented engine %.3f ms, speed-up %.2f)\n",
      static_cast<double>(v.live_ns) / 1e6, static_cast<double>(v.engine_ns) / 1e6,
      v.live_speedup);
  out += line;
  std::snprintf(line, sizeof line,
                "  replay          %10.3f ms   replay / live %.3f; speed-up %.2f, / live's %.3f\n",
                static_cast<double>(v.replay_ns) / 1e6, v.replay_over_live, v.replay_speedup,
                v.replay_speedup_over_live);
  out += line;
  if (v.predicted_ns != 0) {
    std::snprintf(line, sizeof line,
                  "  simulator       %10.3f ms   simulator / live %.3f, simulator / replay %.3f; "
                  "speed-up %.2f, / live's %.3f\n",
                  static_cast<double>(v.predicted_ns) / 1e6, v.predicted_over_live,
                  v.predicted_over_replay, v.predicted_speedup, v.predicted_speedup_over_live);
    out += line;
    std::string terms;
    for (const std::string& t : v.model_terms) terms += (terms.empty() ? "" : ", ") + t;
    out += "  model " + v.model + ": " + terms + "\n";
    std::snprintf(line, sizeof line, "  assignments     the live run's in %u of %zu rounds\n",
                  v.rounds_with_live_assignments, v.rounds.size());
    out += line;
    std::snprintf(line, sizeof line,
                  "  where           simulator / live: bodies' time %.3f, waits %.3f; bodies' "
                  "slow-down live %.3f, simulator %.3f\n",
                  v.body_predicted_over_live, v.wait_predicted_over_live, v.live_inflation,
                  v.predicted_inflation);
    out += line;
  }
  return out;
}

}  // namespace tgraph::measure
