// SPDX-License-Identifier: MIT
// Hand-made and random step graphs for the partition tests.
#pragma once

#include <initializer_list>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "tgraph/graph/step_graph.hpp"

namespace tgraph::partition::testing {

using M = AccessMode;

/// prefix + decimal i (built by appending: GCC 12 warns falsely on "lit" + std::string&&).
inline std::string name(std::string_view prefix, std::int64_t i) {
  std::string s(prefix);
  s += std::to_string(i);
  return s;
}

/// Builds a step graph task by task.
///
///   Builder b;
///   DatumId x = b.datum("x", 8);
///   b.task({{x, M::W}}, 5);
///   StepGraph g = b.done();
struct Builder {
  StepGraph g;
  Builder() { g.kinds = {"op"}; }
  ObjectId object(const std::string& name) {
    g.objects.push_back({name});
    return static_cast<ObjectId>(g.objects.size() - 1);
  }
  DatumId datum(const std::string& name, std::uint64_t bytes, ObjectId owner = kNoObject) {
    g.data.push_back({name, owner, bytes});
    return static_cast<DatumId>(g.data.size() - 1);
  }
  TaskId task(std::initializer_list<Access> acc, std::uint64_t cost, ObjectId obj = kNoObject) {
    std::vector<Access> v(acc);
    const auto t = static_cast<TaskId>(g.tasks.size());
    return g.add_task(0, obj, v, cost, 1000 + t);
  }
  TaskId task(const std::vector<Access>& v, std::uint64_t cost, ObjectId obj = kNoObject) {
    const auto t = static_cast<TaskId>(g.tasks.size());
    return g.add_task(0, obj, v, cost, 1000 + t);
  }
  /// Marks [first, last) as a loop body run `iterations` times; the last task is the break.
  void loop(DatumId condition, TaskId first, TaskId last, std::uint32_t iterations) {
    const auto l = static_cast<LoopId>(g.loops.size());
    for (TaskId t = first; t < last; ++t) g.tasks[t].loop = l;
    g.loops.push_back({condition, first, last, iterations, 100});
  }
  StepGraph done() {
    g.derive_edges();
    return g;
  }
};

/// Two disconnected halves of `per_half` chained tasks each, on disjoint data, one object
/// per half.
inline StepGraph two_halves(int per_half, std::uint64_t cost = 10) {
  Builder b;
  for (int h = 0; h < 2; ++h) {
    const ObjectId o = b.object(name("half", h));
    std::vector<DatumId> d;
    for (int i = 0; i < per_half; ++i) d.push_back(b.datum(name("h", h) + name("d", i), 64, o));
    for (int i = 0; i < per_half; ++i) {
      if (i == 0)
        b.task({{d[0], M::W}}, cost, o);
      else
        b.task({{d[static_cast<std::size_t>(i - 1)], M::R}, {d[static_cast<std::size_t>(i)], M::W}}, cost, o);
    }
  }
  return b.done();
}

/// A random valid step graph: random accesses (R, W, RW, CW) over a few data, optionally a
/// loop whose last task (the break) reads the condition datum written in the body.
inline StepGraph random_graph(std::uint64_t seed, int tasks, int data, bool with_loop) {
  std::mt19937_64 rng(seed);
  Builder b;
  std::vector<DatumId> d;
  for (int i = 0; i < data; ++i) d.push_back(b.datum(name("d", i), 8 + rng() % 4096));
  const DatumId cond = b.datum("cond", 1);
  std::uniform_int_distribution<int> pick(0, data - 1), nacc(1, 3), mode(0, 3);
  std::uniform_int_distribution<std::uint64_t> cost(0, 1000);
  int loop_first = -1, loop_last = -1;
  if (with_loop && tasks >= 4) {
    loop_first = static_cast<int>(rng() % static_cast<std::uint64_t>(tasks / 2));
    loop_last = loop_first + 2 + static_cast<int>(rng() % static_cast<std::uint64_t>(tasks - loop_first - 2));
  }
  for (int t = 0; t < tasks; ++t) {
    std::vector<Access> acc;
    const int na = nacc(rng);
    for (int i = 0; i < na; ++i) {
      const DatumId x = d[static_cast<std::size_t>(pick(rng))];
      bool dup = false;
      for (const Access& a : acc) dup = dup || a.datum == x;
      if (dup) continue;
      acc.push_back({x, static_cast<AccessMode>(mode(rng))});
    }
    if (t == loop_last - 2) acc.push_back({cond, M::W});
    if (t == loop_last - 1) acc.push_back({cond, M::R});
    b.task(acc, cost(rng));
  }
  if (loop_first >= 0)
    b.loop(cond, static_cast<TaskId>(loop_first), static_cast<TaskId>(loop_last),
           1 + static_cast<std::uint32_t>(rng() % 4));
  return b.done();
}

}  // namespace tgraph::partition::testing
