// SPDX-License-Identifier: MIT
// Verifying an engine's declared accesses live (`tgraph run --verify-accesses`): its steps
// through the policy's executor with every body run under tgraph::AccessChecker.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "tgraph/graph/access_check.hpp"
#include "tgraph/measure/adapter.hpp"
#include "tgraph/measure/engine.hpp"
#include "tgraph/measure/live.hpp"

namespace tgraph::measure {

/// What a verification found and cost.
struct VerifyResult {
  replay::Policy policy = replay::Policy::kPartition;
  std::uint32_t threads = 1;
  std::uint32_t steps = 0;
  std::vector<AccessFinding> findings;  ///< empty: the declarations hold (as far as seen)
  AccessChecker::Counts counts;
  std::size_t data_checked = 0;    ///< data with storage (the engine's state regions)
  std::int64_t wall_ns = 0;        ///< the verified pass
  std::int64_t plain_wall_ns = 0;  ///< one pass of the uninstrumented engine, for its cost
};

/// Runs `options.steps` steps of a fresh engine under `options.policy` on
/// `options.exec.threads` threads (the partition policy: each recorded structure partitioned
/// by `partitioner`, unit costs) with every task body under an AccessChecker whose storage is
/// the engine's state() (regions matched to data by name); cumulative writes are serialised
/// (CwMode::kSerialize) so that a body can run twice. Bodies run one at a time, inside the
/// workload, whatever the schedule: what is found does not depend on the policy or K.
/// Then one plain pass of a fresh engine, timed, for the cost.
VerifyResult verify_accesses(const EngineFactory& make_engine,
                             const partition::StepPartitioner* partitioner,
                             const LiveOptions& options);

/// verify_accesses for an outside engine (adapter.hpp) under `method` (a strategy under the
/// partition policy, or a baseline), as run_engine_live runs it:
///
///   VerifyResult v = verify_engine_accesses(make, choose_method("owner"), options);
///   for (const AccessFinding& f : v.findings) std::printf("%s\n", to_string(f).c_str());
VerifyResult verify_engine_accesses(const CallbacksFactory& make, const MethodChoice& method,
                                    LiveOptions options);

/// One JSON object: `scene`, `method`, `policy`, `threads`, `steps`, `access_findings` (list
/// of {task, datum, found, declared}), `access_check` ({runs, reruns, reads_unchecked,
/// data_checked}), `wall_ns`, `plain_wall_ns`, `cost` (wall_ns / plain_wall_ns).
std::string verify_json(const VerifyResult& r, const std::string& engine, const std::string& method);
/// The text: a summary line, then one line per finding.
std::string verify_text(const VerifyResult& r, const std::string& engine, const std::string& method);

/// A verification and its report.
struct VerifyRunReport {
  VerifyResult result;
  std::string report;  ///< the JSON line or the text, ready to print
};

/// `tgraph run --verify-accesses`: run.scene (a built-in scene or scene file, or a test
/// engine of make_live_engine: tiled-heat, tiled-heat:wrong-mode, tiled-heat:missing-halo)
/// verified under run.method (default steps: the scene's; 4 for the test engines).
VerifyRunReport verify_scene(const SceneRun& run);

}  // namespace tgraph::measure
