// SPDX-License-Identifier: MIT
// Runs the `tgraph` binary of this build in a folder: exit status, standard output and error.
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace tgraph::test {

/// What one run of the binary left.
struct CliResult {
  int code = -1;  ///< exit status, or 128 + the signal that ended it
  std::string out;
  std::string err;
};

/// The whole of file `p` (empty when it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

/// `tgraph ARGS` run from `dir` (its output files are written there).
inline CliResult run_tgraph(const std::filesystem::path& dir, const std::string& args) {
  const std::filesystem::path out = dir / "stdout", err = dir / "stderr";
  const std::string cmd = std::string("cd '") + dir.string() + "' && '" + TGRAPH_BIN + "' " +
                          args + " >'" + out.string() + "' 2>'" + err.string() + "'";
  const int status = std::system(cmd.c_str());
  CliResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

}  // namespace tgraph::test
