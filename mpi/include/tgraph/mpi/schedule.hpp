// SPDX-License-Identifier: MIT
// What one step does across MPI ranks: which task instances each processor runs, what each
// waits for, which datum versions travel between ranks. A pure function of the lowered step,
// the layout and where each datum's latest version lies (testable without MPI).
#pragma once

#include <cstdint>
#include <limits>
#include <map>
#include <tuple>
#include <vector>

#include "tgraph/graph/lowering.hpp"
#include "tgraph/graph/step_graph.hpp"

namespace tgraph::mpi {

inline constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

/// Ranks and threads: processor p lives on rank p / threads_per_rank, thread p % that.
struct Layout {
  std::uint32_t ranks = 1;
  std::uint32_t threads_per_rank = 1;
  std::uint32_t rank_of(ProcId p) const { return p / threads_per_rank; }
  std::uint32_t processors() const { return ranks * threads_per_rank; }
};

/// Bytes one datum version takes on the wire: its recorded size in whole 8-byte words (the
/// synthetic buffer that carries the value), at least 1 byte.
std::uint64_t wire_bytes(const Datum& d);

/// Bytes of one loop decision on the wire (continue flag and the decider's clock).
inline constexpr std::uint64_t kDecisionBytes = 16;

/// Messages and bytes per ordered rank pair (index from * ranks + to).
struct Traffic {
  std::uint32_t ranks = 1;
  std::vector<std::uint64_t> messages, bytes;  ///< datum versions (entering ones included)
  std::vector<std::uint64_t> decisions;        ///< loop decisions (kDecisionBytes each)
  std::uint64_t entering_messages = 0;         ///< versions from before the step (also in messages)
  std::uint64_t entering_bytes = 0;
  explicit Traffic(std::uint32_t r = 1)
      : ranks(r), messages(r * r, 0), bytes(r * r, 0), decisions(r * r, 0) {}
  std::uint64_t total_messages() const;
  std::uint64_t total_bytes() const;
  std::uint64_t total_decisions() const;
  void add(const Traffic& o);
  friend bool operator==(const Traffic&, const Traffic&) = default;
};

/// Which ranks hold the latest version of each datum (by datum, ranks bits in a vector).
struct Holders {
  std::uint32_t ranks = 1;
  std::vector<std::uint8_t> has;  ///< has[d * ranks + r]
  bool holds(DatumId d, std::uint32_t r) const { return has[d * ranks + r] != 0; }
  /// The lowest rank holding d.
  std::uint32_t first(DatumId d) const;
  /// Every rank holds data [from, n) (initial contents, the same everywhere).
  void grow(std::size_t n, std::size_t from);
};

/// A persistent channel: one (source task or step start, datum or loop, destination rank),
/// reused for every version it carries. Its index is its MPI tag.
struct Channel {
  bool decision = false;
  TaskId source = kNoTask;  ///< producing exec task (kNoTask: the step start; loop decider)
  std::uint32_t what = 0;   ///< datum (data) or loop (decision)
  std::uint32_t from = 0, to = 0;
  std::uint64_t bytes = 0;
};

/// Channels of one plan (lowered structure + assignment), grown step by step in the same
/// order on every rank.
class ChannelTable {
 public:
  std::uint32_t get(const Channel& c);
  const std::vector<Channel>& channels() const { return channels_; }

 private:
  std::vector<Channel> channels_;
  std::map<std::tuple<bool, TaskId, std::uint32_t, std::uint32_t, std::uint32_t>, std::uint32_t>
      index_;
};

/// What a task instance waits for before it runs.
enum class WaitKind : std::uint8_t { kInstance, kMessage, kDecision };
struct Wait {
  WaitKind kind = WaitKind::kInstance;
  std::uint32_t index = 0;  ///< instance, message or decision
};

/// One task of the lowered step in one loop iteration.
struct Instance {
  TaskId task = 0;
  std::uint32_t iteration = 0;
  ProcId proc = 0;
  std::vector<Wait> waits;
  std::vector<std::uint32_t> sends;  ///< messages sent once it has run
  std::uint32_t decision = kNone;    ///< the decision it makes (a loop's break task)
};

/// One datum version sent to one rank.
struct Message {
  std::uint32_t channel = 0;
  std::uint32_t source = kNone;  ///< instance that produced it (kNone: from before the step)
  DatumId datum = 0;
  std::uint32_t from = 0, to = 0;
  std::uint64_t bytes = 0;
  bool zero_after_send = false;        ///< a temporary: the sender's copy is reset (the reducer's)
  std::vector<std::uint32_t> hazards;  ///< instances on `to` that must end before install
};

/// One loop iteration's decision, sent to the other ranks that run part of the body.
struct Decision {
  LoopId loop = 0;
  std::uint32_t iteration = 0;
  bool stop = false;  ///< what the recorded iteration count says
  std::uint32_t from = 0;
  std::vector<std::uint32_t> to;
  std::vector<std::uint32_t> channels;  ///< by entry of `to`
};

/// An item of a processor's program: run an instance, or wait for a loop decision.
struct ProgramItem {
  bool decision = false;
  std::uint32_t index = 0;
};

/// One step, unrolled (each loop its recorded iteration count; the decisions still travel).
struct StepSchedule {
  std::vector<Instance> instances;  ///< in sequential order
  std::vector<Message> messages;
  std::vector<std::uint32_t> entering;  ///< messages sent at the step's start
  std::vector<Decision> decisions;
  std::vector<std::vector<ProgramItem>> programs;  ///< by processor
  Traffic traffic;
  Holders holders_after;  ///< who holds each original datum's latest version afterwards
};

/// The schedule of lowered step `x` (from `step`, whose loops give the iteration counts)
/// for `layout`, given who holds each datum's latest version before it (`before`, sized
/// for at least the step's original data; missing data count as held everywhere).
/// Channels are taken from (and added to) `channels`.
StepSchedule schedule_step(const ExecGraph& x, const StepGraph& step, const Layout& layout,
                           const Holders& before, ChannelTable& channels);

/// The traffic that schedule_step predicts (the prediction `tgraph-mpi replay` compares with
/// what it sent).
Traffic predict_traffic(const ExecGraph& x, const StepGraph& step, const Layout& layout,
                        const Holders& before);

/// Holders of `data` data with every rank holding everything (a trace's start).
Holders everywhere(std::size_t data, std::uint32_t ranks);

}  // namespace tgraph::mpi
