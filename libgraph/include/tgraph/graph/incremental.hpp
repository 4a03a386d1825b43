// SPDX-License-Identifier: MIT
// Incremental dependency derivation: the edges of a step from those of the previous step.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "tgraph/graph/step_graph.hpp"

namespace tgraph {

namespace detail {
/// One access seen from its datum: the task, its mode, the task's loop (8 bytes: the loop
/// id and the mode share a word; a step has far fewer than 2^30 loops).
struct AccessEntry {
  TaskId task = 0;
  std::uint32_t loop_mode = kNoLoopBits << 2;  ///< loop id (kNoLoopBits for none) << 2 | mode
  static constexpr std::uint32_t kNoLoopBits = (1u << 30) - 1;
  AccessEntry() = default;
  AccessEntry(TaskId t, AccessMode m, LoopId l)
      : task(t),
        loop_mode(((l == kNoLoop ? kNoLoopBits : l) << 2) | static_cast<std::uint32_t>(m)) {}
  AccessMode mode() const { return static_cast<AccessMode>(loop_mode & 3u); }
  LoopId loop() const {
    const std::uint32_t l = loop_mode >> 2;
    return l == kNoLoopBits ? kNoLoop : l;
  }
};
/// A step's accesses grouped by datum, each datum's in program order (CSR: the entries of
/// datum d are [begin[d], begin[d + 1])).
struct AccessesByDatum {
  std::vector<std::uint32_t> begin;
  std::vector<AccessEntry> entries;
};
}  // namespace detail

/// What EdgeDeriver::derive did for one step.
struct EdgeUpdate {
  /// False when the step was derived from scratch (first step, or stable keys that do not
  /// name tasks uniquely in this step or the previous one).
  bool incremental = false;
  std::uint32_t data_rederived = 0;  ///< accessed data whose edges were derived again
  std::uint32_t data_reused = 0;     ///< accessed data whose edges were carried over
  std::uint64_t edges_reused = 0;    ///< edges (intra-step and carried) carried over
  std::uint64_t edges = 0;           ///< edges (intra-step and carried) of the step
  std::int64_t ns = 0;               ///< time derive() took (steady clock)
};

/// Derives the edges of successive steps, each from the previous step's.
///
/// The edges of one datum depend only on its access sequence: the tasks accessing it in
/// program order, each access's mode, and which consecutive accesses share a loop body
/// (StepGraph::derive_edges runs one state machine per datum). Tasks are matched with the
/// previous step's by stable key; a datum (same id and name) whose sequence is the previous
/// step's with every task matched keeps its edges, task ids renumbered; only the data whose
/// sequence changed (those of added or removed contact interactions and of collision groups
/// whose solver loops merged or split) run the state machine again. The result equals
/// derive_edges() edge for edge, in the same order.
///
///   EdgeDeriver deriver;
///   for (StepGraph& g : steps) {
///     EdgeUpdate u = deriver.derive(g);  // g.edges and g.carried_edges filled
///   }
class EdgeDeriver {
 public:
  /// Fills g.edges and g.carried_edges (from the previous derive()'s step when it can) and
  /// remembers g for the next call.
  EdgeUpdate derive(StepGraph& g);
  /// Remembers `g` (edges derived) as the previous step without deriving anything.
  void seed(const StepGraph& g);
  /// Forgets the previous step: the next derive() starts from scratch.
  void reset();

 private:
  using Entry = detail::AccessEntry;
  using ByDatum = detail::AccessesByDatum;
  // Task by stable key: open addressing, linear probing (keys are hashes already).
  class KeyTable {
   public:
    /// Fills the table; false when a key names two tasks.
    bool build(const StepGraph& g);
    /// The task with key `k`, or kNoTask.
    TaskId find(StableKey k) const;

   private:
    std::vector<StableKey> keys_;
    std::vector<TaskId> tasks_;  // kNoTask: empty slot
    std::size_t mask_ = 0;
  };
  void remember(const StepGraph& g, ByDatum&& accesses, bool keyed);

  bool have_previous_ = false;
  bool previous_keyed_ = false;  // stable keys unique in the previous step
  KeyTable previous_task_, current_task_;  // by key; current_task_ is swapped in
  std::vector<std::string> previous_names_;              // by datum
  ByDatum previous_accesses_;
  std::vector<std::uint32_t> edge_begin_, carried_begin_;  // previous edges by datum (CSR)
  std::vector<Edge> edges_by_datum_, carried_by_datum_;
};

/// One-shot form: derives `next`'s edges incrementally from `previous` (edges derived).
EdgeUpdate derive_edges_from(const StepGraph& previous, StepGraph& next);

}  // namespace tgraph
