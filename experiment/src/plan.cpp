// SPDX-License-Identifier: MIT
// Experiment names, their defaults, the plan of runs, and what the paper reports.
#include <algorithm>
#include <cmath>

#include "common.hpp"
#include "tgraph/experiment/experiment.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/model/cost_model.hpp"

namespace tgraph::experiment {
namespace {

using detail::join;

// The paper compares its partitioned executor with work stealing and per-operation
// barriers; the toolkit adds METIS, Scotch, sticky, OpenMP tasks and StarPU.
const std::vector<std::string> kAllMethods = {"owner",   "metis",     "scotch", "sticky", "worksteal",
                                              "barrier", "omp-tasks", "starpu"};

// The sub-object counts, without duplicates; OptionError for one that is not a perfect
// square from 1 to 4096 (a sheet cut into n x n pieces).
std::vector<int> check_subobjects(const std::vector<int>& counts) {
  std::vector<int> out;
  for (int v : counts) {
    const int root = static_cast<int>(std::lround(std::sqrt(static_cast<double>(std::max(v, 0)))));
    if (v < 1 || v > 4096 || root * root != v)
      throw OptionError("subobjects", std::to_string(v) +
                                          " is not a perfect square from 1 to 4096 (expected "
                                          "e.g. 4,16,64)");
    if (std::find(out.begin(), out.end(), v) == out.end()) out.push_back(v);
  }
  return out;
}

}  // namespace

std::string_view to_string(ExperimentName name) {
  switch (name) {
    case ExperimentName::kIndependent:
      return "independent";
    case ExperimentName::kHeterogeneous:
      return "heterogeneous";
    case ExperimentName::kDomain:
      return "domain";
    case ExperimentName::kMedical:
      return "medical";
  }
  return "?";
}

std::optional<ExperimentName> parse_experiment_name(std::string_view name) {
  for (ExperimentName n : {ExperimentName::kIndependent, ExperimentName::kHeterogeneous,
                           ExperimentName::kDomain, ExperimentName::kMedical})
    if (to_string(n) == name) return n;
  return std::nullopt;
}

std::vector<std::string> experiment_names() {
  return {"independent", "heterogeneous", "domain", "medical"};
}

std::vector<std::string> all_experiment_names() {
  std::vector<std::string> names = experiment_names();
  names.insert(names.end(), {"metg", "scaling"});
  return names;
}

std::string SceneVariant::label() const {
  return subobjects ? scene + "-s" + std::to_string(*subobjects) : scene;
}

bool ExperimentPlan::replays(const std::string& method, std::uint32_t k) const {
  return replay && k > 1 && method != "starpu";
}

std::size_t ExperimentPlan::runs() const {
  std::size_t per_scene = 0;
  for (const std::string& m : methods)
    for (std::uint32_t k : threads.measured) per_scene += replays(m, k) ? 2 : 1;
  return scenes.size() * per_scene + series_methods.size();
}

Invocation ExperimentPlan::invocation() const {
  Invocation inv{std::string(to_string(name)),
                 {{"threads", join(threads.all())},
                  {"steps", std::to_string(steps)},
                  {"repeat", std::to_string(repeat)},
                  {"methods", join(methods)}}};
  if (name == ExperimentName::kDomain) {
    std::vector<std::string> subs;
    for (const SceneVariant& v : scenes)
      if (v.subobjects &&
          std::find(subs.begin(), subs.end(), std::to_string(*v.subobjects)) == subs.end())
        subs.push_back(std::to_string(*v.subobjects));
    if (!subs.empty()) inv.settings.push_back({"subobjects", join(subs)});
  }
  inv.settings.push_back({"replay", std::nullopt, replay});
  if (!calibration.empty()) inv.settings.push_back({"calibration", calibration});
  inv.settings.push_back({"out", out_dir});
  return inv;
}

std::string ExperimentPlan::command() const { return words_of(words, invocation()); }

ExperimentPlan plan_experiment(const ExperimentOptions& o, std::uint32_t cores) {
  ExperimentPlan p;
  p.name = o.name;
  p.cores = std::max(cores, 1u);
  p.out_dir = o.out.empty() ? "tgraph-experiment-" + std::string(to_string(o.name)) : o.out;
  p.words = o.words;
  // Read now: a bad file stops the experiment before its first run.
  if (!o.calibration.empty()) (void)model::select_cost_model("calibrated", o.calibration);
  p.calibration = o.calibration;
  const std::vector<std::uint32_t> ks =
      o.threads.empty() ? default_thread_list(p.cores) : thread_counts(o.threads);
  p.threads = split_threads(ks, p.cores);
  if (o.steps && *o.steps == 0) throw OptionError("steps", "must be at least 1");
  if (o.repeat && *o.repeat == 0) throw OptionError("repeat", "must be at least 1");
  if (!o.subobjects.empty() && o.name != ExperimentName::kDomain)
    throw OptionError("subobjects", "applies to the domain experiment only");

  std::vector<std::string> methods = kAllMethods;
  std::uint32_t steps = 0;
  bool replay = true;
  switch (o.name) {
    case ExperimentName::kIndependent:
      p.scenes = {{"bars64", std::nullopt}};
      steps = o.quick ? 4 : 20;
      break;
    case ExperimentName::kHeterogeneous:
      // The paper's scale: falling64's 64 objects are apart for ~45 steps, then contacts
      // merge them. A quick run takes the small `falling` scene up to its first contacts (step 43).
      p.scenes = {{o.quick ? "falling" : "falling64", std::nullopt}};
      steps = 60;
      p.series_methods = {"sticky", "metis", "metis-relabel"};
      break;
    case ExperimentName::kDomain: {
      const std::vector<int> subs =
          o.subobjects.empty() ? (o.quick ? std::vector<int>{16} : std::vector<int>{16, 64})
                               : check_subobjects(o.subobjects);
      for (const char* scene : {"cloth128", "cloth256", "cloth512"})
        for (int s : subs) p.scenes.push_back({scene, s});
      methods = {"owner"};
      steps = o.quick ? 2 : 10;
      replay = false;  // whole-sheet working sets: a replay costs as much as the live run
      break;
    }
    case ExperimentName::kMedical:
      p.scenes = {{"torso", std::nullopt}};
      steps = o.quick ? 5 : 60;
      break;
  }
#ifndef TGRAPH_HAVE_STARPU
  if (o.methods.empty() && std::find(methods.begin(), methods.end(), "starpu") != methods.end()) {
    methods.erase(std::find(methods.begin(), methods.end(), "starpu"));
    p.notes.push_back("starpu: not in this build (libstarpu-dev was not found), no starpu runs");
  }
#endif
  p.methods = o.methods.empty() ? methods : detail::check_methods(o.methods);
  p.steps = o.steps.value_or(steps);
  p.repeat = o.repeat.value_or(o.quick ? 1 : 3);
  p.replay = o.replay.value_or(replay);
  p.series_threads = p.threads.measured.empty() ? 1 : p.threads.measured.back();
  if (p.threads.measured.empty()) {
    p.series_methods.clear();
    p.notes.push_back("no thread count up to this machine's " + std::to_string(p.cores) +
                      " cores was asked for: predictions only");
  }
  return p;
}

PaperFigure paper_figure(ExperimentName name) {
  switch (name) {
    case ExperimentName::kIndependent:
      return {"Fig. 5",
              "64 identical bars of 16x4x4 nodes (hexahedral FEM), fixed at one end, no "
              "collision; time integration step only. Sequential T1 = 150 ms per step on 16 "
              "cores (8 dual-core 2.2 GHz Opteron, NUMA); the partitioned executor's speed-up "
              "is close to ideal up to 16 cores, ahead of Cilk-like work stealing and "
              "recursive (barrier) parallelism.",
              {{"bars64", 150.0}}};
    case ExperimentName::kHeterogeneous:
      return {"Fig. 6 and 8",
              "Heterogeneous objects (rigid, mass-spring, FEM, grid; 400 to 2,500 surface "
              "triangles) falling into one collision group, 16-core Opteron. High speed-up "
              "while objects are apart, less as they form one group sharing a CG loop. "
              "Updating the task graph when collision groups change costs close to 30 ms, "
              "about one time step.",
              {}};
    case ExperimentName::kDomain:
      return {"Fig. 7",
              "A mass-spring sheet cut into connected sub-objects sharing one CG loop, 16-core "
              "Opteron. Sequential time per step 125 ms (128x128), 500 ms (256x256), 2.2 s "
              "(512x512); the smaller sheets scale better (memory accesses of the larger ones).",
              {{"cloth128", 125.0}, {"cloth256", 500.0}, {"cloth512", 2200.0}}};
    case ExperimentName::kMedical:
      return {"Section 4.4",
              "A torso: rigid bones, FEM lungs and liver, spring intestine, on a dual quad-core "
              "Xeon (8 cores). Sequential integration 50 ms per step, 14 ms on 8 cores: "
              "speed-up about 3.5.",
              {{"torso", 50.0}}};
  }
  return {};
}

}  // namespace tgraph::experiment
