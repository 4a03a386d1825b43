// SPDX-License-Identifier: MIT
// Internal: the partition executor's plan (paper section 3.2): one program per processor,
// its tasks in order with the wait points (which completion count of which producer a task
// needs) and signal flags, built from an exec graph (partition_plan.cpp) or updated from the
// previous step's plan (partition_update.cpp). The threaded runtime (partition_executor.cpp)
// and the serial twin (partition_serial.cpp) run the same plans under one readiness rule
// (needed_executions).
#pragma once

#include <cstdint>
#include <vector>

#include "common.hpp"
#include "tgraph/graph/lowering.hpp"

namespace tgraph::replay::detail {

/// Which execution of a producer a wait needs.
enum class WaitKind : std::uint8_t {
  kOnce,       ///< producer outside loops: its single execution
  kSameIter,   ///< producer in the same loop: the same iteration
  kPrevIter,   ///< loop-carried: the previous iteration (nothing in iteration 0)
  kAfterLoop,  ///< producer in an earlier loop: its last iteration
};

/// One wait of a task: the producer's completion count it needs.
struct WaitPoint {
  TaskId producer = 0;
  LoopId loop = kNoLoop;  // kAfterLoop: the producer's loop
  WaitKind kind = WaitKind::kOnce;
  friend bool operator==(const WaitPoint&, const WaitPoint&) = default;
};

/// What an op of a processor's program does.
enum class OpKind : std::uint8_t { kTask, kLoopBegin, kLoopEnd };

/// A task op's part in a combine (PartitionPlan::combines; Op::jump holds the combine).
enum class CombineRole : std::uint8_t {
  kNone,
  kOffer,  ///< after running (and signalling), arrive; the last to arrive runs the combine
  kHead,   ///< arrive instead of waiting; run the combine if last, else wait until it ran
};

/// One op of a processor's program: 32 bytes, aligned, so that a record never straddles two
/// cache lines and the hot loop indexes ops with a shift. Everything the loop needs for a
/// task is here (its original id too), not in the exec graph's arrays.
struct alignas(32) Op {
  OpKind kind = OpKind::kTask;
  bool signal = false;    // publish done[task] after running
  bool is_break = false;  // evaluate and publish the loop decision after running
  CombineRole combine = CombineRole::kNone;
  TaskId task = 0;
  LoopId loop = kNoLoop;
  std::uint32_t wait_begin = 0, wait_end = 0;
  std::uint32_t jump = 0;   // kLoopEnd: first op of the body; kTask: its combine
  TaskId origin = kNoTask;  // kTask: the original task (ExecGraph::origin)
  // kTask: how many ops from this one on are tasks that wait for nothing and publish
  // nothing (the executor runs them in one loop, as the sequential program); 0: not this one.
  std::uint32_t plain_run = 0;
  friend bool operator==(const Op&, const Op&) = default;
};
static_assert(sizeof(Op) == 32);

/// One processor's program: its ops, their wait points, the data it first touches.
struct ProcPlan {
  std::vector<Op> ops;
  std::vector<WaitPoint> waits;
  std::vector<DatumId> owned;
  friend bool operator==(const ProcPlan&, const ProcPlan&) = default;
};

/// A combine: a task that waits for one producer on each of several other processors (a
/// reduction of per-processor partial sums), with the tasks after it on its processor that
/// wait for nothing and that another processor waits for (the scalar of a dot product). Run
/// by whichever processor arrives last (its own, or a producer's right after the producer
/// ran) instead of by its own processor after the producers' signals: one hand-off on the
/// critical path instead of two (the producers' to it, its result's back).
struct Combine {
  ProcId home = 0;                  ///< the processor whose program holds the tasks
  std::uint32_t head = 0, end = 0;  ///< its ops [head, end) in that program
  std::uint32_t parties = 0;        ///< arrivals per execution: the producers' processors and home
  friend bool operator==(const Combine&, const Combine&) = default;
};

/// The partition executor's plan: one program per processor, and what the next incremental
/// update compares with.
struct PartitionPlan {
  std::vector<ProcPlan> procs;
  std::vector<Combine> combines;  // add_combines()
  bool program_order = true;      // false: the assignment's explicit order is followed
  std::size_t tasks = 0;
  std::size_t loops = 0;
  // What the next incremental build compares with (by exec task of this plan).
  bool elide = true;
  std::vector<StableKey> keys;
  std::vector<LoopId> task_loop;
  std::vector<ProcId> proc;
  std::vector<std::int64_t> pos;    // position in its processor's ops
  std::vector<TaskId> breaks;       // by loop: its break task
  Csr intra, carried;               // predecessors along intra-step and loop-carried edges
  std::uint32_t rebuilt_procs = 0;  // processors whose wait points this build computed
  // Partition-guided stealing (add_steal(); PartitionOptions::steal), by exec task: whether
  // a thread other than its processor's may run it (1), and every execution it needs
  // before it runs, on any processor (steal_waits[steal_begin[t], steal_begin[t + 1])).
  std::vector<std::uint8_t> stealable;
  std::vector<std::uint32_t> steal_begin;
  std::vector<WaitPoint> steal_waits;
};

/// The one wait-readiness rule: how many executions of `w.producer` (this step) a task in
/// iteration `iter` of its loop (0 outside loops) needs before it runs; 0: none.
/// `loop_iterations` is, for kAfterLoop, the iterations the producer's loop ran (known once
/// its break task decided to stop; the wait also needs that decision).
constexpr std::uint32_t needed_executions(const WaitPoint& w, std::uint32_t iter,
                                          std::uint32_t loop_iterations) {
  switch (w.kind) {
    case WaitKind::kOnce:
      return 1;
    case WaitKind::kSameIter:
      return iter + 1;
    case WaitKind::kPrevIter:
      return iter;  // nothing in iteration 0
    case WaitKind::kAfterLoop:
      return loop_iterations;
  }
  return 1;
}

/// The programs of two plans are the same (ops, waits, owned data, order mode).
bool same_programs(const PartitionPlan& a, const PartitionPlan& b);

/// Builds the per-processor programs of `x` on `k` processors from scratch: each processor
/// runs its tasks in the assignment's explicit order when `use_order` and the assignment has
/// one (program order otherwise); `elide`: PartitionOptions::elide_waits.
PartitionPlan build_plan(const ExecGraph& x, std::uint32_t k, bool use_order, bool elide);

/// Builds the same plan as build_plan() from `prev`, the plan of an earlier exec graph,
/// keeping the wait points of every processor whose program and dependencies did not change
/// (PartitionPlan::rebuilt_procs counts the others).
PartitionPlan update_plan(const ExecGraph& x, const PartitionPlan& prev, std::uint32_t k,
                          bool use_order, bool elide);

/// The steps of build_plan(), which update_plan() also uses. Step 1: the ops of every
/// processor, each task's position, and what a later update compares with.
void build_ops(const ExecGraph& x, std::uint32_t k, bool use_order, bool elide,
               PartitionPlan& plan);
/// Step 2: processor p's wait points (needs plan.intra and plan.carried).
void build_waits(const ExecGraph& x, ProcId p, PartitionPlan& plan);
/// Step 3: signal flags and first-touch owners.
void finish_plan(const ExecGraph& x, PartitionPlan& plan);

/// Marks the combines of a finished plan (Combine; the threaded executor's option
/// PartitionOptions::combine): every task op whose waits name one producer on each of
/// other processors, all in its own loop iteration (or all outside loops), becomes a head,
/// each producer an offer, when every producer's processor, between two of its offers,
/// waits for something its home runs at or after the head (so that the arrivals of one
/// iteration all come before those of the next). Needs elided waits (plan.elide); the
/// serial twin ignores the roles.
void add_combines(const ExecGraph& x, PartitionPlan& plan);

/// Marks the tasks of a finished plan that another thread may run out of their processor's
/// order (PartitionOptions::steal; after add_combines()): every task op but a loop's break
/// task and the tasks of a combine (heads, offers and the tasks after a head). Lists each
/// one's full dependencies as wait points, none elided: every intra-step and loop-carried
/// predecessor, on its own processor too, and, for each datum it writes cumulatively, the
/// previous cumulative writer of that datum in its processor's order within the same loop
/// region (CW writers of one datum or temporary have no edge between them: program order
/// alone fixes the order of their additions, which a thief must keep). Needs k >= 2.
void add_steal(const ExecGraph& x, PartitionPlan& plan);

}  // namespace tgraph::replay::detail
