// SPDX-License-Identifier: MIT
// The METG experiment (after Task Bench, Slaughter et al., SC'20): every policy runs the same
// synthetic step at a sweep of task durations (the bodies are calibrated spins without data,
// Task Bench's compute-bound kernel). Task granularity is threads x wall time / task
// instances (Task Bench's); efficiency is the sequential policy's wall time on the same step
// in the same run over threads x wall time (Task Bench divides by the kernel's peak instead,
// reported as work_efficiency); METG(50 %) is the smallest granularity whose efficiency is
// still at least 50 %.
#include "tgraph/experiment/metg.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <iomanip>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common.hpp"
#include "tgraph/experiment/threads.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/graph/median.hpp"
#include "tgraph/measure/capture.hpp"
#include "tgraph/partition/strategy.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/synthetic.hpp"
#include "tgraph/viz/series_chart.hpp"

namespace tgraph::experiment {
namespace {

namespace tr = tgraph::replay;

constexpr MetgShape kShapes[] = {MetgShape::kTrivial, MetgShape::kStencil, MetgShape::kFft,
                                 MetgShape::kRandomNearest, MetgShape::kBars64};

/// The sweep: durations from the largest down, a step count sized to a work budget.
struct Sweep {
  std::vector<std::uint64_t> task_ns;  ///< descending
  std::uint64_t work_ns = 0;           ///< work of one step (sum of task durations), about
  std::uint32_t repeat = 1;            ///< timed passes (median), after one warm-up pass
};

Sweep sweep_for(bool quick) {
  Sweep s;
  if (quick) {
    s.task_ns = {256'000, 64'000, 16'000, 4'000, 1'000};
    s.work_ns = 8'000'000;
    s.repeat = 1;
  } else {
    for (std::uint64_t d = 256'000; d >= 250; d /= 2) s.task_ns.push_back(d);
    s.work_ns = 40'000'000;
    s.repeat = 3;
  }
  return s;
}

/// SplitMix64: the random_nearest pattern's seeded choices.
std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

/// Points of step t - 1 that point i of step t depends on.
void dependences(MetgShape shape, std::uint32_t width, std::uint32_t t, std::uint32_t i,
                 std::vector<std::uint32_t>& out) {
  out.clear();
  switch (shape) {
    case MetgShape::kTrivial:
    case MetgShape::kBars64:
      return;
    case MetgShape::kStencil:
      if (i > 0) out.push_back(i - 1);
      out.push_back(i);
      if (i + 1 < width) out.push_back(i + 1);
      return;
    case MetgShape::kFft: {
      std::uint32_t stages = 1;
      while ((1u << stages) < width) ++stages;
      const std::uint32_t partner = i ^ (1u << ((t - 1) % stages));
      out.push_back(i);
      if (partner < width) out.push_back(partner);
      std::sort(out.begin(), out.end());
      return;
    }
    case MetgShape::kRandomNearest:
      for (std::int64_t j = std::int64_t{i} - 2; j <= std::int64_t{i} + 2; ++j) {
        if (j < 0 || j >= width) continue;
        const bool self = j == i;
        if (self || (mix((std::uint64_t{t} << 32) ^ (std::uint64_t{i} << 8) ^
                         static_cast<std::uint64_t>(j)) &
                     1) != 0)
          out.push_back(static_cast<std::uint32_t>(j));
      }
      return;
  }
}

/// bars64's first step as the engine records it.
StepGraph capture_bars64() { return measure::capture_trace("bars64", 1).steps.front(); }

/// Task instances of one step (loop bodies times their recorded iterations).
std::uint64_t instances_of(const StepGraph& g) {
  std::uint64_t n = 0;
  for (const Task& t : g.tasks) n += t.loop == kNoLoop ? 1 : g.loops[t.loop].iterations;
  return n;
}

/// bars64 with every task lasting `task_ns` and its loops cut to fit `work_ns` (at least one
/// iteration, at most the recorded count).
StepGraph sized_bars64(const StepGraph& captured, std::uint64_t task_ns, std::uint64_t work_ns) {
  StepGraph g = captured;
  std::uint64_t outside = 0, body = 0;
  for (const Task& t : g.tasks) (t.loop == kNoLoop ? outside : body) += 1;
  const std::uint64_t budget = work_ns / task_ns;
  const std::uint64_t fit = budget > outside && body > 0 ? (budget - outside) / body : 1;
  for (Loop& l : g.loops)
    l.iterations = static_cast<std::uint32_t>(std::clamp<std::uint64_t>(fit, 1, l.iterations));
  for (Task& t : g.tasks) t.cost_ns = task_ns;
  return g;
}

/// Width of the synthetic shapes: two points per core of the machine (at least 4), so that
/// every measured thread count has parallel slack.
std::uint32_t shape_width(std::uint32_t cores) { return std::max(4u, 2 * cores); }

std::vector<std::string> check_policies(const std::vector<std::string>& names) {
  std::vector<std::string> out;
  if (names.empty()) {
    out = {"sequential", "partition", "worksteal", "barrier", "omp-tasks"};
#ifdef TGRAPH_HAVE_STARPU
    out.push_back("starpu");
#endif
    return out;
  }
  for (const std::string& p : names) {
    if (!tr::parse_policy(p))
      throw OptionError("methods", "unknown policy '" + p +
                                       "' (expected sequential, partition, worksteal, barrier, "
                                       "omp-tasks, starpu)");
    if (std::find(out.begin(), out.end(), p) == out.end()) out.push_back(p);
  }
  return out;
}

/// Times `g` under one executor: a warm-up step, then the median of `repeat` steps.
MetgPoint time_point(tr::Executor& ex, const StepGraph& g, const Assignment* a,
                     std::uint32_t repeat) {
  tr::SyntheticWorkload w({.cost_scale = 1.0, .touch = false});
  w.set_step(g);
  ex.run_step(g, a, w);
  std::vector<std::int64_t> walls;
  for (std::uint32_t r = 0; r < repeat; ++r) walls.push_back(ex.run_step(g, a, w).wall_ns);
  MetgPoint p;
  p.threads = ex.threads();
  p.instances = instances_of(g);
  p.wall_ns = std::max<std::int64_t>(1, median(walls));
  return p;
}

/// The METG record of the points of one (policy, shape, threads).
MetgRecord record_of(const std::vector<MetgPoint>& points) {
  MetgRecord r;
  r.policy = points.front().policy;
  r.shape = points.front().shape;
  r.threads = points.front().threads;
  for (const MetgPoint& p : points)
    if (p.efficiency >= 0.5 && (!r.metg_ns || p.granularity_ns < *r.metg_ns)) {
      r.metg_ns = p.granularity_ns;
      r.task_ns = p.task_ns;
      r.efficiency = p.efficiency;
    }
  return r;
}

viz::SeriesChart efficiency_chart(const MetgResult& res, const std::string& shape,
                                  std::uint32_t threads) {
  viz::SeriesChart c;
  c.title = "Efficiency against task duration: " + shape + ", " + std::to_string(threads) +
            " thread" + (threads == 1 ? "" : "s");
  c.subtitle = "efficiency = sequential wall / (threads x wall), same step, same run; "
               "METG(50 %) where a line crosses 0.5; " + res.machine.summary();
  c.x_title = "task duration (us)";
  c.y_title = "efficiency";
  c.log2_x = true;
  viz::Series half{"50 % (METG threshold)", viz::SeriesKind::kReference, 0, {}};
  std::map<std::string, viz::Series> lines;
  std::uint32_t colour = 0;
  for (const std::string& policy : res.policies) {
    viz::Series s{policy, viz::SeriesKind::kMeasured, colour++, {}};
    for (const MetgPoint& p : res.points)
      if (p.policy == policy && p.shape == shape &&
          (p.threads == threads || (policy == "sequential" && p.threads == 1)))
        s.points.push_back({static_cast<double>(p.task_ns) / 1000.0, p.efficiency});
    std::sort(s.points.begin(), s.points.end(),
              [](const viz::SeriesPoint& a, const viz::SeriesPoint& b) { return a.x < b.x; });
    if (!s.points.empty()) c.series.push_back(std::move(s));
  }
  for (const viz::Series& s : c.series)
    for (const viz::SeriesPoint& p : s.points)
      if (half.points.empty() || p.x < half.points.front().x) half.points.insert(half.points.begin(), {p.x, 0.5});
      else if (p.x > half.points.back().x) half.points.push_back({p.x, 0.5});
  c.series.insert(c.series.begin(), std::move(half));
  return c;
}

void write_outputs(MetgResult& res) {
  namespace fs = std::filesystem;
  const std::string dir = res.options.out;
  std::vector<std::pair<std::string, std::string>> files;
  std::ostringstream csv;
  csv << "policy,shape,threads,task_ns,instances,wall_ns,efficiency,work_efficiency,"
         "granularity_ns\n";
  for (const MetgPoint& p : res.points)
    csv << p.policy << ',' << p.shape << ',' << p.threads << ',' << p.task_ns << ','
        << p.instances << ',' << p.wall_ns << ',' << p.efficiency << ',' << p.work_efficiency
        << ',' << p.granularity_ns << '\n';
  files.emplace_back("results.csv", csv.str());
  const std::uint32_t top = res.threads.empty() ? 1 : res.threads.back();
  for (const std::string& shape : res.shapes) {
    const viz::SeriesChart c = efficiency_chart(res, shape, top);
    files.emplace_back("efficiency-" + shape + ".svg",
                       viz::render_series_chart(c, viz::TimelineFormat::kSvg));
    files.emplace_back("efficiency-" + shape + ".png",
                       viz::render_series_chart(c, viz::TimelineFormat::kPng));
  }
  res.files.clear();
  for (const auto& f : files) res.files.push_back(f.first);
  res.files.insert(res.files.begin(), "results.json");
  write_file_atomic((fs::path(dir) / "results.json").string(), metg_json(res, 2) + "\n");
  for (const auto& [name, content] : files) write_file_atomic((fs::path(dir) / name).string(), content);
}

}  // namespace

std::string_view to_string(MetgShape shape) {
  switch (shape) {
    case MetgShape::kTrivial:
      return "trivial";
    case MetgShape::kStencil:
      return "stencil";
    case MetgShape::kFft:
      return "fft";
    case MetgShape::kRandomNearest:
      return "random_nearest";
    case MetgShape::kBars64:
      return "bars64";
  }
  return "?";
}

StepGraph metg_graph(MetgShape shape, std::uint32_t width, std::uint32_t steps,
                     std::uint64_t task_ns) {
  if (shape == MetgShape::kBars64) throw UsageError("metg_graph: bars64 is captured, not built");
  StepGraph g;
  const KindId kind = g.intern_kind(std::string(to_string(shape)));
  for (std::uint32_t i = 0; i < width; ++i) g.objects.push_back({"point" + std::to_string(i)});
  g.data.reserve(std::size_t{width} * steps);
  for (std::uint32_t t = 0; t < steps; ++t)
    for (std::uint32_t i = 0; i < width; ++i)
      g.data.push_back({"p" + std::to_string(i) + "@" + std::to_string(t), i, 8});
  std::vector<std::uint32_t> deps;
  std::vector<Access> acc;
  for (std::uint32_t t = 0; t < steps; ++t)
    for (std::uint32_t i = 0; i < width; ++i) {
      acc.clear();
      if (t > 0) {
        dependences(shape, width, t, i, deps);
        for (std::uint32_t j : deps) acc.push_back({(t - 1) * width + j, AccessMode::R});
      }
      acc.push_back({t * width + i, AccessMode::W});
      g.add_task(kind, i, acc, task_ns, (std::uint64_t{t} << 32) + i + 1);
    }
  g.derive_edges();
  return g;
}

Invocation MetgResult::invocation() const {
  Invocation inv{"metg", {}};
  if (options.quick) inv.settings.push_back({"quick", std::nullopt});
  if (!options.threads.empty()) inv.settings.push_back({"threads", detail::join(threads)});
  if (!options.methods.empty()) inv.settings.push_back({"methods", detail::join(policies)});
  inv.settings.push_back({"out", options.out});
  return inv;
}

std::string MetgResult::command() const { return words_of(options.words, invocation()); }

MetgResult run_metg(const MetgOptions& options, Progress& progress) {
  MetgResult res;
  res.options = options;
  if (res.options.out.empty()) res.options.out = "tgraph-experiment-metg";
  res.machine = probe_machine();
  res.date = detail::utc_now();
  const std::uint32_t cores = std::max(1u, res.machine.cores);
  if (options.threads.empty()) {
    for (std::uint32_t k = 1; k <= cores; ++k) res.threads.push_back(k);
  } else {
    res.threads = thread_counts(options.threads);
  }
  res.policies = check_policies(options.methods);
  detail::make_results_folder(res.options.out);
  for (MetgShape s : kShapes) res.shapes.emplace_back(to_string(s));
  const Sweep sweep = sweep_for(options.quick);
  const auto t0 = std::chrono::steady_clock::now();
  const std::uint32_t width = shape_width(cores);
  const StepGraph bars = capture_bars64();
  struct Run {
    tr::Policy policy;
    std::string name;
    std::uint32_t threads;
    std::vector<MetgPoint> points;
    int below = 0;  // consecutive points under 50 %: the run's sweep stops after two
  };
  // A policy that cannot run some of the thread counts (StarPU beyond its build's CPU
  // workers) runs the others; the skipped ones are named once, here and in the results.
  for (const std::string& name : res.policies) {
    const std::optional<std::uint32_t> top = tr::max_threads(*tr::parse_policy(name));
    std::vector<std::uint32_t> over;
    for (std::uint32_t k : res.threads)
      if (top && k > *top) over.push_back(k);
    if (over.empty()) continue;
    std::string line = name + " skipped at";
    for (std::uint32_t k : over) line += " " + std::to_string(k);
    line += " threads: this " + name + " build has at most " + std::to_string(*top) +
            " CPU workers";
    progress.note(line);
    res.skipped.push_back(std::move(line));
  }
  progress.set_total(std::size(kShapes));
  for (MetgShape shape : kShapes) {
    const std::string shape_name(to_string(shape));
    std::vector<Run> runs;
    for (const std::string& name : res.policies) {
      const tr::Policy policy = *tr::parse_policy(name);
      if (policy == tr::Policy::kSequential) continue;  // the reference, timed at every point
      const std::optional<std::uint32_t> top = tr::max_threads(policy);
      for (std::uint32_t k : res.threads)
        if (!top || k <= *top) runs.push_back({policy, name, k, {}, 0});
    }
    progress.begin(shape_name);
    std::vector<MetgPoint> reference;
    for (std::uint64_t d : sweep.task_ns) {
      StepGraph g;
      if (shape == MetgShape::kBars64) {
        g = sized_bars64(bars, d, sweep.work_ns);
        if (instances_of(g) * d > 4 * sweep.work_ns) continue;  // one CG iteration is too long
      } else {
        const std::uint64_t steps = std::clamp<std::uint64_t>(sweep.work_ns / (d * width), 4,
                                                              options.quick ? 500 : 5000);
        g = metg_graph(shape, width, static_cast<std::uint32_t>(steps), d);
      }
      auto point = [&](tr::Policy policy, const std::string& name, std::uint32_t threads) {
        tr::ExecOptions eo;
        eo.threads = threads;
        auto ex = tr::make_executor(policy, eo);  // one at a time: StarPU is one per process
        std::optional<Assignment> a;
        if (policy == tr::Policy::kPartition)
          a = partition::make_strategy("owner")->partition(g, threads, {}, {}).assignment;
        MetgPoint p = time_point(*ex, g, a ? &*a : nullptr, sweep.repeat);
        p.policy = name;
        p.shape = shape_name;
        p.task_ns = d;
        const double wall_x_threads = static_cast<double>(p.wall_ns) * threads;
        p.work_efficiency = static_cast<double>(p.instances) * static_cast<double>(d) / wall_x_threads;
        p.granularity_ns = static_cast<std::uint64_t>(
            std::llround(wall_x_threads / static_cast<double>(p.instances)));
        return p;
      };
      MetgPoint seq = point(tr::Policy::kSequential, "sequential", 1);
      seq.efficiency = 1.0;
      const bool any = std::any_of(runs.begin(), runs.end(), [](const Run& r) { return r.below < 2; });
      if (!any && !reference.empty()) break;
      reference.push_back(seq);
      for (Run& r : runs) {
        if (r.below >= 2) continue;
        MetgPoint p = point(r.policy, r.name, r.threads);
        p.efficiency = static_cast<double>(seq.wall_ns) / (static_cast<double>(p.wall_ns) * r.threads);
        r.below = p.efficiency < 0.5 ? r.below + 1 : 0;
        r.points.push_back(p);
      }
    }
    std::ostringstream line;
    line << shape_name << ":";
    if (std::find(res.policies.begin(), res.policies.end(), "sequential") != res.policies.end() &&
        !reference.empty()) {
      res.points.insert(res.points.end(), reference.begin(), reference.end());
      res.records.push_back(record_of(reference));
    }
    for (Run& r : runs) {
      if (r.points.empty()) continue;
      res.points.insert(res.points.end(), r.points.begin(), r.points.end());
      const MetgRecord rec = record_of(r.points);
      res.records.push_back(rec);
      line << " " << r.name << "/" << r.threads << " "
           << (rec.metg_ns ? std::to_string(*rec.metg_ns / 1000) + "us" : std::string("-"));
    }
    progress.end(line.str());
  }
  progress.finish();
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  write_outputs(res);
  return res;
}

std::string metg_json(const MetgResult& res, int indent) {
  nlohmann::json j;
  j["experiment"] = "metg";
  j["command"] = res.command();
  j["definition"] =
      "granularity = threads x wall time / task instances (Task Bench, Slaughter et al., "
      "SC'20); efficiency = the sequential policy's wall time on the same step in the same run "
      "/ (threads x wall time) (Task Bench divides by the kernel's peak instead: that is "
      "work_efficiency, instances x duration of the calibrated spins / (threads x wall)); "
      "METG(50 %) = the smallest granularity among the swept durations whose efficiency is at "
      "least 50 %";
  j["machine"] = res.machine.summary();
  j["date"] = res.date;
  j["seconds"] = res.seconds;
  j["threads"] = res.threads;
  j["policies"] = res.policies;
  j["shapes"] = res.shapes;
  j["metg"] = nlohmann::json::array();
  j["unreached"] = nlohmann::json::array();
  j["skipped"] = res.skipped;
  for (const MetgRecord& r : res.records) {
    nlohmann::json o = {{"policy", r.policy}, {"shape", r.shape}, {"threads", r.threads}};
    if (r.metg_ns) {
      o["metg_ns"] = *r.metg_ns;
      o["task_ns"] = r.task_ns;
      o["efficiency"] = r.efficiency;
      j["metg"].push_back(o);
    } else {
      j["unreached"].push_back(o);
    }
  }
  j["points"] = nlohmann::json::array();
  for (const MetgPoint& p : res.points)
    j["points"].push_back({{"policy", p.policy},
                           {"shape", p.shape},
                           {"threads", p.threads},
                           {"task_ns", p.task_ns},
                           {"instances", p.instances},
                           {"wall_ns", p.wall_ns},
                           {"efficiency", p.efficiency},
                           {"work_efficiency", p.work_efficiency},
                           {"granularity_ns", p.granularity_ns}});
  j["files"] = res.files;
  return j.dump(indent);
}

std::string metg_text(const MetgResult& res) {
  std::ostringstream s;
  s << "METG(50 %) in us (threads x wall / tasks at the smallest swept duration whose "
       "efficiency, sequential wall / (threads x wall), is >= 50 %); "
    << res.machine.summary() << "\n";
  s << std::left << std::setw(12) << "policy" << std::setw(4) << "K";
  for (const std::string& shape : res.shapes) s << std::right << std::setw(16) << shape;
  s << "\n";
  for (const std::string& policy : res.policies)
    for (std::uint32_t k : res.threads) {
      std::vector<const MetgRecord*> row;
      for (const std::string& shape : res.shapes)
        for (const MetgRecord& r : res.records)
          if (r.policy == policy && r.shape == shape && r.threads == k) row.push_back(&r);
      if (row.empty()) continue;
      s << std::left << std::setw(12) << policy << std::setw(4) << k;
      for (const MetgRecord* r : row) {
        std::ostringstream cell;
        if (r->metg_ns)
          cell << std::fixed << std::setprecision(2) << static_cast<double>(*r->metg_ns) / 1000.0;
        else
          cell << "-";
        s << std::right << std::setw(16) << cell.str();
      }
      s << "\n";
    }
  for (const std::string& line : res.skipped) s << line << "\n";
  s << "files in " << res.options.out << ":";
  for (const std::string& f : res.files) s << " " << f;
  s << "\n";
  return s.str();
}

}  // namespace tgraph::experiment
