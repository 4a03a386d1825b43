// SPDX-License-Identifier: MIT
// What both schedule simulators (built-in and SimGrid) run: each processor's program of
// tasks and loop blocks, each task's dependencies, and which instance a dependency names.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/step_graph.hpp"

namespace tgraph::model::detail {

/// An instance index that names no instance (the dependency has no source this iteration).
inline constexpr std::uint64_t kNoInstance = std::numeric_limits<std::uint64_t>::max();

/// One dependency of a task: intra-step edge or loop-carried edge (from iteration i - 1).
struct Dep {
  TaskId from;
  DatumId datum;
  bool raw;
  bool carried;
};

/// One thing a processor runs: a task outside loops, or its share of one loop's body
/// (paper section 3.3: the body is partitioned once, loop control replicated).
struct Item {
  TaskId task = kNoTask;
  LoopId loop = kNoLoop;
  std::vector<TaskId> body;
};

/// A datum version (the instance that wrote it) known on a processor: what both simulators
/// count once (a wait, a transfer's bytes).
struct VersionOnProc {
  std::uint64_t instance;
  std::uint32_t datum;
  std::uint32_t proc;
  friend bool operator==(const VersionOnProc&, const VersionOnProc&) = default;
};
struct VersionOnProcHash {
  std::size_t operator()(const VersionOnProc& k) const {
    std::uint64_t h = k.instance * 0x9E3779B97F4A7C15ull;
    h ^= (static_cast<std::uint64_t>(k.datum) << 32 | k.proc) + 0x7F4A7C159E3779B9ull + (h << 6) +
         (h >> 2);
    return static_cast<std::size_t>(h);
  }
};

/// The set of VersionOnProc keys a simulation has seen: open addressing with linear probing
/// in one array (no allocation per key; std::unordered_set spent most of a sticky partition
/// of falling64 in node allocation and rehashing).
class VersionSet {
 public:
  /// Inserts `k` (its instance is never kNoInstance, the empty slot's mark); true when it
  /// was not there yet.
  bool insert(const VersionOnProc& k) {
    if ((size_ + 1) * 4 > slots_.size() * 3) grow();
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t i = mix(k) & mask;; i = (i + 1) & mask) {
      VersionOnProc& s = slots_[i];
      if (s.instance == kNoInstance) {
        s = k;
        ++size_;
        return true;
      }
      if (s == k) return false;
    }
  }
  void clear() {
    slots_.assign(slots_.size(), kEmpty);
    size_ = 0;
  }
  std::size_t size() const { return size_; }

 private:
  static constexpr VersionOnProc kEmpty{kNoInstance, 0, 0};
  static std::size_t mix(const VersionOnProc& k) {
    std::uint64_t h = VersionOnProcHash{}(k);
    h ^= h >> 29;  // the low bits index the table
    h *= 0xBF58476D1CE4E5B9ull;
    return static_cast<std::size_t>(h ^ (h >> 32));
  }
  void grow() {
    std::vector<VersionOnProc> old(slots_.empty() ? 64 : slots_.size() * 2, kEmpty);
    old.swap(slots_);
    size_ = 0;
    for (const VersionOnProc& k : old)
      if (k.instance != kNoInstance) insert(k);
  }
  std::vector<VersionOnProc> slots_;
  std::size_t size_ = 0;
};

/// Per task, the first of its instances (iteration i of task t is `first[t] + i`), plus the
/// total number of instances at the end.
std::vector<std::uint64_t> first_instances(const StepGraph& g);
/// Per task, its dependencies (self edges dropped, loop-carried edges marked).
std::vector<std::vector<Dep>> dependencies(const StepGraph& g);
/// Per processor, its items in `a.order[p]` or program order; a processor's loop tasks form
/// one block placed where its first loop task appears.
std::vector<std::vector<Item>> programs(const StepGraph& g, const Assignment& a);

/// The error text of a processor stuck at position `pos` of item `it` (the task it waits to
/// run, or the loop's break task at the end of an iteration).
std::string deadlock_message(const StepGraph& g, const Item& it, std::size_t pos, ProcId p);

/// The instance that dependency `d` of iteration `i` of task `t` refers to (kNoInstance for
/// none): iteration i - 1 for a loop-carried edge, iteration i within one loop body, else the
/// source's last run.
inline std::uint64_t dependency_source(const StepGraph& g, const std::vector<std::uint64_t>& first,
                                       const Dep& d, TaskId t, std::uint32_t i) {
  const LoopId lu = g.tasks[d.from].loop;
  if (d.carried) return i == 0 ? kNoInstance : first[d.from] + i - 1;
  if (lu != kNoLoop && lu == g.tasks[t].loop) return first[d.from] + i;
  const std::uint64_t runs = g.runs(d.from);
  return runs == 0 ? kNoInstance : first[d.from] + runs - 1;
}

}  // namespace tgraph::model::detail
