// SPDX-License-Identifier: MIT
#include "tgraph/replay/measure.hpp"

#include <linux/perf_event.h>
#include <sys/ioctl.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/median.hpp"
#include "tgraph/graph/metrics.hpp"

namespace tgraph::replay {

CacheMissCounter::CacheMissCounter() {
  perf_event_attr attr;
  std::memset(&attr, 0, sizeof attr);
  attr.size = sizeof attr;
  attr.type = PERF_TYPE_HARDWARE;
  attr.config = PERF_COUNT_HW_CACHE_MISSES;
  attr.disabled = 0;
  attr.inherit = 1;
  attr.exclude_kernel = 1;
  attr.exclude_hv = 1;
  const long fd = syscall(SYS_perf_event_open, &attr, 0, -1, -1, 0);
  if (fd < 0) {
    reason_ = std::string("not counted: the kernel refused hardware performance counters "
                          "(perf_event_open: ") +
              std::strerror(errno) + ")";
    return;
  }
  fd_ = static_cast<int>(fd);
}

CacheMissCounter::~CacheMissCounter() {
  if (fd_ >= 0) close(fd_);
}

std::uint64_t CacheMissCounter::read() const {
  if (fd_ < 0) return 0;
  std::uint64_t v = 0;
  if (::read(fd_, &v, sizeof v) != static_cast<ssize_t>(sizeof v)) return 0;
  return v;
}

std::uint64_t ReplayResult::signals() const {
  std::uint64_t s = 0;
  for (const auto& m : steps) s += m.signals;
  return s;
}
std::uint64_t ReplayResult::waits() const {
  std::uint64_t s = 0;
  for (const auto& m : steps) s += m.waits;
  return s;
}
std::int64_t ReplayResult::wait_ns() const {
  std::int64_t s = 0;
  for (const auto& m : steps) s += m.wait_ns;
  return s;
}
std::int64_t ReplayResult::build_ns() const {
  std::int64_t s = 0;
  for (const auto& m : steps) s += m.build_ns;
  return s;
}

std::int64_t ReplayResult::rebuild_ns() const {
  std::int64_t s = 0;
  for (const auto& m : steps) s += m.rebuild_ns;
  return s;
}
std::uint64_t ReplayResult::remote_bytes() const {
  std::uint64_t s = 0;
  for (const auto& m : steps) s += m.remote_bytes;
  return s;
}
std::uint64_t ReplayResult::migrated_bytes() const {
  std::uint64_t s = 0;
  for (const auto& m : steps) s += m.migrated_bytes;
  return s;
}
std::optional<std::uint64_t> ReplayResult::predicted_makespan_ns() const {
  std::uint64_t s = 0;
  for (const auto& m : steps) {
    if (!m.predicted_makespan_ns) return std::nullopt;
    s += *m.predicted_makespan_ns;
  }
  return s;
}

ReplayResult replay_trace(const Trace& trace, const TraceAssignment* assignments,
                          const ReplayOptions& o, const std::vector<std::uint64_t>* predicted,
                          TimelineObserver* timeline) {
  if (o.exec.threads == 0) throw UsageError("--threads must be at least 1");
  if (trace.steps.empty()) throw UsageError("the trace has no steps");
  if (o.first_step >= trace.steps.size())
    throw UsageError("--first-step " + std::to_string(o.first_step) + ": the trace has " +
                     std::to_string(trace.steps.size()) + " steps");
  const std::uint32_t last =
      o.steps == 0 ? static_cast<std::uint32_t>(trace.steps.size())
                   : std::min<std::uint32_t>(static_cast<std::uint32_t>(trace.steps.size()),
                                             o.first_step + o.steps);
  const bool partition = o.policy == Policy::kPartition;
  if (partition) {
    if (!assignments) throw UsageError("the partition policy needs an assignment");
    if (assignments->steps.size() < last)
      throw UsageError("the assignment covers " + std::to_string(assignments->steps.size()) +
                       " steps, " + std::to_string(last) + " are replayed");
  }
  if (o.repeat == 0) throw UsageError("--repeat must be at least 1");

  ReplayResult r;
  r.policy = o.policy;
  r.calibration = SyntheticWorkload::calibration();
  CacheMissCounter misses;
  const std::uint64_t misses0 = misses.read();

  auto ex = make_executor(o.policy, o.exec);
  r.threads = ex->threads();  // 1 for the sequential policy, which is its own baseline
  std::unique_ptr<Executor> seq;
  if (o.sequential_baseline && o.policy != Policy::kSequential)
    seq = make_executor(Policy::kSequential, o.exec);
  SyntheticWorkload w(o.synthetic), ws(o.synthetic);
  std::uint64_t working_set = 0;
  for (const Datum& d : trace.steps[o.first_step].data) working_set += d.bytes;
  if (o.synthetic.touch) {
    r.touch_ns_per_byte = ws.calibrate_touch(working_set);
    w.calibrate_touch(working_set);
  }
  r.working_set_bytes = working_set;

  const std::uint32_t n = last - o.first_step;
  r.steps.resize(n);
  std::vector<std::vector<std::int64_t>> walls(n), seq_walls(n), runs(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    const StepGraph& g = trace.steps[o.first_step + i];
    StepMeasure& m = r.steps[i];
    m.step = o.first_step + i;
    const Metrics met = compute_metrics(g);
    m.work_ns = met.work_ns;
    m.span_ns = met.span_ns;
    m.host_ns = g.host_ns;
    r.host_ns += g.host_ns;
    if (predicted && m.step < predicted->size()) m.predicted_makespan_ns = (*predicted)[m.step];
    r.work_ns += m.work_ns;
    r.span_ns += m.span_ns;
  }
  auto assignment_of = [&](std::uint32_t s) -> const Assignment* {
    return partition ? &assignments->steps[s] : nullptr;
  };
  for (std::uint32_t pass = 0; pass < o.repeat; ++pass) {
    if (seq) {
      std::int64_t total = 0;
      for (std::uint32_t i = 0; i < n; ++i) {
        const StepGraph& g = trace.steps[o.first_step + i];
        ws.set_step(g);
        const std::int64_t host = ws.run_host(g);
        const ExecStepStats s = seq->run_step(g, nullptr, ws);
        seq_walls[i].push_back(host + s.wall_ns);
        total += host + s.wall_ns;
      }
      r.sequential_pass_wall_ns.push_back(total);
    }
    std::int64_t total = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
      const StepGraph& g = trace.steps[o.first_step + i];
      w.set_step(g);
      const std::int64_t host = w.run_host(g);
      const ExecStepStats s = ex->run_step(g, assignment_of(o.first_step + i), w);
      walls[i].push_back(host + s.wall_ns);
      runs[i].push_back(host + s.wall_ns - s.build_ns);
      total += host + s.wall_ns;
      if (pass == 0) {
        StepMeasure& m = r.steps[i];
        m.build_ns = s.build_ns;
        m.rebuild_ns = s.rebuild_ns;
        m.rebuilt_procs = s.rebuilt_procs;
        m.signals = s.signals();
        m.waits = s.waits();
        m.blocked_waits = s.blocked_waits();
        m.parks = s.parks();
        m.wait_ns = s.wait_ns();
      }
    }
    r.pass_wall_ns.push_back(total);
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    r.steps[i].wall_ns = median(walls[i]);
    r.steps[i].run_ns = median(runs[i]);
    r.steps[i].sequential_wall_ns = median(seq_walls[i]);
  }
  r.wall_ns = median(r.pass_wall_ns);
  r.sequential_wall_ns = median(r.sequential_pass_wall_ns);
  if (o.policy == Policy::kSequential) {  // its own baseline: speed-up 1 by definition
    r.sequential_wall_ns = r.wall_ns;
    for (StepMeasure& m : r.steps) m.sequential_wall_ns = m.wall_ns;
  }
  r.plans_built = ex->plans_built();
  r.cw = ex->cw();
  r.scope = ex->scope();
  r.order_fallbacks = ex->order_fallbacks();
  if (misses.available()) {
    r.cache_misses = misses.read() - misses0;
  } else {
    r.cache_misses_note = misses.reason();
  }

