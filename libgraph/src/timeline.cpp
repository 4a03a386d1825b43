// SPDX-License-Identifier: MIT
// The timeline model: step offsets, the format of one object per event (timeline_json) and
// its reader, gzip, and parse_timeline, which reads both formats (the columnar one:
// timeline_columns.cpp).
#include "tgraph/graph/timeline.hpp"

#include <zlib.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <tuple>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "timeline_format.hpp"

namespace tgraph {
namespace timeline_format {

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

}  // namespace timeline_format

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

using namespace timeline_format;

namespace {

std::optional<TaskId> get_optional_u32(const json& e, const char* key) {
  if (!e.contains(key) || e.at(key).is_null()) return std::nullopt;
  return get_u32(e, key);
}

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
