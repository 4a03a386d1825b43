// SPDX-License-Identifier: MIT
// The explanation as JSON (`tgraph explain --json`, the `attribution` key of the results)
// and as the table `tgraph explain` prints.
#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "tgraph/explain/explain.hpp"

namespace tgraph::explain {

using nlohmann::json;

namespace {

json attribution_object(const Attribution& a) {
  json causes = json::object();
  for (const std::string_view n : cause_names()) causes[std::string(n)] = cause(a.causes, n);
  return {{"lost_ns", a.lost_ns}, {"causes", causes}};
}

json what_if_array(const std::vector<WhatIf>& v) {
  json a = json::array();
  for (const WhatIf& w : v)
    a.push_back({{"target", w.target},
                 {"change", w.change},
                 {"predicted_ns", w.predicted_ns},
                 {"gain", w.gain},
                 {"model", w.model},
                 {"scope", w.scope}});
  return a;
}

}  // namespace

std::string attribution_json(const Attribution& a) { return attribution_object(a).dump(); }

std::string explanation_json(const Explanation& e) {
  json steps = json::array();
  for (const StepExplanation& s : e.steps) {
    json path = json::array();
    for (const PathLink& l : s.critical_path)
      path.push_back({{"task", l.task ? json(*l.task) : json(nullptr)},
                      {"kind", l.kind},
                      {"thread", l.thread},
                      {"iteration", l.iteration},
                      {"start_ns", l.start_ns},
                      {"end_ns", l.end_ns},
                      {"link", std::string(to_string(l.link))}});
    json split = json::object();
    for (const auto& [name, ns] : s.makespan_split) split[name] = ns;
    json late = json::array();
    for (const LateWriter& w : s.late_writers)
      late.push_back({{"task", w.task},
                      {"kind", w.kind},
                      {"datum", w.datum},
                      {"wait_ns", w.wait_ns},
                      {"late_ns", w.late_ns}});
    steps.push_back({{"step", s.step},
                     {"threads", s.threads},
                     {"makespan_ns", s.makespan_ns},
                     {"serial_ns", s.serial_ns},
                     {"work_ns", s.work_ns},
                     {"span_ns", s.span_ns},
                     {"instances", s.instances},
                     {"unobserved_instances", s.unobserved},
                     {"attribution", attribution_object(s.attribution)},
                     {"makespan_split", split},
                     {"critical_path", path},
                     {"late_writers", late},
                     {"what_if", what_if_array(s.what_if)},
                     {"simulated_ns", s.simulated_ns}});
  }
  return json{{"threads", e.threads},
              {"attribution", attribution_object(e.attribution)},
              {"what_if", what_if_array(e.what_if)},
              {"steps", steps}}
      .dump();
}

std::string explanation_text(const Explanation& e, const std::string& name) {
  std::string out;
  char line[640];
  const auto add = [&](int n) {
    out.append(line, static_cast<std::size_t>(std::clamp(n, 0, static_cast<int>(sizeof line) - 1)));
  };
  const auto ms = [](std::int64_t ns) { return static_cast<double>(ns) / 1e6; };
  const auto pct = [](std::int64_t part, std::int64_t whole) {
    return whole != 0 ? 100.0 * static_cast<double>(part) / static_cast<double>(whole) : 0.0;
  };
  add(std::snprintf(line, sizeof line,
                    "explain %s: %zu steps, %u threads; lost time = threads x makespan - "
                    "sequential work, its causes in %% of it\n",
                    name.c_str(), e.steps.size(), e.threads));
  add(std::snprintf(line, sizeof line, "%6s %10s %10s %6s", "step", "makespan", "lost", "eff"));
  static const char* kShort[] = {"serial", "imbal", "depwait", "handoff", "interr",
                                 "inflat", "runtime", "starv", "resid"};
  for (const char* s : kShort) add(std::snprintf(line, sizeof line, " %7s", s));
  out += "\n";
  const auto row = [&](const char* label, std::int64_t makespan, std::int64_t work,
                       std::uint32_t threads, const Attribution& a) {
    const double eff = makespan > 0 && threads > 0
                           ? static_cast<double>(work) /
                                 (static_cast<double>(threads) * static_cast<double>(makespan))
                           : 0.0;
    if (makespan > 0)
      add(std::snprintf(line, sizeof line, "%6s %8.3fms %8.3fms %6.2f", label, ms(makespan),
                        ms(a.lost_ns), eff));
    else
      add(std::snprintf(line, sizeof line, "%6s %10s %8.3fms %6s", label, "-", ms(a.lost_ns), "-"));
    for (const std::string_view n : cause_names())
      add(std::snprintf(line, sizeof line, " %6.1f%%", pct(cause(a.causes, n), a.lost_ns)));
    out += "\n";
  };
  std::int64_t makespan = 0, work = 0;
  for (const StepExplanation& s : e.steps) {
    row(std::to_string(s.step).c_str(), s.makespan_ns, s.work_ns, s.threads, s.attribution);
    makespan += s.makespan_ns;
    work += s.work_ns;
  }
  if (e.steps.size() > 1) row("all", makespan, work, e.threads, e.attribution);
  if (e.steps.size() == 1) {
    const StepExplanation& s = e.steps.front();
    add(std::snprintf(line, sizeof line,
                      "\nstep %u: makespan %.3f ms, sequential work %.3f ms, span %.3f ms, "
                      "%llu instances%s\n",
                      s.step, ms(s.makespan_ns), ms(s.work_ns), ms(s.span_ns),
                      static_cast<unsigned long long>(s.instances),
                      s.unobserved ? " (some not observed: the timeline was sampled)" : ""));
    out += "  the makespan along the critical path:";
    for (const auto& [n, ns] : s.makespan_split)
      add(std::snprintf(line, sizeof line, " %s %.1f%%", n.c_str(), pct(ns, s.makespan_ns)));
    out += "\n  critical path (longest links first, of " + std::to_string(s.critical_path.size()) +
           "):\n";
    std::vector<const PathLink*> links;
    for (const PathLink& l : s.critical_path) links.push_back(&l);
    std::stable_sort(links.begin(), links.end(), [](const PathLink* a, const PathLink* b) {
      return a->end_ns - a->start_ns > b->end_ns - b->start_ns;
    });
    for (std::size_t k = 0; k < std::min<std::size_t>(links.size(), 12); ++k) {
      const PathLink& l = *links[k];
      add(std::snprintf(line, sizeof line, "    %-8s %9.3f ms  at %9.3f ms  thread %u  %s%s\n",
                        std::string(to_string(l.link)).c_str(), ms(l.end_ns - l.start_ns),
                        ms(l.start_ns), l.thread, l.kind.c_str(),
                        l.task ? (" (task " + std::to_string(*l.task) + ", iteration " +
                                  std::to_string(l.iteration) + ")")
                                     .c_str()
                               : ""));
    }
    if (!s.late_writers.empty()) out += "  writers waited for (dependency waits):\n";
    for (const LateWriter& w : s.late_writers)
      add(std::snprintf(line, sizeof line,
                        "    %9.3f ms  %s (task %u) writing %s, started %.3f ms after its inputs\n",
                        ms(w.wait_ns), w.kind.c_str(), w.task, w.datum.c_str(), ms(w.late_ns)));
  }
  const std::vector<WhatIf>& wi = e.steps.size() == 1 ? e.steps.front().what_if : e.what_if;
  if (!wi.empty())
    out += "\nwhat if (predicted time, gain, the model: simulator or executed schedule):\n";
  for (std::size_t k = 0; k < std::min<std::size_t>(wi.size(), 10); ++k)
    add(std::snprintf(line, sizeof line, "  %-31s %-34s %10.3f ms  %+8.3f ms (%.1f%%)  %s\n",
                      (wi[k].scope == "cause" ? wi[k].target : wi[k].scope + " " + wi[k].target)
                          .c_str(),
                      wi[k].change.c_str(), ms(wi[k].predicted_ns),
                      ms(wi[k].gain), pct(wi[k].gain, wi[k].predicted_ns + wi[k].gain),
                      wi[k].model.c_str()));
  return out;
}

}  // namespace tgraph::explain
