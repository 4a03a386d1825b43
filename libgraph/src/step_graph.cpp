// SPDX-License-Identifier: MIT
// StepGraph basics: access modes, task insertion, validation, structural hash.
#include "tgraph/graph/step_graph.hpp"

#include <algorithm>
#include <string>

namespace tgraph {

std::string_view to_string(AccessMode mode) {
  switch (mode) {
    case AccessMode::R: return "R";
    case AccessMode::W: return "W";
    case AccessMode::RW: return "RW";
    case AccessMode::CW: return "CW";
  }
  return "?";
}

bool writes(AccessMode mode) { return mode != AccessMode::R; }
bool reads(AccessMode mode) { return mode == AccessMode::R || mode == AccessMode::RW; }

std::string_view to_string(EdgeKind kind) {
  switch (kind) {
    case EdgeKind::RAW: return "RAW";
    case EdgeKind::WAR: return "WAR";
    case EdgeKind::WAW: return "WAW";
  }
  return "?";
}

TaskId StepGraph::add_task(KindId kind, ObjectId object, std::span<const Access> acc,
                           std::uint64_t cost_ns, StableKey key) {
  Task t;
  t.kind = kind;
  t.object = object;
  t.access_begin = static_cast<std::uint32_t>(accesses.size());
  t.access_count = static_cast<std::uint32_t>(acc.size());
  t.cost_ns = cost_ns;
  t.key = key;
  accesses.insert(accesses.end(), acc.begin(), acc.end());
  tasks.push_back(t);
  return static_cast<TaskId>(tasks.size() - 1);
}

KindId StepGraph::intern_kind(std::string_view name) {
  for (std::size_t i = 0; i < kinds.size(); ++i)
    if (kinds[i] == name) return static_cast<KindId>(i);
  kinds.emplace_back(name);
  return static_cast<KindId>(kinds.size() - 1);
}

std::string StepGraph::validate() const {
  const auto n_tasks = tasks.size();
  std::uint64_t expected_begin = 0;
  for (std::size_t t = 0; t < n_tasks; ++t) {
    const Task& task = tasks[t];
    auto where = [t] { return "task " + std::to_string(t); };
    if (task.kind >= kinds.size()) return where() + ": kind " + std::to_string(task.kind) + " out of range";
    if (task.object != kNoObject && task.object >= objects.size())
      return where() + ": object " + std::to_string(task.object) + " out of range";
    if (task.access_begin != expected_begin) return where() + ": accesses not contiguous";
    expected_begin += task.access_count;
    if (expected_begin > accesses.size()) return where() + ": accesses out of range";
    if (task.loop != kNoLoop && task.loop >= loops.size())
      return where() + ": loop " + std::to_string(task.loop) + " out of range";
  }
  if (expected_begin != accesses.size()) return "accesses not all owned by tasks";
  for (std::size_t i = 0; i < accesses.size(); ++i) {
    if (accesses[i].datum >= data.size())
      return "access " + std::to_string(i) + ": datum " + std::to_string(accesses[i].datum) + " out of range";
    if (static_cast<unsigned>(accesses[i].mode) > static_cast<unsigned>(AccessMode::CW))
      return "access " + std::to_string(i) + ": bad mode";
  }
  for (const Datum& d : data)
    if (d.object != kNoObject && d.object >= objects.size()) return "datum " + d.name + ": object out of range";
  TaskId prev_last = 0;
  for (std::size_t l = 0; l < loops.size(); ++l) {
    const Loop& loop = loops[l];
    const std::string where = "loop " + std::to_string(l);
    if (loop.first >= loop.last || loop.last > n_tasks) return where + ": empty or out-of-range body";
    if (loop.first < prev_last) return where + ": overlaps or precedes the previous loop";
    prev_last = loop.last;
    if (loop.condition >= data.size()) return where + ": condition datum out of range";
    if (loop.iterations == 0) return where + ": zero iterations";
    if (loop.max_iterations != 0 && loop.iterations > loop.max_iterations)
      return where + ": more iterations than its maximum";
    for (TaskId t = loop.first; t < loop.last; ++t)
      if (tasks[t].loop != l) return where + ": task " + std::to_string(t) + " in body not marked";
    bool reads_condition = false;
    for (const Access& a : accesses_of(loop.last - 1))
      if (a.datum == loop.condition && reads(a.mode)) reads_condition = true;
    if (!reads_condition) return where + ": last body task does not read the condition";
  }
  for (std::size_t t = 0; t < n_tasks; ++t) {
    const LoopId l = tasks[t].loop;
    if (l != kNoLoop && (t < loops[l].first || t >= loops[l].last))
      return "task " + std::to_string(t) + ": marked in loop " + std::to_string(l) + " but outside its body";
  }
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    const Contact& c = contacts[i];
    if (c.a >= objects.size() || c.b >= objects.size()) return "contact object out of range";
    if (c.a >= c.b) return "contact " + std::to_string(i) + ": expected a < b";
    if (i > 0 && !(contacts[i - 1] < c)) return "contacts not sorted and unique";
  }
  if (groups.size() > objects.size()) return "more collision groups than objects";
  return {};
}

