// SPDX-License-Identifier: MIT
// Internal: the write/sync/rename sequence of all-or-nothing outputs (file_util.cpp), shared
// by write_file_atomic and the streaming TraceWriter (trace_io.cpp).
#pragma once

#include <string>
#include <string_view>

namespace tgraph::detail {

/// Writes all of `bytes` to descriptor `fd` (short writes and EINTR retried); throws
/// tgraph::Error("NAME: cannot write: REASON").
void write_all(int fd, std::string_view bytes, const std::string& name);

/// Makes the file written through `fd` at `from` the file `to`: fsync (the data reach the
/// disk before the rename exposes them), close, rename. `fd` is closed in every case; throws
/// tgraph::Error("NAME: cannot sync|close: ...") or ("TO: cannot rename FROM_LABEL into
/// place: ..."), leaving `from` in place.
void sync_close_rename(int fd, const std::string& from, const std::string& to,
                       const std::string& name, const std::string& from_label);

}  // namespace tgraph::detail
