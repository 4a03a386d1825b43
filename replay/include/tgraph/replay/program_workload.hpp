// SPDX-License-Identifier: MIT
// The workload of a live run: the engine's own bodies and loop conditions of a step recorded
// in deferred mode, with cumulative writes redirected to the lowering's temporaries.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

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
};

}  // namespace tgraph::replay
