// SPDX-License-Identifier: MIT
// The timeline model: step offsets, its JSON writer and its reader.
#include "tgraph/graph/timeline.hpp"

#include <zlib.h>

#include <algorithm>
#include <limits>
#include <nlohmann/json.hpp>
#include <tuple>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"

namespace tgraph {
namespace {

using nlohmann::json;

// Threads a timeline may have (rows of the picture).
constexpr std::uint32_t kMaxThreads = 4096;

std::uint32_t get_u32(const json& e, const char* key) {
  const json& v = e.at(key);
  if (!v.is_number_unsigned() || v.get<std::uint64_t>() > 0xffffffffu)
    throw json::type_error::create(
        302, std::string("\"") + key + "\" must be an unsigned 32-bit integer", &v);
  return v.get<std::uint32_t>();
}

std::int64_t get_i64(const json& e, const char* key) {
  const json& v = e.at(key);
  if (!v.is_number_integer())
    throw json::type_error::create(302, std::string("\"") + key + "\" must be an integer", &v);
  return v.get<std::int64_t>();
}

std::optional<TaskId> get_optional_u32(const json& e, const char* key) {
  if (!e.contains(key) || e.at(key).is_null()) return std::nullopt;
  return get_u32(e, key);
}


}  // namespace

std::vector<std::int64_t> Timeline::step_offsets() const {
  std::uint32_t last = 0;
  for (const TimelineTask& e : tasks) last = std::max(last, e.step);
  for (const TimelineWait& w : waits) last = std::max(last, w.step);
  std::vector<std::int64_t> end(last + 1, 0);
  for (const TimelineTask& e : tasks) end[e.step] = std::max(end[e.step], e.end_ns);
  for (const TimelineWait& w : waits) end[w.step] = std::max(end[w.step], w.end_ns);
  std::vector<std::int64_t> offsets(last + 1, 0);
  for (std::size_t s = 1; s <= last; ++s) offsets[s] = offsets[s - 1] + end[s - 1];
  return offsets;
}

namespace {

void read_graphs(const json& j, Timeline& t, std::int64_t events);

// One object per event (timeline_json).
Timeline parse_objects(const json& j, const std::string& name) {
  Timeline t;
  std::size_t index = 0;
  const char* what = "tasks";
  // Ceilings before anything is sized by a value read: every step of a replay has task
  // events, so step numbers stay below the number of events (step_offsets() allocates by
  // step number); threads below kMaxThreads.
  const std::size_t events = j["tasks"].size() + (j.contains("waits") ? j["waits"].size() : 0);
  const auto step_of = [&](const json& e) {
    const std::uint32_t s = get_u32(e, "step");
    if (s >= events)
      throw json::other_error::create(501,
                                      "\"step\": " + std::to_string(s) + " (expected < " +
                                          std::to_string(events) + ", the number of events)",
                                      &e);
    return s;
  };
  const auto thread_of = [&](const json& e) {
    const std::uint32_t th = get_u32(e, "thread");
    if (th >= kMaxThreads)
      throw json::other_error::create(
          501,
          "\"thread\": " + std::to_string(th) + " (expected < " + std::to_string(kMaxThreads) + ")",
          &e);
    return th;
  };
  // An event's start_ns and end_ns: not negative, the end not before the start.
  const auto span_of = [](const json& e) {
    const std::int64_t start = get_i64(e, "start_ns"), end = get_i64(e, "end_ns");
    if (end < start || start < 0)
      throw json::other_error::create(501, "end_ns before start_ns, or a negative time", &e);
    return std::pair{start, end};
  };
  try {
    t.threads = j.contains("threads") ? get_u32(j, "threads") : 0;
    t.steps = j.contains("steps") ? get_u32(j, "steps") : 0;
    for (const json& e : j["tasks"]) {
      TimelineTask ev;
      ev.step = step_of(e);
      ev.thread = thread_of(e);
      ev.task = get_u32(e, "task");
      ev.origin = get_optional_u32(e, "origin");
      ev.kind = e.contains("kind") && e["kind"].is_string() ? e["kind"].get<std::string>() : "task";
      ev.iteration = e.contains("iteration") ? get_u32(e, "iteration") : 0;
      std::tie(ev.start_ns, ev.end_ns) = span_of(e);
      if (e.contains("cpu_ns")) {
        ev.cpu_ns = get_i64(e, "cpu_ns");
        if (ev.cpu_ns < -1 || ev.cpu_ns > ev.end_ns - ev.start_ns)
          throw json::other_error::create(501, "cpu_ns out of range", &e);
      }
      t.tasks.push_back(std::move(ev));
      ++index;
    }
    what = "waits";
    index = 0;
    if (j.contains("waits")) {
      if (!j["waits"].is_array())
        throw json::type_error::create(302, "\"waits\" must be an array", &j);
      for (const json& e : j["waits"]) {
        TimelineWait w;
        w.step = step_of(e);
        w.thread = thread_of(e);
        w.task = get_optional_u32(e, "task");
        std::tie(w.start_ns, w.end_ns) = span_of(e);
        w.parked = e.value("parked", false);
        t.waits.push_back(w);
        ++index;
      }
    }
    what = "graphs";
    index = 0;
    read_graphs(j, t, static_cast<std::int64_t>(events));
  } catch (const json::exception& e) {
    std::string why = e.what();
    if (const auto p = why.find("] "); p != std::string::npos) why = why.substr(p + 2);
    throw InputError(name, std::nullopt,
                     std::string(what) + (what[0] == 'g' ? "" : "[" + std::to_string(index) + "]") +
                         ": " + why);
  }
  return t;
}

// Checks shared by both formats: threads, steps, and times that add up within 64 bits.
void check_totals(Timeline& t, const std::string& name) {
  const std::size_t events = t.tasks.size() + t.waits.size();
  std::uint32_t seen = 0;
  for (const TimelineTask& e : t.tasks) {
    seen = std::max(seen, e.thread + 1);
    t.steps = std::max(t.steps, e.step + 1);
  }
  for (const TimelineWait& w : t.waits) {
    seen = std::max(seen, w.thread + 1);
    t.steps = std::max(t.steps, w.step + 1);
  }
  if (t.threads == 0) t.threads = seen;
  if (seen > t.threads)
    throw InputError(name, std::nullopt,
                     "thread " + std::to_string(seen - 1) +
                         " out of range (\"threads\": " + std::to_string(t.threads) + ")");
  if (t.threads > kMaxThreads)
    throw InputError(name, std::nullopt,
                     "\"threads\": " + std::to_string(t.threads) + " (expected at most " +
                         std::to_string(kMaxThreads) + ")");
  // The pictures add step offsets to times and sum durations in 64-bit integers: the steps
  // laid end to end, and the tasks' total time, must fit (292 years of nanoseconds).
  std::vector<std::int64_t> end(events, 0);
  for (const TimelineTask& e : t.tasks) end[e.step] = std::max(end[e.step], e.end_ns);
  for (const TimelineWait& w : t.waits) end[w.step] = std::max(end[w.step], w.end_ns);
  std::int64_t sum = 0, busy = 0;
  bool overflow = false;
  for (const std::int64_t ns : end) overflow |= __builtin_add_overflow(sum, ns, &sum);
  for (const TimelineTask& e : t.tasks)
    overflow |= __builtin_add_overflow(busy, e.end_ns - e.start_ns, &busy);
  if (overflow)
    throw InputError(name, std::nullopt,
                     "the steps laid end to end or the tasks' total time exceed 2^63-1 ns "
                     "(expected a replay timeline's nanoseconds)");
}

// ---- columns (version 2) ------------------------------------------------------------

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

// gzip (RFC 1952) through zlib.
bool is_gzip(std::string_view bytes) {
  return bytes.size() >= 2 && static_cast<unsigned char>(bytes[0]) == 0x1f &&
         static_cast<unsigned char>(bytes[1]) == 0x8b;
}

std::string gunzip(std::string_view bytes, const std::string& name) {
  // Ceiling of the inflated text: a timeline of 1 GiB is beyond what anything writes.
  constexpr std::size_t kMaxText = std::size_t{1} << 30;
  z_stream z{};
  if (inflateInit2(&z, 15 + 16) != Z_OK) throw std::runtime_error(name + ": zlib failed to start");
  std::string out;
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
  z.avail_in = static_cast<uInt>(std::min<std::size_t>(bytes.size(), 0xffffffffu));
  int rc = Z_OK;
  char buffer[1 << 16];
  while (rc != Z_STREAM_END) {
    z.next_out = reinterpret_cast<Bytef*>(buffer);
    z.avail_out = sizeof buffer;
    rc = inflate(&z, Z_NO_FLUSH);
    if (rc != Z_OK && rc != Z_STREAM_END) {
      inflateEnd(&z);
      throw InputError(name, std::nullopt, "not a valid gzip stream (truncated or corrupt)");
    }
    out.append(buffer, sizeof buffer - z.avail_out);
    if (out.size() > kMaxText) {
      inflateEnd(&z);
      throw InputError(name, std::nullopt, "more than 1 GiB once inflated");
    }
    if (rc == Z_OK && z.avail_in == 0 && z.avail_out != 0) {
      inflateEnd(&z);
      throw InputError(name, std::nullopt, "not a valid gzip stream (truncated)");
    }
  }
  inflateEnd(&z);
  return out;
}

std::string gzip(std::string_view text) {
  z_stream z{};
  if (deflateInit2(&z, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK)
    throw std::runtime_error("zlib failed to start");
  std::string out(deflateBound(&z, static_cast<uLong>(text.size())), '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(text.data()));
  z.avail_in = static_cast<uInt>(text.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  const int rc = deflate(&z, Z_FINISH);
  out.resize(z.total_out);
  deflateEnd(&z);
  if (rc != Z_STREAM_END) throw std::runtime_error("zlib failed to compress a timeline");
  return out;
}

}  // namespace

const TimelineStep* Timeline::info(std::uint32_t step) const {
  const auto it = std::lower_bound(step_info.begin(), step_info.end(), step,
                                   [](const TimelineStep& s, std::uint32_t v) { return s.step < v; });
  return it != step_info.end() && it->step == step ? &*it : nullptr;
}

// The executed graphs and step information as the two formats write them.
json graphs_json(const Timeline& t);
json step_info_json(const Timeline& t);

std::string timeline_json(const Timeline& t) {
  json tasks = json::array(), waits = json::array();
  const auto optional_json = [](const std::optional<TaskId>& v) { return v ? json(*v) : json(nullptr); };
  for (const TimelineTask& e : t.tasks) {
    json o = {{"step", e.step},         {"thread", e.thread},   {"task", e.task},
              {"origin", optional_json(e.origin)}, {"kind", e.kind},
              {"iteration", e.iteration}, {"start_ns", e.start_ns}, {"end_ns", e.end_ns}};
    if (e.cpu_ns >= 0) o["cpu_ns"] = e.cpu_ns;
    tasks.push_back(std::move(o));
  }
  for (const TimelineWait& w : t.waits)
    waits.push_back({{"step", w.step},
                     {"thread", w.thread},
                     {"task", optional_json(w.task)},
                     {"start_ns", w.start_ns},
                     {"end_ns", w.end_ns},
                     {"parked", w.parked}});
  json j = {{"threads", t.threads}, {"steps", t.steps}, {"tasks", tasks}, {"waits", waits}};
  if (!t.graphs.empty()) {
    j["graphs"] = graphs_json(t);
    j["step_info"] = step_info_json(t);
  }
  return j.dump();
}

std::string compact_timeline_json(const Timeline& t) {
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

Timeline parse_timeline(std::string_view text, const std::string& name) {
  std::string inflated;
  if (is_gzip(text)) {
    inflated = gunzip(text, name);
    text = inflated;
  }
  const json j = json::parse(text, nullptr, false);
  if (j.is_discarded())
    throw InputError(name, std::nullopt,
                     "not JSON (expected a replay timeline, as timeline_json writes it)");
  if (!j.is_object() || !j.contains("tasks") || !(j["tasks"].is_array() || j["tasks"].is_object()))
    throw InputError(name, std::nullopt,
                     "not a replay timeline (expected a JSON object with a \"tasks\" array "
                     "or columns)");
  Timeline t;
  if (j["tasks"].is_array()) {
    t = parse_objects(j, name);
  } else {
    try {
      t = parse_columns(j);
    } catch (const json::exception& e) {
      std::string why = e.what();
      if (const auto p = why.find("] "); p != std::string::npos) why = why.substr(p + 2);
      throw InputError(name, std::nullopt, why);
    }
  }
  check_totals(t, name);
  return t;
}

Timeline read_timeline(const std::string& path) {
  return parse_timeline(read_file_text(path), path);
}

void write_timeline(const std::string& path, const Timeline& t) {
  write_file_atomic(path, gzip(compact_timeline_json(t)));
}

}  // namespace tgraph
