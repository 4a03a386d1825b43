// SPDX-License-Identifier: MIT
// Built-in observers: per-thread stats, locality, timeline (a tgraph::Timeline; viz draws it).
#include <time.h>

#include <algorithm>
#include <optional>

#include "tgraph/replay/observer.hpp"

namespace tgraph::replay {

void StatsObserver::on_step_begin(const ExecGraph&, std::uint32_t threads, std::int64_t t_ns) {
  slots_.assign(threads, Slot{});
  step_begin_ = t_ns;
}
void StatsObserver::on_begin(std::uint32_t thread, TaskId, std::uint32_t, std::int64_t t_ns) {
  slots_[thread].begin = t_ns;
}
void StatsObserver::on_end(std::uint32_t thread, TaskId, std::uint32_t, std::int64_t t_ns) {
  Slot& s = slots_[thread];
  s.t.busy_ns += t_ns - s.begin;
  ++s.t.tasks;
}
void StatsObserver::on_wait(std::uint32_t thread, TaskId, std::int64_t t0, std::int64_t t1, bool) {
  slots_[thread].t.wait_ns += t1 - t0;
}
void StatsObserver::on_step_end(std::int64_t t_ns) {
  last_.clear();
  const std::int64_t wall = t_ns - step_begin_;
  for (const Slot& s : slots_) {
    Thread t = s.t;
    t.idle_ns = std::max<std::int64_t>(0, wall - t.busy_ns - t.wait_ns);
    last_.push_back(t);
  }
}

void LocalityObserver::on_step_begin(const ExecGraph& exec, std::uint32_t, std::int64_t) {
  exec_ = &exec;
  where_.resize(exec.graph.tasks.size());
  for (auto& w : where_) w.clear();
}

void LocalityObserver::on_end(std::uint32_t thread, TaskId task, std::uint32_t iteration,
                              std::int64_t) {
  // Instances of one task never overlap, so only this thread touches where_[task] now.
  auto& w = where_[task];
  if (w.size() <= iteration) w.resize(iteration + 1, 0xffff);
  w[iteration] = static_cast<std::uint16_t>(thread);
}

void LocalityObserver::on_step_end(std::int64_t) {
  remote_ = 0;
  migrated_ = 0;
  if (!exec_) return;
  const StepGraph& g = exec_->graph;
  auto thread_of = [&](TaskId t, std::uint32_t it) -> std::uint32_t {
    const auto& w = where_[t];
    return it < w.size() ? w[it] : 0xffffu;
  };
  auto iterations = [&](TaskId t) -> std::uint32_t {
    return static_cast<std::uint32_t>(where_[t].size());
  };
  auto add = [&](const Edge& e, TaskId from, std::uint32_t it_from, TaskId to,
                 std::uint32_t it_to) {
    const std::uint32_t a = thread_of(from, it_from), b = thread_of(to, it_to);
    if (a != 0xffffu && b != 0xffffu && a != b) remote_ += g.data[e.datum].bytes;
  };
  for (const Edge& e : g.edges) {
    if (e.kind != EdgeKind::RAW) continue;
    const LoopId lf = g.tasks[e.from].loop, lt = g.tasks[e.to].loop;
    const std::uint32_t nt = iterations(e.to);
    for (std::uint32_t it = 0; it < nt; ++it) {
      if (lf != kNoLoop && lf == lt) {
        add(e, e.from, it, e.to, it);
      } else if (it == 0) {
        const std::uint32_t nf = iterations(e.from);
        if (nf > 0) add(e, e.from, nf - 1, e.to, 0);
      }
    }
  }
  for (const Edge& e : g.carried_edges) {
    if (e.kind != EdgeKind::RAW) continue;
    const std::uint32_t nt = iterations(e.to);
    for (std::uint32_t it = 1; it < nt; ++it) add(e, e.from, it - 1, e.to, it);
  }
  // Owner of each original datum: thread of its first writer in program order (else of its
  // first reader); temporaries count for their target.
  const std::size_t n_orig =
      exec_->datum_origin.empty()
          ? g.data.size()
          : *std::max_element(exec_->datum_origin.begin(), exec_->datum_origin.end()) + 1;
  std::vector<std::uint32_t> owner(n_orig, 0xffffffffu), reader(n_orig, 0xffffffffu);
  for (TaskId t = 0; t < g.tasks.size(); ++t) {
    if (exec_->origin[t] == kNoTask || where_[t].empty()) continue;
    for (const Access& a : g.accesses_of(t)) {
      const DatumId d = exec_->datum_origin[a.datum];
      if (writes(a.mode)) {
        if (owner[d] == 0xffffffffu) owner[d] = where_[t][0];
      } else if (reader[d] == 0xffffffffu) {
        reader[d] = where_[t][0];
      }
    }
  }
  for (DatumId d = 0; d < n_orig; ++d)
    if (owner[d] == 0xffffffffu) owner[d] = reader[d];
  // Data ids are stable across steps (a recorder only appends data): compare the common ids.
  const std::size_t common = std::min(prev_owner_.size(), n_orig);
  for (DatumId d = 0; d < common; ++d)
    if (owner[d] != 0xffffffffu && prev_owner_[d] != 0xffffffffu && owner[d] != prev_owner_[d])
      migrated_ += g.data[d].bytes;
  prev_owner_ = std::move(owner);
}

namespace {

// A timeline's task: empty for kNoTask (a reducer's origin, a wait on no task).
std::optional<TaskId> known(TaskId t) { return t == kNoTask ? std::nullopt : std::optional(t); }

// The calling thread's CPU time in ns.
std::int64_t thread_cpu_ns() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// The executed graph as a timeline records it.
TimelineGraph timeline_graph(const ExecGraph& exec) {
  const StepGraph& g = exec.graph;
  TimelineGraph out;
  out.kinds = g.kinds;
  out.data.reserve(g.data.size());
  for (const Datum& d : g.data) out.data.push_back(d.name);
  out.task_kind.reserve(g.tasks.size());
  out.task_loop.reserve(g.tasks.size());
  for (const ObjectInfo& o : g.objects) out.objects.push_back(o.name);
  for (const Task& t : g.tasks) {
    out.task_kind.push_back(t.kind);
    out.task_loop.push_back(t.loop);
    out.task_object.push_back(t.object < g.objects.size() ? t.object : kNoObject);
  }
  out.origin = exec.origin;
  for (const Loop& l : g.loops) out.loops.emplace_back(l.first, l.last);
  out.edges = g.edges;
  out.carried_edges = g.carried_edges;
  for (Edge& e : out.edges) e.kind = EdgeKind::RAW;
  for (Edge& e : out.carried_edges) e.kind = EdgeKind::RAW;
  return out;
}

}  // namespace

void TimelineObserver::on_step_begin(const ExecGraph& exec, std::uint32_t threads,
                                     std::int64_t t_ns) {
  exec_ = &exec;
  recording_ = timeline_.steps < max_steps_;
  timeline_.threads = std::max(timeline_.threads, threads);
  per_thread_.resize(threads);
  waits_per_thread_.resize(threads);
  open_.assign(threads * 8, 0);  // one slot per 64 bytes
  step_begin_ = t_ns;
}

void TimelineObserver::on_begin(std::uint32_t thread, TaskId, std::uint32_t, std::int64_t t_ns) {
  open_[thread * 8] = t_ns;
  if (cpu_time_ && recording_) open_[thread * 8 + 1] = thread_cpu_ns();
}

void TimelineObserver::on_end(std::uint32_t thread, TaskId task, std::uint32_t iteration,
                              std::int64_t t_ns) {
  if (!recording_) return;
  const std::int64_t cpu = cpu_time_ ? thread_cpu_ns() - open_[thread * 8 + 1] : -1;
  const std::int64_t start = open_[thread * 8] - step_begin_, end = t_ns - step_begin_;
  // The CPU clock's reads sit just inside the body's wall span: never more than it.
  per_thread_[thread].push_back({task, iteration, start, end, cpu < 0 ? -1 : std::min(cpu, end - start)});
}

void TimelineObserver::on_wait(std::uint32_t thread, TaskId task, std::int64_t t0, std::int64_t t1,
                               bool parked) {
  if (!recording_) return;
  waits_per_thread_[thread].push_back(
      {timeline_.steps, thread, known(task), t0 - step_begin_, t1 - step_begin_, parked});
}

void TimelineObserver::on_step_end(std::int64_t t_ns) {
  if (recording_) {
    const std::uint32_t step = timeline_.steps;
    const std::size_t first = timeline_.tasks.size();
    for (std::uint32_t th = 0; th < per_thread_.size(); ++th) {
      for (const Instance& i : per_thread_[th]) {
        timeline_.tasks.push_back({step, th, i.task, known(exec_->origin[i.task]),
                                   exec_->graph.kind_name(i.task), i.iteration, i.start_ns,
                                   i.end_ns, i.cpu_ns});
      }
      per_thread_[th].clear();
    }
    std::stable_sort(timeline_.tasks.begin() + static_cast<std::ptrdiff_t>(first),
                     timeline_.tasks.end(), [](const TimelineTask& a, const TimelineTask& b) {
                       return a.start_ns < b.start_ns;
                     });
    for (auto& v : waits_per_thread_) {
      timeline_.waits.insert(timeline_.waits.end(), v.begin(), v.end());
      v.clear();
    }
    // The executed graph, shared with the last step of the same one (the newest first).
    TimelineGraph graph = timeline_graph(*exec_);
    std::uint32_t index = static_cast<std::uint32_t>(timeline_.graphs.size());
    for (std::uint32_t i = index; i-- > 0;)
      if (timeline_.graphs[i] == graph) {
        index = i;
        break;
      }
    if (index == timeline_.graphs.size()) timeline_.graphs.push_back(std::move(graph));
    TimelineStep info;
    info.step = step;
    info.graph = index;
    info.wall_ns = t_ns - step_begin_;
    const StepGraph& g = exec_->graph;
    for (const Loop& l : g.loops) info.iterations.push_back(l.iterations);
    info.cost_ns.reserve(g.tasks.size());
    for (TaskId t = 0; t < g.tasks.size(); ++t)
      info.cost_ns.push_back(exec_->origin[t] == kNoTask
                                 ? 0
                                 : static_cast<std::int64_t>(g.tasks[t].cost_ns));
    timeline_.step_info.push_back(std::move(info));
  }
  ++timeline_.steps;
}

void TimelineObserver::set_serial(std::int64_t record_ns, std::int64_t partition_ns,
                                  std::int64_t prepare_ns, std::int64_t host_ns) {
  if (timeline_.step_info.empty() || timeline_.step_info.back().step + 1 != timeline_.steps)
    return;
  TimelineStep& s = timeline_.step_info.back();
  s.record_ns = record_ns;
  s.partition_ns = partition_ns;
  s.prepare_ns = prepare_ns;
  s.host_ns = host_ns;
}

void TimelineObserver::set_sequential_costs(const std::vector<std::int64_t>& cost_by_origin) {
  if (timeline_.step_info.empty() || timeline_.step_info.back().step + 1 != timeline_.steps)
    return;
  TimelineStep& s = timeline_.step_info.back();
  const TimelineGraph& g = timeline_.graphs[s.graph];
  for (TaskId t = 0; t < g.origin.size(); ++t)
    if (g.origin[t] != kNoTask && g.origin[t] < cost_by_origin.size())
      s.cost_ns[t] = cost_by_origin[g.origin[t]];
}

}  // namespace tgraph::replay
