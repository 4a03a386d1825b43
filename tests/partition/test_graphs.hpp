// SPDX-License-Identifier: MIT
// Hand-made and random step graphs for the partition tests.
#pragma once

#include <initializer_list>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/step_graph.hpp"

namespace tgraph::partition::testing {

using M = AccessMode;

/// K processors, processor per task, program order.
inline Assignment assign(std::uint32_t k, std::vector<ProcId> proc) {
  Assignment a;
  a.k = k;
  a.proc = std::move(proc);
  return a;
}

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

/// A scene of objects each with a few tasks (keys 10 i + 1, 10 i + 2); each contact (a, c)
/// adds an interaction task (key 100000 + 1000 a + c); `heavy_on_zero` heavy tasks on object
/// 0's data only.
inline StepGraph objects_scene(int objects, const std::vector<std::pair<int, int>>& contacts,
                        int heavy_on_zero = 0) {
  Builder b;
  std::vector<DatumId> x, f;
  for (int i = 0; i < objects; ++i) {
    const ObjectId o = b.object(testing::name("obj", i));
    x.push_back(b.datum(testing::name("x", i), 1024, o));
    f.push_back(b.datum(testing::name("f", i), 1024, o));
  }
  for (int i = 0; i < objects; ++i) {
    const auto u = static_cast<std::size_t>(i);
    b.g.add_task(0, static_cast<ObjectId>(i), std::vector<Access>{{f[u], M::W}, {x[u], M::R}}, 100,
                 static_cast<StableKey>(10 * i + 1));
  }
  for (const auto& [a, c] : contacts) {
    const auto ua = static_cast<std::size_t>(a), uc = static_cast<std::size_t>(c);
    b.g.add_task(0, kNoObject,
                 std::vector<Access>{{f[ua], M::CW}, {f[uc], M::CW}, {x[ua], M::R}, {x[uc], M::R}}, 20,
                 static_cast<StableKey>(100000 + 1000 * a + c));
    b.g.contacts.push_back({static_cast<ObjectId>(a), static_cast<ObjectId>(c)});
  }
  for (int j = 0; j < heavy_on_zero; ++j)
    b.g.add_task(0, kNoObject, std::vector<Access>{{f[0], M::CW}, {x[0], M::R}}, 400,
                 static_cast<StableKey>(200000 + j));
  for (int i = 0; i < objects; ++i) {
    const auto u = static_cast<std::size_t>(i);
    b.g.add_task(0, static_cast<ObjectId>(i), std::vector<Access>{{x[u], M::RW}, {f[u], M::R}}, 100,
                 static_cast<StableKey>(10 * i + 2));
  }
  return b.done();
}

/// Objects in collision groups, each group solved by its own CG-like loop (as the engine
/// does): per object a force task, then per group a loop of `iterations` whose body holds
/// per object a product task, one dot product (CW into the group's scalar) per object, per
/// object an update, and the break; then per object an integration task. Per-object tasks
/// keep their stable key whatever group the object is in; group tasks are keyed by the
/// group's first object. `groups` partitions 0..objects-1.
inline StepGraph grouped_scene(int objects, const std::vector<std::vector<int>>& groups,
                               std::uint32_t iterations = 5) {
  Builder b;
  std::vector<DatumId> x, p, q;
  for (int i = 0; i < objects; ++i) {
    const ObjectId o = b.object(name("obj", i));
    x.push_back(b.datum(name("x", i), 4096, o));
    p.push_back(b.datum(name("p", i), 4096, o));
    q.push_back(b.datum(name("q", i), 4096, o));
  }
  auto ob = [](int i) { return static_cast<ObjectId>(i); };
  auto ui = [](int i) { return static_cast<std::size_t>(i); };
  auto key = [](int i, int what) { return static_cast<StableKey>(100 * i + what); };
  for (int i = 0; i < objects; ++i)
    b.g.add_task(0, ob(i), std::vector<Access>{{p[ui(i)], M::W}, {x[ui(i)], M::R}}, 200, key(i, 1));
  for (const std::vector<int>& group : groups) {
    const int first = group.front();
    const DatumId alpha = b.datum(name("alpha", first), 8), cond = b.datum(name("cond", first), 1);
    const TaskId begin = static_cast<TaskId>(b.g.tasks.size());
    for (int i : group)
      b.g.add_task(0, ob(i), std::vector<Access>{{q[ui(i)], M::W}, {p[ui(i)], M::R}}, 300, key(i, 2));
    for (int i : group)
      b.g.add_task(0, ob(i), std::vector<Access>{{alpha, M::CW}, {p[ui(i)], M::R}, {q[ui(i)], M::R}}, 50,
                   key(i, 3));
    for (int i : group)
      b.g.add_task(0, ob(i), std::vector<Access>{{p[ui(i)], M::RW}, {q[ui(i)], M::R}, {alpha, M::R}}, 100,
                   key(i, 4));
    b.g.add_task(0, kNoObject, std::vector<Access>{{cond, M::W}, {alpha, M::R}}, 10, key(first, 5));
    b.g.add_task(0, kNoObject, std::vector<Access>{{cond, M::R}}, 1, key(first, 6));
    b.loop(cond, begin, static_cast<TaskId>(b.g.tasks.size()), iterations);
  }
  for (int i = 0; i < objects; ++i)
    b.g.add_task(0, ob(i), std::vector<Access>{{x[ui(i)], M::RW}, {p[ui(i)], M::R}}, 100, key(i, 7));
  return b.done();
}

}  // namespace tgraph::partition::testing
