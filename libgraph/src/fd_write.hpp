// SPDX-License-Identifier: MIT
// Internal: the write/sync/rename sequence of all-or-nothing outputs (file_util.cpp), shared
// by write_file_atomic and the streaming TraceWriter (trace_write.cpp), and the unnamed file
// the TraceWriter writes its header to before naming it.
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

/// An unnamed file (O_TMPFILE) in the folder of `path`, open for writing; -1 where the file
/// system or the kernel has none.
int open_unnamed_beside(const std::string& path);

/// Gives the unnamed file `fd` the name `path`, replacing a file of that name; false if
/// neither /proc nor linkat(AT_EMPTY_PATH) can name it.
bool name_unnamed(int fd, const std::string& path);

}  // namespace tgraph::detail
