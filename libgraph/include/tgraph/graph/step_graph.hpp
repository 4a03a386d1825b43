// SPDX-License-Identifier: MIT
// The data model of one simulation step: data, tasks with accesses, loops, edges, contacts.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace tgraph {

using DatumId = std::uint32_t;
using TaskId = std::uint32_t;
using ObjectId = std::uint32_t;
using LoopId = std::uint32_t;
using KindId = std::uint32_t;
using StableKey = std::uint64_t;

inline constexpr ObjectId kNoObject = std::numeric_limits<ObjectId>::max();
inline constexpr LoopId kNoLoop = std::numeric_limits<LoopId>::max();
inline constexpr TaskId kNoTask = std::numeric_limits<TaskId>::max();

/// How a task touches a datum. CW = cumulative write (commutative `+=` reduction).
enum class AccessMode : std::uint8_t { R = 0, W = 1, RW = 2, CW = 3 };

/// "R", "W", "RW" or "CW".
std::string_view to_string(AccessMode mode);
/// True for W, RW and CW.
bool writes(AccessMode mode);
/// True for R and RW.
bool reads(AccessMode mode);

/// Why an edge exists.
enum class EdgeKind : std::uint8_t { RAW = 0, WAR = 1, WAW = 2 };
/// "RAW", "WAR" or "WAW".
std::string_view to_string(EdgeKind kind);

/// One access of a task: which datum, how.
struct Access {
  DatumId datum = 0;
  AccessMode mode = AccessMode::R;
  friend bool operator==(const Access&, const Access&) = default;
};

/// A piece of shared state (a state vector of an object, a scalar of the solver...).
struct Datum {
  std::string name;
  ObjectId object = kNoObject;  ///< owning object, or kNoObject for shared data
  std::uint64_t bytes = 0;
  friend bool operator==(const Datum&, const Datum&) = default;
};

/// A simulated object (or interaction) that tasks belong to.
struct ObjectInfo {
  std::string name;  ///< stable across steps; stable keys are derived from it
  friend bool operator==(const ObjectInfo&, const ObjectInfo&) = default;
};

/// One call of a component method on one object: the unit of scheduling.
struct Task {
  KindId kind = 0;                ///< index into StepGraph::kinds
  ObjectId object = kNoObject;    ///< object (or interaction) the task belongs to
  std::uint32_t access_begin = 0; ///< first access in StepGraph::accesses
  std::uint32_t access_count = 0;
  std::uint64_t cost_ns = 0;      ///< measured cost of one execution (mean over loop iterations)
  LoopId loop = kNoLoop;          ///< enclosing dynamic loop
  StableKey key = 0;              ///< names the same task across steps (object, kind, occurrence)
  friend bool operator==(const Task&, const Task&) = default;
};

/// A dynamic loop (paper section 3.3): body recorded once, run `iterations` times.
/// The body is the contiguous task range [first, last); its last task is the
/// conditional break, which reads `condition`. Every body task runs in every iteration.
struct Loop {
  DatumId condition = 0;
  TaskId first = 0;
  TaskId last = 0;                ///< one past the break task
  std::uint32_t iterations = 1;   ///< iterations actually run this step
  std::uint32_t max_iterations = 0;
  friend bool operator==(const Loop&, const Loop&) = default;
};

/// A dependency between two tasks through one datum.
struct Edge {
  TaskId from = 0;
  TaskId to = 0;
  DatumId datum = 0;
  EdgeKind kind = EdgeKind::RAW;
  friend bool operator==(const Edge&, const Edge&) = default;
  friend auto operator<=>(const Edge&, const Edge&) = default;
};

/// A pair of objects in contact or otherwise interacting this step (a < b).
struct Contact {
  ObjectId a = 0;
  ObjectId b = 0;
  friend bool operator==(const Contact&, const Contact&) = default;
  friend auto operator<=>(const Contact&, const Contact&) = default;
};

/// The task graph of one time step.
///
///   StepGraph g;  // filled by capture, a trace reader or by hand
///   g.derive_edges();
///   Metrics m = compute_metrics(g);
class StepGraph {
 public:
  std::vector<std::string> kinds;     ///< task kind names (method names)
  std::vector<ObjectInfo> objects;
  std::vector<Datum> data;
  std::vector<Task> tasks;            ///< in program order
  std::vector<Access> accesses;       ///< all tasks' accesses, task by task
  std::vector<Loop> loops;            ///< sorted by first task, not nested
  std::vector<Contact> contacts;      ///< sorted, unique
  /// Collision group of objects [0, groups.size()) (bodies; interaction objects declared
  /// after them may have none). Empty: one group.
  std::vector<std::uint32_t> groups;
  /// Time the engine spent this step on its main thread outside the step's tasks and before
  /// them (collision detection, contact and group bookkeeping): serial work that every
  /// execution of the step pays before its first task. Replays run it, the simulator adds it.
  std::uint64_t host_ns = 0;

  /// Derived by derive_edges(): intra-step edges (within one loop iteration for loop bodies).
  std::vector<Edge> edges;
  /// Derived by derive_edges(): loop-carried edges, from iteration i to iteration i+1
  /// of the same loop (from >= to in program order is allowed here).
  std::vector<Edge> carried_edges;

  /// Accesses of task `t`.
  std::span<const Access> accesses_of(TaskId t) const {
    const Task& task = tasks[t];
    return {accesses.data() + task.access_begin, task.access_count};
  }
  /// Number of times task `t` runs this step (its loop's iterations, else 1).
  std::uint64_t runs(TaskId t) const {
    const LoopId l = tasks[t].loop;
    return l == kNoLoop ? 1 : loops[l].iterations;
  }
  /// Kind name of task `t`.
  const std::string& kind_name(TaskId t) const { return kinds[tasks[t].kind]; }

  /// Appends a task with its accesses; returns its id. For hand-built graphs and readers.
  TaskId add_task(KindId kind, ObjectId object, std::span<const Access> acc,
                  std::uint64_t cost_ns = 0, StableKey key = 0);
  /// Interns a kind name.
  KindId intern_kind(std::string_view name);

  /// Recomputes `edges` and `carried_edges` from program order and accesses.
  void derive_edges();
  /// Same, giving up (both lists left empty, returns false) when either list would exceed
  /// `max_edges`: CW groups followed by many readers grow as writers x readers, so readers
  /// of untrusted files bound it.
  bool derive_edges(std::size_t max_edges);
  /// Checks internal consistency (ids in range, loops well formed); returns an empty
  /// string when valid, else a one-line reason.
  std::string validate() const;
  /// Hash of the structure: kinds, objects, data, tasks and accesses, loop shapes.
  /// Ignores costs, iteration counts and the contact list (contact interactions show up
  /// as tasks and objects). Equal structure => equal hash.
  std::uint64_t structural_hash() const;
  /// True when both steps have the same structure (what structural_hash summarises).
  bool same_structure(const StepGraph& other) const;

  friend bool operator==(const StepGraph&, const StepGraph&) = default;

 private:
  void derive_edges_unchecked(std::size_t max_edges);
};

}  // namespace tgraph
