// SPDX-License-Identifier: MIT
// The columnar timeline format (version 2, compact_timeline_json: one array a field, kinds
// interned, starts as differences) and its reader, with the executed graphs and step
// information that both formats carry (timeline_format.hpp).
#include <algorithm>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tgraph/graph/timeline.hpp"
#include "timeline_format.hpp"

namespace tgraph {
namespace timeline_format {
namespace {

// A column of integers; throws json::type_error when it is not one, or out of [lo, hi].
std::vector<std::int64_t> column(const json& obj, const char* key, std::size_t n, std::int64_t lo,
                                 std::int64_t hi) {
  const json& a = obj.at(key);
  if (!a.is_array())
    throw json::type_error::create(302, std::string("\"") + key + "\" must be an array", &a);
  if (a.size() != n)
    throw json::other_error::create(501,
                                    std::string("\"") + key + "\": " + std::to_string(a.size()) +
                                        " entries (expected " + std::to_string(n) + ")",
                                    &a);
  std::vector<std::int64_t> v;
  v.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const json& x = a[i];
    if (!x.is_number_integer())
      throw json::type_error::create(
          302, std::string("\"") + key + "\"[" + std::to_string(i) + "] must be an integer", &x);
    const std::int64_t value = x.get<std::int64_t>();
    if (value < lo || value > hi)
      throw json::other_error::create(501,
                                      std::string("\"") + key + "\"[" + std::to_string(i) +
                                          "]: " + std::to_string(value) + " out of range",
                                      &x);
    v.push_back(value);
  }
  return v;
}

std::size_t column_size(const json& obj, const char* key) {
  const json& a = obj.at(key);
  if (!a.is_array())
    throw json::type_error::create(302, std::string("\"") + key + "\" must be an array", &a);
  return a.size();
}

std::vector<std::string> strings(const json& obj, const char* key) {
  const json& a = obj.at(key);
  if (!a.is_array())
    throw json::type_error::create(302, std::string("\"") + key + "\" must be an array", &a);
  std::vector<std::string> v;
  for (const json& x : a) {
    if (!x.is_string())
      throw json::type_error::create(302, std::string("\"") + key + "\" must hold strings", &x);
    v.push_back(x.get<std::string>());
  }
  return v;
}

constexpr std::int64_t kU32 = 0xffffffffll;
constexpr std::int64_t kMaxNs = std::numeric_limits<std::int64_t>::max() / 4;

json edges_json(const std::vector<Edge>& edges) {
  json from = json::array(), to = json::array(), datum = json::array();
  for (const Edge& e : edges) {
    from.push_back(e.from);
    to.push_back(e.to);
    datum.push_back(e.datum);
  }
  return {{"from", from}, {"to", to}, {"datum", datum}};
}

std::vector<Edge> edges_of(const json& e, std::size_t tasks, std::size_t data) {
  const std::size_t n = column_size(e, "from");
  const auto from = column(e, "from", n, 0, static_cast<std::int64_t>(tasks) - 1);
  const auto to = column(e, "to", n, 0, static_cast<std::int64_t>(tasks) - 1);
  const auto datum = column(e, "datum", n, 0, static_cast<std::int64_t>(data) - 1);
  std::vector<Edge> v(n);
  for (std::size_t i = 0; i < n; ++i)
    v[i] = {static_cast<TaskId>(from[i]), static_cast<TaskId>(to[i]),
            static_cast<DatumId>(datum[i]), EdgeKind::RAW};
  return v;
}

TimelineGraph graph_of(const json& g) {
  TimelineGraph out;
  out.kinds = strings(g, "kinds");
  out.data = strings(g, "data");
  const std::size_t n = column_size(g, "task_kind");
  for (const std::int64_t k :
       column(g, "task_kind", n, 0, static_cast<std::int64_t>(out.kinds.size()) - 1))
    out.task_kind.push_back(static_cast<KindId>(k));
  for (const std::int64_t o : column(g, "origin", n, -1, kU32 - 1))
    out.origin.push_back(o < 0 ? kNoTask : static_cast<TaskId>(o));
  const std::size_t nl = column_size(g, "loop_first");
  const auto first = column(g, "loop_first", nl, 0, static_cast<std::int64_t>(n) - 1);
  const auto last = column(g, "loop_last", nl, 1, static_cast<std::int64_t>(n));
  for (std::size_t l = 0; l < nl; ++l) {
    if (last[l] <= first[l] || (l > 0 && first[l] < last[l - 1]))
      throw json::other_error::create(501, "loops must be disjoint [first, last) ranges in order",
                                      &g);
    out.loops.emplace_back(static_cast<TaskId>(first[l]), static_cast<TaskId>(last[l]));
  }
  out.task_loop.assign(n, kNoLoop);
  for (std::size_t l = 0; l < nl; ++l)
    for (TaskId t = out.loops[l].first; t < out.loops[l].second; ++t)
      out.task_loop[t] = static_cast<LoopId>(l);
  out.edges = edges_of(g.at("edges"), n, out.data.size());
  out.carried_edges = edges_of(g.at("carried_edges"), n, out.data.size());
  if (g.contains("task_object")) {
    out.objects = strings(g, "objects");
    for (const std::int64_t o :
         column(g, "task_object", n, -1, static_cast<std::int64_t>(out.objects.size()) - 1))
      out.task_object.push_back(o < 0 ? kNoObject : static_cast<ObjectId>(o));
  }
  for (const Edge& e : out.edges)
    if (e.from >= e.to)
      throw json::other_error::create(501, "an intra-step edge must go forward in program order",
                                      &g);
  for (const Edge& e : out.carried_edges)
    if (out.task_loop[e.from] == kNoLoop || out.task_loop[e.from] != out.task_loop[e.to])
      throw json::other_error::create(501, "a carried edge must join two tasks of one loop", &g);
  return out;
}

}  // namespace

// The executed graphs and step information (both formats): "graphs" and "step_info".
void read_graphs(const json& j, Timeline& t, std::int64_t events) {
  if (j.contains("graphs")) {
    if (!j["graphs"].is_array()) throw json::type_error::create(302, "\"graphs\" must be an array", &j);
    for (const json& g : j["graphs"]) t.graphs.push_back(graph_of(g));
  }
  if (j.contains("step_info")) {
    if (!j["step_info"].is_array())
      throw json::type_error::create(302, "\"step_info\" must be an array", &j);
    for (const json& e : j["step_info"]) {
      TimelineStep s;
      s.step = get_u32(e, "step");
      if (static_cast<std::int64_t>(s.step) >= std::max<std::int64_t>(events, 1) ||
          (!t.step_info.empty() && s.step <= t.step_info.back().step))
        throw json::other_error::create(501, "step_info: steps must increase, below the events",
                                        &e);
      s.graph = get_u32(e, "graph");
      if (s.graph >= t.graphs.size())
        throw json::other_error::create(501, "step_info: \"graph\" out of range", &e);
      const TimelineGraph& g = t.graphs[s.graph];
      for (const char* key : {"wall_ns", "record_ns", "partition_ns", "prepare_ns", "host_ns"}) {
        const std::int64_t v = get_i64(e, key);
        if (v < 0 || v > kMaxNs) throw json::other_error::create(501, std::string(key) + " out of range", &e);
      }
      s.wall_ns = get_i64(e, "wall_ns");
      s.record_ns = get_i64(e, "record_ns");
      s.partition_ns = get_i64(e, "partition_ns");
      s.prepare_ns = get_i64(e, "prepare_ns");
      s.host_ns = get_i64(e, "host_ns");
      for (const std::int64_t i : column(e, "iterations", g.loops.size(), 0, 1 << 24))
        s.iterations.push_back(static_cast<std::uint32_t>(i));
      s.cost_ns = column(e, "cost_ns", g.task_kind.size(), 0, kMaxNs / 65536);
      t.step_info.push_back(std::move(s));
    }
    // An instance of a step with a graph names one of its tasks.
    for (std::size_t i = 0; i < t.tasks.size(); ++i)
      if (const TimelineStep* s = t.info(t.tasks[i].step);
          s && t.tasks[i].task >= t.graphs[s->graph].task_kind.size())
        throw json::other_error::create(
            501, "tasks[" + std::to_string(i) + "]: task out of range of its step's graph", &j);
  }
}

// The columnar format (compact_timeline_json).
Timeline parse_columns(const json& j) {
  Timeline t;
  t.threads = j.contains("threads") ? get_u32(j, "threads") : 0;
  t.steps = j.contains("steps") ? get_u32(j, "steps") : 0;
  const std::vector<std::string> kinds = strings(j, "kinds");
  const json& tasks = j.at("tasks");
  const json& waits = j.at("waits");
  if (!tasks.is_object() || !waits.is_object())
    throw json::type_error::create(302, "\"tasks\" and \"waits\" must be objects of columns", &j);
  const std::size_t n = column_size(tasks, "step"), nw = column_size(waits, "step");
  const std::int64_t events = static_cast<std::int64_t>(n + nw);
  {
    const auto step = column(tasks, "step", n, 0, events - 1);
    const auto thread = column(tasks, "thread", n, 0, kMaxThreads - 1);
    const auto task = column(tasks, "task", n, 0, kU32);
    const auto origin = column(tasks, "origin", n, -1, kU32);
    const auto kind = column(tasks, "kind", n, 0, static_cast<std::int64_t>(kinds.size()) - 1);
    const auto iteration = column(tasks, "iteration", n, 0, kU32);
    const auto start = column(tasks, "start_ns", n, -kMaxNs, kMaxNs);
    const auto duration = column(tasks, "duration_ns", n, 0, kMaxNs);
    const auto cpu = tasks.contains("cpu_ns") ? column(tasks, "cpu_ns", n, -1, kMaxNs)
                                              : std::vector<std::int64_t>(n, -1);
    t.tasks.resize(n);
    std::int64_t at = 0;
    for (std::size_t i = 0; i < n; ++i) {
      TimelineTask& e = t.tasks[i];
      e.step = static_cast<std::uint32_t>(step[i]);
      at = (i > 0 && step[i] == step[i - 1] ? at : 0) + start[i];
      if (at < 0 || at > kMaxNs)
        throw json::other_error::create(501, "tasks[" + std::to_string(i) + "]: a negative time",
                                        &tasks);
      e.thread = static_cast<std::uint32_t>(thread[i]);
      e.task = static_cast<TaskId>(task[i]);
      if (origin[i] >= 0) e.origin = static_cast<TaskId>(origin[i]);
      e.kind = kinds[static_cast<std::size_t>(kind[i])];
      e.iteration = static_cast<std::uint32_t>(iteration[i]);
      e.start_ns = at;
      e.end_ns = at + duration[i];
      e.cpu_ns = cpu[i];
    }
  }
  {
    const auto step = column(waits, "step", nw, 0, events - 1);
    const auto thread = column(waits, "thread", nw, 0, kMaxThreads - 1);
    const auto task = column(waits, "task", nw, -1, kU32);
    const auto start = column(waits, "start_ns", nw, 0, kMaxNs);
    const auto duration = column(waits, "duration_ns", nw, 0, kMaxNs);
    const auto parked = column(waits, "parked", nw, 0, 1);
    t.waits.resize(nw);
    for (std::size_t i = 0; i < nw; ++i) {
      TimelineWait& w = t.waits[i];
      w.step = static_cast<std::uint32_t>(step[i]);
      w.thread = static_cast<std::uint32_t>(thread[i]);
      if (task[i] >= 0) w.task = static_cast<TaskId>(task[i]);
      w.start_ns = start[i];
      w.end_ns = start[i] + duration[i];
      w.parked = parked[i] != 0;
    }
  }
  read_graphs(j, t, events);
  return t;
}

json graphs_json(const Timeline& t) {
  json graphs = json::array();
  for (const TimelineGraph& g : t.graphs) {
    json first = json::array(), last = json::array(), origins = json::array();
    for (const auto& [f, l] : g.loops) {
      first.push_back(f);
      last.push_back(l);
    }
    for (const TaskId o : g.origin)
      origins.push_back(o == kNoTask ? std::int64_t{-1} : static_cast<std::int64_t>(o));
    graphs.push_back({{"kinds", g.kinds},
                      {"data", g.data},
                      {"task_kind", g.task_kind},
                      {"origin", origins},
                      {"loop_first", first},
                      {"loop_last", last},
                      {"edges", edges_json(g.edges)},
                      {"carried_edges", edges_json(g.carried_edges)}});
    if (g.task_object.empty()) continue;
    json objects = json::array();
    for (const ObjectId o : g.task_object)
      objects.push_back(o == kNoObject ? std::int64_t{-1} : static_cast<std::int64_t>(o));
    graphs.back()["objects"] = g.objects;
    graphs.back()["task_object"] = objects;
  }
  return graphs;
}

json step_info_json(const Timeline& t) {
  json info = json::array();
  for (const TimelineStep& s : t.step_info)
    info.push_back({{"step", s.step},
                    {"graph", s.graph},
                    {"wall_ns", s.wall_ns},
                    {"record_ns", s.record_ns},
                    {"partition_ns", s.partition_ns},
                    {"prepare_ns", s.prepare_ns},
                    {"host_ns", s.host_ns},
                    {"iterations", s.iterations},
                    {"cost_ns", s.cost_ns}});
  return info;
}

}  // namespace timeline_format

