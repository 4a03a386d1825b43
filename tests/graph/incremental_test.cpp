// SPDX-License-Identifier: MIT
// EdgeDeriver: incremental edges equal derive_edges() edge for edge, on random programs
// mutated step to step and on random contact sequences of an engine-like program.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "tgraph/graph/incremental.hpp"
#include "tgraph/graph/step_graph.hpp"

namespace tgraph {
namespace {

using M = AccessMode;

// Stable key of a task the way the recorder makes one: hash(object, kind, occurrence).
std::uint64_t fnv(const std::string& s, std::uint64_t h = 1469598103934665603ull) {
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h;
}

void assign_keys(StepGraph& g) {
  std::map<std::pair<ObjectId, KindId>, std::uint32_t> occurrence;
  for (Task& t : g.tasks) {
    const std::string obj = t.object == kNoObject ? "-" : g.objects[t.object].name;
    t.key = fnv(obj + "/" + g.kinds[t.kind] + "/" + std::to_string(occurrence[{t.object, t.kind}]++));
  }
}

StepGraph scratch(StepGraph g) {
  g.derive_edges();
  return g;
}

// ---- Random programs: a task list with loops, mutated from step to step. ----

struct ProgTask {
  std::uint32_t id = 0;  // names the task across steps (its object)
  std::vector<Access> acc;
};
struct Program {
  std::vector<ProgTask> tasks;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> loops;  // [first, last) by position
};

Access random_access(std::mt19937& rng, std::uint32_t n_data) {
  static const M modes[] = {M::R, M::R, M::W, M::RW, M::CW, M::CW};
  return {static_cast<DatumId>(rng() % n_data), modes[rng() % 6]};
}

StepGraph build(const Program& p, std::uint32_t n_data, std::uint32_t n_ids) {
  StepGraph g;
  g.kinds = {"op", "loop.break"};
  for (std::uint32_t i = 0; i < n_ids; ++i) g.objects.push_back({"o" + std::to_string(i)});
  for (std::uint32_t d = 0; d < n_data; ++d) g.data.push_back({"d" + std::to_string(d), kNoObject, 8});
  std::size_t next_loop = 0;
  for (std::size_t i = 0; i < p.tasks.size(); ++i) {
    // Every task has kind "op", the breaks too: a task keeps its key when loops reshape.
    const TaskId t = g.add_task(0, p.tasks[i].id, p.tasks[i].acc, 1);
    if (next_loop < p.loops.size() && i >= p.loops[next_loop].first) {
      g.tasks[t].loop = static_cast<LoopId>(next_loop);
      if (i + 1 == p.loops[next_loop].second) {
        g.loops.push_back({p.tasks[i].acc.front().datum, static_cast<TaskId>(p.loops[next_loop].first),
                           static_cast<TaskId>(i + 1), 3, 0});
        ++next_loop;
      }
    }
  }
  assign_keys(g);
  return g;
}

// Random loops over the current task list: non-overlapping ranges of at least 2 tasks.
void random_loops(std::mt19937& rng, Program& p) {
  p.loops.clear();
  std::size_t at = 0;
  while (at + 2 < p.tasks.size()) {
    const std::size_t skip = rng() % 6;
    const std::size_t len = 2 + rng() % 7;
    if (at + skip + len > p.tasks.size()) break;
    if (rng() % 3 != 0) p.loops.push_back({static_cast<std::uint32_t>(at + skip),
                                           static_cast<std::uint32_t>(at + skip + len)});
    at += skip + len;
  }
}

void expect_same_edges(const StepGraph& incremental, const StepGraph& reference, int step) {
  ASSERT_EQ(incremental.edges.size(), reference.edges.size()) << "step " << step;
  ASSERT_EQ(incremental.carried_edges.size(), reference.carried_edges.size()) << "step " << step;
  for (std::size_t i = 0; i < reference.edges.size(); ++i)
    ASSERT_EQ(incremental.edges[i], reference.edges[i]) << "step " << step << " edge " << i;
  for (std::size_t i = 0; i < reference.carried_edges.size(); ++i)
    ASSERT_EQ(incremental.carried_edges[i], reference.carried_edges[i])
        << "step " << step << " carried edge " << i;
}

TEST(IncrementalEdges, EqualFromScratchOnRandomlyMutatedPrograms) {
  std::uint64_t reused = 0, total = 0, incremental_steps = 0;
  for (std::uint32_t seed = 1; seed <= 40; ++seed) {
    std::mt19937 rng(seed);
    const std::uint32_t n_data = 4 + static_cast<std::uint32_t>(rng() % 20);
    Program p;
    std::uint32_t next_id = 0;
    const std::size_t n = 5 + rng() % 60;
    for (std::size_t i = 0; i < n; ++i) {
      ProgTask t{next_id++, {}};
      const std::size_t k = 1 + rng() % 3;
      for (std::size_t j = 0; j < k; ++j) t.acc.push_back(random_access(rng, n_data));
      p.tasks.push_back(std::move(t));
    }
    random_loops(rng, p);
    EdgeDeriver deriver;
    for (int step = 0; step < 25; ++step) {
      StepGraph g = build(p, n_data, next_id);
      const StepGraph reference = scratch(g);
      const EdgeUpdate u = deriver.derive(g);
      EXPECT_EQ(u.incremental, step > 0);
      expect_same_edges(g, reference, step);
      if (step > 0) {
        ++incremental_steps;
        reused += u.edges_reused;
        total += u.edges;
      }
      // Mutate: remove, insert, change an access, reshape the loops (sometimes).
      const auto what = rng() % 5;
      if (what == 0 && p.tasks.size() > 3) {
        p.tasks.erase(p.tasks.begin() + static_cast<std::ptrdiff_t>(rng() % p.tasks.size()));
      } else if (what == 1) {
        ProgTask t{next_id++, {random_access(rng, n_data)}};
        p.tasks.insert(p.tasks.begin() + static_cast<std::ptrdiff_t>(rng() % (p.tasks.size() + 1)), t);
      } else if (what == 2) {
        ProgTask& t = p.tasks[rng() % p.tasks.size()];
        t.acc[rng() % t.acc.size()] = random_access(rng, n_data);
      } else if (what == 3) {
        random_loops(rng, p);
        continue;
      }
      // Keep loops within the task list.
      std::erase_if(p.loops, [&](const auto& l) { return l.second > p.tasks.size(); });
    }
  }
  // Most steps change one task: most edges are carried over.
  EXPECT_GT(incremental_steps, 0u);
  EXPECT_GT(reused * 2, total);
}

TEST(IncrementalEdges, LoopsMergedOverTheSameTasksAreDerivedAgain) {
  // Tasks 0-1 and 2-3 form two loops, then one loop 0-3: same tasks and accesses.
  Program p;
  for (std::uint32_t i = 0; i < 4; ++i) p.tasks.push_back({i, {{0, i % 2 ? M::R : M::W}}});
  p.loops = {{0, 2}, {2, 4}};
  StepGraph a = build(p, 1, 4);
  a.derive_edges();
  p.loops = {{0, 4}};
  StepGraph b = build(p, 1, 4);
  const EdgeUpdate u = derive_edges_from(a, b);
  EXPECT_EQ(u.data_rederived, 1u);
  EXPECT_EQ(b.edges, scratch(b).edges);
  EXPECT_EQ(b.carried_edges, scratch(b).carried_edges);
  EXPECT_NE(b.carried_edges, a.carried_edges);  // 3 -> 0 is carried now
}

TEST(IncrementalEdges, DuplicateKeysFallBackToScratch) {
  StepGraph g;
  g.kinds = {"op"};
  g.data = {{"x", kNoObject, 8}};
  g.add_task(0, kNoObject, std::vector<Access>{{0, M::W}}, 1, 7);
  g.add_task(0, kNoObject, std::vector<Access>{{0, M::R}}, 1, 7);
  EdgeDeriver deriver;
  deriver.derive(g);
  StepGraph h = g;
  h.add_task(0, kNoObject, std::vector<Access>{{0, M::W}}, 1, 9);
  const EdgeUpdate u = deriver.derive(h);
  EXPECT_FALSE(u.incremental);
  EXPECT_EQ(h.edges, scratch(h).edges);
}

TEST(IncrementalEdges, RenamedDatumIsDerivedAgain) {
  StepGraph g;
  g.kinds = {"op"};
  g.data = {{"x", kNoObject, 8}};
  g.add_task(0, kNoObject, std::vector<Access>{{0, M::W}}, 1, 1);
  g.add_task(0, kNoObject, std::vector<Access>{{0, M::R}}, 1, 2);
  g.derive_edges();
  StepGraph h = g;
  h.data[0].name = "y";
  const EdgeUpdate u = derive_edges_from(g, h);
  EXPECT_TRUE(u.incremental);
  EXPECT_EQ(u.data_rederived, 1u);
  EXPECT_EQ(u.data_reused, 0u);
  EXPECT_EQ(h.edges, g.edges);
}

// ---- Random contact sequences of an engine-like program (the shape of samples/). ----

// Bodies with state x, v, f, dx, df; per collision group a solver loop; per contact an
// interaction object whose tasks read both bodies' state and add into both forces.
StepGraph engine_step(std::uint32_t bodies, const std::set<std::pair<std::uint32_t, std::uint32_t>>& contacts) {
  StepGraph g;
  const KindId reset = g.intern_kind("resetForce"), add = g.intern_kind("addForce"),
               add_d = g.intern_kind("addDForce"), rhs = g.intern_kind("computeRhs"),
               dot = g.intern_kind("dotProduct"), upd = g.intern_kind("cgUpdate"),
               brk = g.intern_kind("loop.break"), pos = g.intern_kind("updatePosition");
  auto datum = [&](const std::string& name) {
    for (DatumId d = 0; d < g.data.size(); ++d)
      if (g.data[d].name == name) return d;
    g.data.push_back({name, kNoObject, 24});
    return static_cast<DatumId>(g.data.size() - 1);
  };
  auto object = [&](const std::string& name) {
    for (ObjectId o = 0; o < g.objects.size(); ++o)
      if (g.objects[o].name == name) return o;
    g.objects.push_back({name});
    return static_cast<ObjectId>(g.objects.size() - 1);
  };
  auto b = [](std::uint32_t i) { return "b" + std::to_string(i); };
  // Every body's data first, so that datum ids stay the same from step to step.
  for (std::uint32_t i = 0; i < bodies; ++i) {
    object(b(i));
    for (const char* v : {".x", ".v", ".f", ".dx", ".df", ".r"}) datum(b(i) + v);
  }
  std::vector<std::uint32_t> parent(bodies);
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](std::uint32_t i) {
    while (parent[i] != i) i = parent[i];
    return i;
  };
  for (auto [a, c] : contacts) {
    const std::uint32_t ra = find(a), rc = find(c);
    if (ra != rc) parent[std::max(ra, rc)] = std::min(ra, rc);
  }
  std::map<std::uint32_t, std::vector<std::uint32_t>> groups;
  for (std::uint32_t i = 0; i < bodies; ++i) groups[find(i)].push_back(i);
  for (const auto& [root, members] : groups) {
    const ObjectId solver = object("solver[" + b(root) + "]");
    const DatumId alpha = datum("solver[" + b(root) + "].alpha"), cond = datum("solver[" + b(root) + "].cond");
    std::vector<std::pair<std::uint32_t, std::uint32_t>> inter;
    for (auto [a, c] : contacts)
      if (find(a) == root) inter.push_back({a, c});
    auto task = [&](KindId k, ObjectId o, std::vector<Access> acc) { g.add_task(k, o, acc); };
    for (std::uint32_t i : members) task(reset, object(b(i)), {{datum(b(i) + ".f"), M::W}});
    for (auto [a, c] : inter)
      task(add, object("contact[" + b(a) + "|" + b(c) + "]"),
           {{datum(b(a) + ".x"), M::R}, {datum(b(c) + ".x"), M::R}, {datum(b(a) + ".f"), M::CW},
            {datum(b(c) + ".f"), M::CW}});
    for (std::uint32_t i : members)
      task(rhs, object(b(i)), {{datum(b(i) + ".f"), M::R}, {datum(b(i) + ".v"), M::R}, {datum(b(i) + ".r"), M::W}});
    const auto first = static_cast<TaskId>(g.tasks.size());
    const auto loop = static_cast<LoopId>(g.loops.size());
    for (std::uint32_t i : members)
      task(add_d, object(b(i)), {{datum(b(i) + ".dx"), M::R}, {datum(b(i) + ".df"), M::W}});
    for (auto [a, c] : inter)
      task(add_d, object("contact[" + b(a) + "|" + b(c) + "]"),
           {{datum(b(a) + ".dx"), M::R}, {datum(b(c) + ".dx"), M::R}, {datum(b(a) + ".df"), M::CW},
            {datum(b(c) + ".df"), M::CW}});
    for (std::uint32_t i : members)
      task(dot, object(b(i)), {{datum(b(i) + ".df"), M::R}, {datum(b(i) + ".dx"), M::R}, {alpha, M::CW}});
    for (std::uint32_t i : members)
      task(upd, object(b(i)), {{alpha, M::R}, {datum(b(i) + ".r"), M::RW}, {datum(b(i) + ".dx"), M::RW}});
    task(brk, solver, {{cond, M::R}});
    for (TaskId t = first; t < g.tasks.size(); ++t) g.tasks[t].loop = loop;
    g.loops.push_back({cond, first, static_cast<TaskId>(g.tasks.size()), 5, 0});
    for (std::uint32_t i : members)
      task(pos, object(b(i)), {{datum(b(i) + ".dx"), M::R}, {datum(b(i) + ".v"), M::RW}, {datum(b(i) + ".x"), M::RW}});
  }
  assign_keys(g);
  return g;
}

TEST(IncrementalEdges, EqualFromScratchOnRandomContactSequences) {
  std::uint64_t rederived = 0, accessed = 0;
  for (std::uint32_t seed = 1; seed <= 20; ++seed) {
    std::mt19937 rng(seed);
    const auto bodies = 3 + static_cast<std::uint32_t>(rng() % 10);
    std::set<std::pair<std::uint32_t, std::uint32_t>> contacts;
    EdgeDeriver deriver;
    for (int step = 0; step < 30; ++step) {
      StepGraph g = engine_step(bodies, contacts);
      ASSERT_EQ(g.validate(), "");
      const StepGraph reference = scratch(g);
      const EdgeUpdate u = deriver.derive(g);
      expect_same_edges(g, reference, step);
      if (step > 0) {
        EXPECT_TRUE(u.incremental);
        rederived += u.data_rederived;
        accessed += u.data_rederived + u.data_reused;
      }
      // One or two contacts appear or disappear (groups merge or split).
      for (auto c = 1 + rng() % 2; c > 0; --c) {
        auto a = static_cast<std::uint32_t>(rng() % bodies), d = static_cast<std::uint32_t>(rng() % bodies);
        if (a == d) continue;
        if (a > d) std::swap(a, d);
        if (!contacts.erase({a, d})) contacts.insert({a, d});
      }
    }
  }
  // A contact change touches a few bodies' data: most data keep their edges.
  EXPECT_LT(rederived * 2, accessed);
}

}  // namespace
}  // namespace tgraph