namespace {

struct Hasher {
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a 64
  void bytes(const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
  }
  template <class T>
  void value(const T& v) { bytes(&v, sizeof v); }
  /// The fields of one record, in order.
  template <class... T>
  void values(const T&... v) { (value(v), ...); }
  void str(const std::string& s) {
    value(s.size());
    bytes(s.data(), s.size());
  }
};

}  // namespace

std::uint64_t StepGraph::structural_hash() const {
  Hasher h;
  h.value(kinds.size());
  for (const auto& k : kinds) h.str(k);
  h.value(objects.size());
  for (const auto& o : objects) h.str(o.name);
  h.value(data.size());
  for (const auto& d : data) {
    h.str(d.name);
    h.values(d.object, d.bytes);
  }
  h.value(tasks.size());
  for (const auto& t : tasks) h.values(t.kind, t.object, t.access_count, t.loop, t.key);
  for (const auto& a : accesses) h.values(a.datum, static_cast<std::uint8_t>(a.mode));
  h.value(loops.size());
  for (const auto& l : loops) h.values(l.condition, l.first, l.last, l.max_iterations);
  return h.h;
}

namespace {

// Equal names, the lists' lengths already equal.
template <class T, class Name>
bool same_names(const std::vector<T>& a, const std::vector<T>& b, Name name) {
  for (std::size_t i = 0; i < a.size(); ++i)
    if (name(a[i]) != name(b[i])) return false;
  return true;
}

}  // namespace

// Called on every step by the executors' plan cache, where it mostly says "equal": the
// numbers are compared first, each list in one pass without early exit (the differences
// OR-ed together, which the compiler can vectorise), the names (a string comparison each)
// last.
bool StepGraph::same_structure(const StepGraph& o) const {
  if (tasks.size() != o.tasks.size() || accesses.size() != o.accesses.size() ||
      data.size() != o.data.size() || objects.size() != o.objects.size() ||
      kinds.size() != o.kinds.size() || loops.size() != o.loops.size())
    return false;
  std::uint64_t diff = 0;
  for (std::size_t i = 0; i < accesses.size(); ++i)
    diff |= (accesses[i].datum ^ o.accesses[i].datum) |
            static_cast<std::uint32_t>(static_cast<std::uint8_t>(accesses[i].mode) ^
                                       static_cast<std::uint8_t>(o.accesses[i].mode));
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    const Task& a = tasks[i];
    const Task& b = o.tasks[i];
    diff |= (a.kind ^ b.kind) | (a.object ^ b.object) | (a.access_begin ^ b.access_begin) |
            (a.access_count ^ b.access_count) | (a.loop ^ b.loop) | (a.key ^ b.key);
  }
  for (std::size_t i = 0; i < data.size(); ++i)
    diff |= (data[i].object ^ o.data[i].object) | (data[i].bytes ^ o.data[i].bytes) |
            (data[i].name.size() ^ o.data[i].name.size());
  for (std::size_t i = 0; i < loops.size(); ++i) {
    const Loop& a = loops[i];
    const Loop& b = o.loops[i];
    diff |= (a.condition ^ b.condition) | (a.first ^ b.first) | (a.last ^ b.last) |
            (a.max_iterations ^ b.max_iterations);
  }
  if (diff != 0) return false;
  const auto name = [](const auto& x) -> const std::string& { return x.name; };
  return kinds == o.kinds && same_names(objects, o.objects, name) &&
         same_names(data, o.data, name);
}

}  // namespace tgraph
