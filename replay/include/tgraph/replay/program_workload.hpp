// SPDX-License-Identifier: MIT
// The workload of a live run: the engine's own bodies and loop conditions of a step recorded
// in deferred mode, with cumulative writes redirected to the lowering's temporaries.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "tgraph/graph/access_check.hpp"
#include "tgraph/graph/cumulative.hpp"
#include "tgraph/replay/workload.hpp"

namespace tgraph::replay {

/// Runs the bodies and loop conditions of a deferred step. CW writers whose datum has an
/// Accumulator and whose write the lowering redirected to a temporary run with that
/// redirection installed (tgraph::accumulate), and reducers add the temporaries into the
/// datum in the lowering's fixed order; CW groups of data without one are serialised.
class ProgramWorkload : public Workload {
 public:
  /// `accumulators` by datum (nullptr: not reducible); empty: none is.
  ProgramWorkload(std::span<const std::function<void()>> bodies,
                  std::span<const std::function<bool()>> conditions,
                  std::span<const Accumulator* const> accumulators = {});
  ProgramWorkload() = default;
  /// The next step's bodies (same structure: the plan and its temporaries are kept).
  void set_program(std::span<const std::function<void()>> bodies,
                   std::span<const std::function<bool()>> conditions,
                   std::span<const Accumulator* const> accumulators = {});
  /// Verifies accesses (`--verify-accesses`): every body then runs under `checker` (its
  /// storage set by datum of the step, synced before each step by the caller), one at a
  /// time whatever the executor's threads, and what it finds goes to `findings`, named by
  /// the task's key. Reads are checked in a loop's first two iterations and every 8th.
  /// Needs CwMode::kSerialize (no temporaries: a body that runs twice must write the datum
  /// itself). nullptr: off (the default; one untaken branch per task).
  void set_access_checker(AccessChecker* checker, AccessFindings* findings) {
    checker_ = checker;
    findings_ = findings;
  }
  void bind(const ExecGraph& exec) override;
  bool needs_touch(DatumId d) const override;
  void first_touch(DatumId d) override;
  const std::vector<bool>* reducible() const override { return &reducible_; }
  void run(const TaskRun& r) override;
  bool stop_after(LoopId loop, std::uint32_t iteration) override;

 private:
  std::span<const std::function<void()>> bodies_;
  std::span<const std::function<bool()>> conditions_;
  std::span<const Accumulator* const> accumulators_;
  std::vector<bool> reducible_;  // by original datum
  const ExecGraph* exec_ = nullptr;
  std::vector<std::shared_ptr<void>> temps_;  // by exec datum (temporaries only)
  std::vector<std::uint8_t> redirected_;      // by exec task: writes a temporary
  AccessChecker* checker_ = nullptr;           // set_access_checker
  AccessFindings* findings_ = nullptr;
  void checked_run(const TaskRun& r);
  bool checked_stop_after(LoopId loop);
};

}  // namespace tgraph::replay