  if (o.observe) {
    StatsObserver stats;
    LocalityObserver locality;
    ex->add_observer(stats);
    ex->add_observer(locality);
    if (timeline) ex->add_observer(*timeline);
    for (std::uint32_t i = 0; i < n; ++i) {
      const StepGraph& g = trace.steps[o.first_step + i];
      w.set_step(g);
      ex->run_step(g, assignment_of(o.first_step + i), w);
      r.steps[i].threads = stats.threads();
      r.steps[i].remote_bytes = locality.remote_bytes();
      r.steps[i].migrated_bytes = locality.migrated_bytes();
    }
    ex->clear_observers();
  }
  // Amdahl: the host time is serial, in the sequential run and on the critical path alike.
  const double parallelism = r.span_ns == 0 ? 1.0
                                            : static_cast<double>(r.work_ns + r.host_ns) /
                                                  static_cast<double>(r.span_ns + r.host_ns);
  r.bound = std::max(1.0, std::min(static_cast<double>(r.threads), parallelism));
  if (r.wall_ns > 0 && r.sequential_wall_ns > 0)
    r.speedup = static_cast<double>(r.sequential_wall_ns) / static_cast<double>(r.wall_ns);
  r.efficiency = r.speedup / r.bound;
  return r;
}

std::string to_json(const ReplayResult& r) {
  using nlohmann::json;
  json per_step = json::array();
  for (const StepMeasure& m : r.steps) {
    json threads = json::array();
    for (const auto& t : m.threads)
      threads.push_back({{"busy_ns", t.busy_ns},
                         {"wait_ns", t.wait_ns},
                         {"idle_ns", t.idle_ns},
                         {"tasks", t.tasks}});
    json s = {{"step", m.step},
              {"wall_ns", m.wall_ns},
              {"sequential_wall_ns", m.sequential_wall_ns},
              {"build_ns", m.build_ns},
              {"rebuild_ns", m.rebuild_ns},
              {"rebuilt_procs", m.rebuilt_procs},
              {"rebuild_over_wall", m.wall_ns > 0 ? static_cast<double>(m.rebuild_ns) /
                                                        static_cast<double>(m.wall_ns)
                                                  : 0.0},
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
              {"host_ns", m.host_ns},
              {"threads", threads}};
    s["predicted_makespan_ns"] =
        m.predicted_makespan_ns ? json(*m.predicted_makespan_ns) : json(nullptr);
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
              {"working_set_bytes", r.working_set_bytes}}},
            {"per_step", per_step}};
  j["cache_misses"] = r.cache_misses ? json(*r.cache_misses) : json(r.cache_misses_note);
  j["warnings"] = r.warnings;
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

}  // namespace tgraph::replay
