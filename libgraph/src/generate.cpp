// SPDX-License-Identifier: MIT
// Synthetic steps (`tgraph generate`): Task Bench's shapes over double-buffered cells, and a
// solver step of any size. Random numbers come from splitmix64 only (the same on every
// platform and standard library).
#include "tgraph/graph/generate.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/trace_io.hpp"

namespace tgraph {
namespace {

constexpr std::uint64_t kMaxIds = std::numeric_limits<std::uint32_t>::max() - 1;

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

/// A deterministic stream of 64-bit numbers.
class Random {
 public:
  explicit Random(std::uint64_t seed) : state_(splitmix64(seed)) {}
  std::uint64_t next() { return splitmix64(state_++); }
  /// Uniform in [0, n) (n > 0), by multiply-shift.
  std::uint64_t below(std::uint64_t n) {
    return static_cast<std::uint64_t>((static_cast<unsigned __int128>(next()) * n) >> 64);
  }

 private:
  std::uint64_t state_;
};

/// Stable key of the task of column `i` in layer `t` (a hash, like captured keys).
StableKey key_of(std::uint64_t t, std::uint64_t i) { return splitmix64((t << 32) ^ i); }

/// Draws every task's cost: uniform in [cost/2, 3 cost/2], from the seed and the step.
void draw_costs(StepGraph& g, const GenerateOptions& o, std::uint32_t step) {
  Random rng(o.seed * 0x100000001b3ull + step);
  const std::uint64_t half = o.cost_ns / 2;
  for (Task& t : g.tasks) t.cost_ns = half + rng.below(o.cost_ns + 1);
}

/// Task Bench's shapes: `width` columns, cells double-buffered by layer parity.
void cells(StepGraph& g, const GenerateOptions& o) {
  const std::uint64_t n = o.tasks;
  const std::uint64_t width = o.width != 0 ? o.width : std::max<std::uint64_t>(1, n / 16);
  if (width > n) throw OptionError("width", "expected at most {tasks} (" + std::to_string(n) + ")");
  if (2 * width > kMaxIds) throw OptionError("width", "expected at most 2^31 - 1 columns");
  const KindId kind = g.intern_kind(std::string(to_string(o.pattern)));
  g.objects.reserve(width);
  for (std::uint64_t i = 0; i < width; ++i) g.objects.push_back({"c" + std::to_string(i)});
  const bool data = o.pattern != Pattern::kTrivial;
  if (data) {
    g.data.reserve(2 * width);
    for (std::uint64_t b = 0; b < 2; ++b)
      for (std::uint64_t i = 0; i < width; ++i)
        g.data.push_back({g.objects[i].name + "." + std::to_string(b), static_cast<ObjectId>(i),
                          o.datum_bytes});
  }
  auto cell = [width](std::uint64_t layer, std::uint64_t i) {
    return static_cast<DatumId>((layer % 2) * width + i);
  };
  std::uint32_t log_width = 0;
  while ((std::uint64_t{2} << log_width) <= width) ++log_width;  // floor(log2 width)
  // The random reads are drawn from the seed alone: every step has the same structure.
  Random rng(o.seed);
  const std::uint32_t per_task = o.pattern == Pattern::kRandom ? o.degree + 2 : 4;
  g.tasks.reserve(n);
  g.accesses.reserve(data ? n * per_task : 0);
  std::vector<Access> acc;
  for (std::uint64_t id = 0; id < n; ++id) {
    const std::uint64_t t = id / width, i = id % width;
    acc.clear();
    if (data && t > 0) {
      auto read = [&](std::uint64_t j) {
        const Access a{cell(t - 1, j), AccessMode::R};
        if (std::find(acc.begin(), acc.end(), a) == acc.end()) acc.push_back(a);
      };
      switch (o.pattern) {
        case Pattern::kTrivial:
        case Pattern::kDomain:
          break;
        case Pattern::kStencil:
          if (i > 0) read(i - 1);
          read(i);
          if (i + 1 < width) read(i + 1);
          break;
        case Pattern::kRandom:
          read(i);
          for (std::uint32_t r = 0; r < o.degree; ++r) read(rng.below(width));
          break;
        case Pattern::kTree:
          read(i);
          if (log_width > 0) {
            const std::uint64_t partner = i ^ (std::uint64_t{1} << ((t - 1) % log_width));
            if (partner < width) read(partner);
          }
          break;
      }
    }
    if (data) acc.push_back({cell(t, i), AccessMode::W});
    g.add_task(kind, static_cast<ObjectId>(i), acc, 0, key_of(t, i));
  }
}

/// A solver step of about `tasks` tasks over tasks * 4 / 25 objects: per object a force
/// task (R x, CW f) and one contact per four objects before a CG loop of five vector tasks
/// per object and three scalar tasks. Each global sum (CW by every object) has one reader
/// whose scalar the objects then read, as in the engine: edges stay linear in the tasks.
void domain(StepGraph& g, const GenerateOptions& o) {
  const std::uint64_t objects = std::max<std::uint64_t>(1, o.tasks * 4 / 25);
  if (5 * objects + 5 > kMaxIds) throw OptionError("tasks", "too many for the domain pattern");
  const KindId kf = g.intern_kind("addForce"), kc = g.intern_kind("contact"),
               kd = g.intern_kind("addDForce"), kpq = g.intern_kind("dotPQ"),
               ks = g.intern_kind("cgScalars"), ku = g.intern_kind("cgUpdate"),
               krr = g.intern_kind("dotRR"), kres = g.intern_kind("residual"),
               kdir = g.intern_kind("cgDirection"), kb = g.intern_kind("loop.break");
  g.objects.reserve(objects);
  g.data.reserve(5 * objects + 5);
  static constexpr std::array<const char*, 5> kVectors = {".x", ".f", ".p", ".q", ".r"};
  for (std::uint64_t b = 0; b < objects; ++b) {
    g.objects.push_back({"b" + std::to_string(b)});
    for (const char* v : kVectors)
      g.data.push_back({g.objects.back().name + v, static_cast<ObjectId>(b), o.datum_bytes});
  }
  auto vec = [](std::uint64_t b, int v) { return static_cast<DatumId>(5 * b + v); };
  const DatumId x = 0, f = 1, p = 2, q = 3, r = 4;
  const auto pq = static_cast<DatumId>(5 * objects);
  const DatumId alpha = pq + 1, rr = pq + 2, beta = pq + 3, cond = pq + 4;
  for (const char* s : {"pq", "alpha", "rr", "beta", "cond"}) g.data.push_back({s, kNoObject, 8});
  g.tasks.reserve(o.tasks + 8);
  g.accesses.reserve(o.tasks * 3 + 16);
  std::uint64_t serial = 0;
  auto add = [&](KindId k, std::uint64_t b, std::initializer_list<Access> acc) {
    const auto object = b == kNoObject ? kNoObject : static_cast<ObjectId>(b);
    g.add_task(k, object, std::span<const Access>(acc.begin(), acc.size()), 0,
               key_of(k, b == kNoObject ? (std::uint64_t{1} << 31) + serial++ : b));
  };
  for (std::uint64_t b = 0; b < objects; ++b)
    add(kf, b, {{vec(b, x), AccessMode::R}, {vec(b, f), AccessMode::CW}});
  for (std::uint64_t b = 0; b + 1 < objects; b += 4)
    add(kc, b,
        {{vec(b, x), AccessMode::R},
         {vec(b + 1, x), AccessMode::R},
         {vec(b, f), AccessMode::CW},
         {vec(b + 1, f), AccessMode::CW}});
  Loop loop;
  loop.condition = cond;
  loop.first = static_cast<TaskId>(g.tasks.size());
  loop.iterations = o.iterations;
  loop.max_iterations = std::max<std::uint32_t>(o.iterations, 200);
  for (std::uint64_t b = 0; b < objects; ++b)
    add(kd, b, {{vec(b, f), AccessMode::R}, {vec(b, p), AccessMode::R}, {vec(b, q), AccessMode::W}});
  for (std::uint64_t b = 0; b < objects; ++b)
    add(kpq, b, {{vec(b, p), AccessMode::R}, {vec(b, q), AccessMode::R}, {pq, AccessMode::CW}});
  add(ks, kNoObject, {{pq, AccessMode::R}, {rr, AccessMode::R}, {alpha, AccessMode::W}});
  for (std::uint64_t b = 0; b < objects; ++b)
    add(ku, b,
        {{alpha, AccessMode::R},
         {vec(b, q), AccessMode::R},
         {vec(b, x), AccessMode::RW},
         {vec(b, r), AccessMode::RW}});
  for (std::uint64_t b = 0; b < objects; ++b)
    add(krr, b, {{vec(b, r), AccessMode::R}, {rr, AccessMode::CW}});
  add(kres, kNoObject, {{rr, AccessMode::R}, {beta, AccessMode::W}, {cond, AccessMode::W}});
  for (std::uint64_t b = 0; b < objects; ++b)
    add(kdir, b, {{vec(b, r), AccessMode::R}, {beta, AccessMode::R}, {vec(b, p), AccessMode::RW}});
  add(kb, kNoObject, {{cond, AccessMode::R}});
  loop.last = static_cast<TaskId>(g.tasks.size());
  for (TaskId t = loop.first; t < loop.last; ++t) g.tasks[t].loop = 0;
  g.loops.push_back(loop);
}

}  // namespace

std::string_view to_string(Pattern p) {
  switch (p) {
    case Pattern::kTrivial:
      return "trivial";
    case Pattern::kStencil:
      return "stencil";
    case Pattern::kRandom:
      return "random";
    case Pattern::kTree:
      return "tree";
    case Pattern::kDomain:
      return "domain";
  }
  return "?";
}

std::optional<Pattern> pattern_from_string(std::string_view name) {
  for (const Pattern p : {Pattern::kTrivial, Pattern::kStencil, Pattern::kRandom, Pattern::kTree,
                          Pattern::kDomain})
    if (to_string(p) == name) return p;
  return std::nullopt;
}

StepGraph generate_step(const GenerateOptions& o, std::uint32_t step) {
  if (o.tasks == 0) throw OptionError("tasks", "expected at least 1");
  if (o.tasks > kMaxIds) throw OptionError("tasks", "expected at most 2^32 - 2");
  StepGraph g;
  switch (o.pattern) {
    case Pattern::kTrivial:
    case Pattern::kStencil:
    case Pattern::kRandom:
    case Pattern::kTree:
      cells(g, o);
      break;
    case Pattern::kDomain:
      if (o.iterations == 0) throw OptionError("iterations", "expected at least 1");
      domain(g, o);
      break;
  }
  draw_costs(g, o, step);
  return g;
}

ChainsStep chains_step(std::uint32_t chains, std::uint32_t per_chain, std::uint64_t cost_ns) {
  ChainsStep c;
  StepGraph& g = c.graph;
  const KindId kind = g.intern_kind("calibrate");
  for (std::uint32_t p = 0; p < chains; ++p)
    g.data.push_back({"chain " + std::to_string(p), kNoObject, 64});
  c.assignment.k = chains;
  for (std::uint32_t i = 0; i < per_chain * chains; ++i) {
    const Access acc[] = {{static_cast<DatumId>(i % chains), AccessMode::RW}};
    g.add_task(kind, kNoObject, acc, cost_ns, i);
    c.assignment.proc.push_back(i % chains);
  }
  g.derive_edges();
  return c;
}

Trace generate_trace(const GenerateOptions& o, std::uint32_t steps) {
  Trace trace;
  trace.header.scene = "generated-" + std::string(to_string(o.pattern));
  trace.header.engine = "tgraph generate";
  trace.header.tgraph_version = TGRAPH_VERSION;
  trace.steps.reserve(steps);
  for (std::uint32_t s = 0; s < steps; ++s) {
    if (s == 0) {
      trace.steps.push_back(generate_step(o, 0));
      trace.steps.back().derive_edges();
    } else {
      // Same structure and edges: a copy with the step's own costs.
      trace.steps.push_back(trace.steps.front());
      draw_costs(trace.steps.back(), o, s);
    }
  }
  return trace;
}

GeneratedFile generate_file(const GenerateOptions& o, std::uint32_t steps,
                            const std::string& output) {
  const auto t0 = std::chrono::steady_clock::now();
  const Trace trace = generate_trace(o, steps);
  write_trace(output, trace);
  GeneratedFile f;
  f.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  f.output = output;
  f.options = o;
  f.steps = trace.steps.size();
  const StepGraph& g = trace.steps.front();
  f.tasks = g.tasks.size();
  f.data = g.data.size();
  f.accesses = g.accesses.size();
  f.edges = g.edges.size() + g.carried_edges.size();
  return f;
}

std::string generated_json(const GeneratedFile& f) {
  return nlohmann::json{{"trace", f.output},
                        {"pattern", to_string(f.options.pattern)},
                        {"steps", f.steps},
                        {"tasks", f.tasks},
                        {"data", f.data},
                        {"accesses", f.accesses},
                        {"edges", f.edges},
                        {"seed", f.options.seed},
                        {"seconds", f.seconds}}
      .dump();
}

std::string generated_text(const GeneratedFile& f) {
  std::ostringstream s;
  s << "wrote " << f.output << ": " << f.steps << " step(s) of " << f.tasks << " tasks, "
    << f.data << " data, " << f.accesses << " accesses, " << f.edges << " edges ("
    << to_string(f.options.pattern) << ", seed " << f.options.seed << ") in " << f.seconds
    << " s\n";
  return s.str();
}

}  // namespace tgraph