std::string compact_timeline_json(const Timeline& t) {
  using namespace timeline_format;
  // Kinds interned; instances in step order (stable), each start the difference from the
  // previous instance of its step.
  std::vector<std::string> kinds;
  std::vector<std::size_t> order(t.tasks.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return t.tasks[a].step < t.tasks[b].step; });
  json step = json::array(), thread = json::array(), task = json::array(), origin = json::array(),
       kind = json::array(), iteration = json::array(), start = json::array(),
       duration = json::array(), cpu = json::array();
  bool any_cpu = false;
  std::int64_t prev = 0;
  std::uint32_t prev_step = 0;
  for (std::size_t n = 0; n < order.size(); ++n) {
    const TimelineTask& e = t.tasks[order[n]];
    std::size_t k = 0;
    while (k < kinds.size() && kinds[k] != e.kind) ++k;
    if (k == kinds.size()) kinds.push_back(e.kind);
    if (n == 0 || e.step != prev_step) prev = 0;
    step.push_back(e.step);
    thread.push_back(e.thread);
    task.push_back(e.task);
    origin.push_back(e.origin ? static_cast<std::int64_t>(*e.origin) : -1);
    kind.push_back(k);
    iteration.push_back(e.iteration);
    start.push_back(e.start_ns - prev);
    duration.push_back(e.end_ns - e.start_ns);
    cpu.push_back(e.cpu_ns);
    any_cpu |= e.cpu_ns >= 0;
    prev = e.start_ns;
    prev_step = e.step;
  }
  json tasks = {{"step", step},           {"thread", thread}, {"task", task},
                {"origin", origin},       {"kind", kind},     {"iteration", iteration},
                {"start_ns", start},      {"duration_ns", duration}};
  if (any_cpu) tasks["cpu_ns"] = cpu;
  json wstep = json::array(), wthread = json::array(), wtask = json::array(),
       wstart = json::array(), wduration = json::array(), parked = json::array();
  for (const TimelineWait& w : t.waits) {
    wstep.push_back(w.step);
    wthread.push_back(w.thread);
    wtask.push_back(w.task ? static_cast<std::int64_t>(*w.task) : -1);
    wstart.push_back(w.start_ns);
    wduration.push_back(w.end_ns - w.start_ns);
    parked.push_back(w.parked ? 1 : 0);
  }
  const json graphs = graphs_json(t), info = step_info_json(t);
  return json{{"format", "tgraph-timeline"},
              {"version", 2},
              {"threads", t.threads},
              {"steps", t.steps},
              {"kinds", kinds},
              {"tasks", tasks},
              {"waits",
               {{"step", wstep},
                {"thread", wthread},
                {"task", wtask},
                {"start_ns", wstart},
                {"duration_ns", wduration},
                {"parked", parked}}},
              {"graphs", graphs},
              {"step_info", info}}
      .dump();
}

}  // namespace tgraph
