// SPDX-License-Identifier: MIT
// Internal: the one pinning rule every policy follows (ExecOptions::pin): the thread of slot p
// runs on the p-th processing unit in "one PU per core first" order (pinned_pu(p)), bound once
// for as long as it keeps that slot.
#pragma once

#include <cstdint>

namespace tgraph::replay::detail {

/// Applies the rule to the calling thread for slot `slot`: with `pin`, binds it to slot's PU
/// unless it is already bound there (a thread that kept its slot since the last call makes
/// no system call and takes no lock); without, undoes a binding an earlier executor left on
/// it (runtime pool threads outlive executors), else nothing. Returns false if hwloc could
/// not bind (never fails the run).
bool bind_current_thread(bool pin, std::uint32_t slot);

/// The slot the calling thread is bound to by the rule, or -1 when it is not.
std::int64_t bound_slot();

/// hwloc's logical index of slot p's PU (StarPU names CPUs by it), -1 without hwloc.
int pinned_pu_logical(std::uint32_t p);

}  // namespace tgraph::replay::detail
