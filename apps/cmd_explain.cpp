// SPDX-License-Identifier: MIT
// `tgraph explain FILE [--step N] [--json]`: where each step's time went (tgraph::explain):
// FILE is a timeline (replay --timeline, run --timeline) or a run's or replay's JSON, whose
// attribution it prints, or whose timeline (its "timeline" key) it explains.
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "commands.hpp"
#include "tgraph/explain/explain.hpp"
#include "tgraph/graph/timeline.hpp"

namespace tgraph::app {
namespace {

struct ExplainArgs {
  std::string input;
  std::optional<std::uint32_t> step;
  bool json = false;
};

// A run's or replay's JSON without a timeline: its attribution, per step, as the table.
std::string attribution_only(const nlohmann::json& j, const ExplainArgs& a) {
  if (!j.contains("attribution") || !j["attribution"].is_object())
    throw InputError(a.input, std::nullopt,
                     "neither a timeline nor a result with \"attribution\" (expected tgraph "
                     "replay/run --json output or a --timeline file)");
  explain::Explanation e;
  e.threads = j.value("threads", 0u);
  const auto read = [&](const nlohmann::json& o) {
    explain::Attribution at;
    try {
      at.lost_ns = o.at("lost_ns").get<std::int64_t>();
      for (const std::string_view n : explain::cause_names())
        explain::cause(at.causes, n) = o.at("causes").at(std::string(n)).get<std::int64_t>();
    } catch (const nlohmann::json::exception&) {
      throw InputError(a.input, std::nullopt,
                       "\"attribution\" must hold lost_ns and causes {serial, ..., residual}");
    }
    return at;
  };
  e.attribution = read(j["attribution"]);
  if (j.contains("per_step") && j["per_step"].is_array()) {
    std::uint32_t index = 0;
    for (const auto& s : j["per_step"]) {
      const std::uint32_t step = s.value("step", index);
      ++index;
      if (a.step && step != *a.step) continue;
      if (!s.contains("attribution")) continue;
      explain::StepExplanation x;
      x.step = step;
      x.threads = e.threads;
      x.attribution = read(s["attribution"]);
      // The attribution is of the observed pass, whose makespan the result does not give.
      x.makespan_ns = 0;
      x.work_ns = 0;
      e.steps.push_back(std::move(x));
    }
    if (a.step && e.steps.empty())
      throw InputError(a.input, std::nullopt, "no step " + std::to_string(*a.step));
  }
  if (a.json) {
    nlohmann::json out = nlohmann::json::parse(explain::explanation_json(e));
    return out.dump() + "\n";
  }
  return explain::explanation_text(e, a.input) +
         "(no timeline: record one with --timeline for the critical path and the what-ifs)\n";
}

}  // namespace

void add_explain(CLI::App& app) {
  auto a = std::make_shared<ExplainArgs>();
  auto* cmd = app.add_subcommand(
      "explain",
      "Where each step's time went: the lost processor time by cause, the critical path, "
      "what-ifs (docs/explain.md)");
  cmd->add_option("file", a->input,
                  "A timeline (replay/run --timeline) or a replay/run --json result")
      ->required();
  cmd->add_option("--step", a->step, "Only this step (its number in the file)");
  cmd->add_flag("--json", a->json, "Print one JSON object");
  cmd->callback([a] {
    const std::string text = read_file_text(a->input);
    const bool gzip = text.size() >= 2 && static_cast<unsigned char>(text[0]) == 0x1f &&
                      static_cast<unsigned char>(text[1]) == 0x8b;
    std::string timeline_path = a->input;
    if (!gzip) {
      const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
      if (j.is_discarded())
        throw InputError(a->input, std::nullopt,
                         "not JSON (expected a timeline or a replay/run --json result)");
      if (j.is_object() && !j.contains("tasks")) {
        // A result: its timeline when it names one that exists, else its attribution.
        if (j.contains("timeline") && j["timeline"].is_string()) {
          std::filesystem::path p = j["timeline"].get<std::string>();
          if (p.is_relative()) p = std::filesystem::path(a->input).parent_path() / p;
          if (std::filesystem::exists(p)) timeline_path = p.string();
        }
        if (timeline_path == a->input) {
          std::cout << attribution_only(j, *a);
          return;
        }
      }
    }
    const Timeline t = timeline_path == a->input ? parse_timeline(text, a->input)
                                                 : read_timeline(timeline_path);
    explain::ExplainOptions o;
    o.step = a->step;
    const explain::Explanation e = explain::explain_timeline(t, timeline_path, o);
    std::cout << (a->json ? explain::explanation_json(e) + "\n"
                          : explain::explanation_text(e, timeline_path));
  });
}

}  // namespace tgraph::app
