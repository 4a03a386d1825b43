// SPDX-License-Identifier: MIT
// Whole-file reads and all-or-nothing writes.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace tgraph {

/// Reads a whole file; throws InputError("cannot open ...") naming it.
std::vector<std::uint8_t> read_file_bytes(const std::string& path);
/// read_file_bytes as text (JSON, CSV and other text inputs).
std::string read_file_text(const std::string& path);
/// Writes `content` to `path` through a temporary file in the same folder renamed into
/// place, so that a failure never leaves a half-written output. The bytes go to an unnamed
/// file (O_TMPFILE) where the file system has them, named ".NAME.tmp.N" only for the rename,
/// so that a process killed while it writes leaves no temporary file either (elsewhere a
/// named temporary file from the start). Throws tgraph::Error.
void write_file_atomic(const std::string& path, std::string_view content);
/// write_file_atomic, or `content` on standard output when `path` is empty or "-".
void write_output(const std::string& path, std::string_view content);

}  // namespace tgraph
