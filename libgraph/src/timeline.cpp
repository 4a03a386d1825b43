// SPDX-License-Identifier: MIT
// The timeline model: step offsets, its JSON writer and its reader.
#include "tgraph/graph/timeline.hpp"

#include <algorithm>
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

json optional_json(const std::optional<TaskId>& v) { return v ? json(*v) : json(nullptr); }

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

Timeline read_timeline(const std::string& path) {
  return parse_timeline(read_file_text(path), path);
}

std::string timeline_json(const Timeline& t) {
  json tasks = json::array(), waits = json::array();
  for (const TimelineTask& e : t.tasks)
    tasks.push_back({{"step", e.step},
                     {"thread", e.thread},
                     {"task", e.task},
                     {"origin", optional_json(e.origin)},
                     {"kind", e.kind},
                     {"iteration", e.iteration},
                     {"start_ns", e.start_ns},
                     {"end_ns", e.end_ns}});
  for (const TimelineWait& w : t.waits)
    waits.push_back({{"step", w.step},
                     {"thread", w.thread},
                     {"task", optional_json(w.task)},
                     {"start_ns", w.start_ns},
                     {"end_ns", w.end_ns},
                     {"parked", w.parked}});
  return json{{"threads", t.threads}, {"steps", t.steps}, {"tasks", tasks}, {"waits", waits}}
      .dump();
}

Timeline parse_timeline(std::string_view text, const std::string& name) {
  const json j = json::parse(text, nullptr, false);
  if (j.is_discarded())
    throw InputError(name, std::nullopt,
                     "not JSON (expected a replay timeline, as timeline_json writes it)");
  if (!j.is_object() || !j.contains("tasks") || !j["tasks"].is_array())
    throw InputError(name, std::nullopt,
                     "not a replay timeline (expected a JSON object with a \"tasks\" array)");
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
  } catch (const json::exception& e) {
    std::string why = e.what();
    if (const auto p = why.find("] "); p != std::string::npos) why = why.substr(p + 2);
    throw InputError(name, std::nullopt,
                     std::string(what) + "[" + std::to_string(index) + "]: " + why);
  }
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
  return t;
}

}  // namespace tgraph
