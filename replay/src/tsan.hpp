// SPDX-License-Identifier: MIT
// Internal: ThreadSanitizer annotations for the synchronisation that happens inside
// uninstrumented libraries (oneTBB's task hand-off, libgomp's barriers), so that the
// happens-before those libraries provide is visible to TSan. No-ops in normal builds.
#pragma once

#if defined(__SANITIZE_THREAD__)
#include <sanitizer/tsan_interface.h>
#define TGRAPH_TSAN_RELEASE(addr) __tsan_release(const_cast<void*>(static_cast<const void*>(addr)))
#define TGRAPH_TSAN_ACQUIRE(addr) __tsan_acquire(const_cast<void*>(static_cast<const void*>(addr)))
#else
#define TGRAPH_TSAN_RELEASE(addr) ((void)(addr))
#define TGRAPH_TSAN_ACQUIRE(addr) ((void)(addr))
#endif
