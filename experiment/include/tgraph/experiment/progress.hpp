// SPDX-License-Identifier: MIT
// Progress of an experiment on stderr: one line per finished run, and a progress bar below
// them when the stream is a terminal.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdio>
#include <string>

namespace tgraph::experiment {

/// Reports the runs of an experiment as they finish.
///
///   Progress p(stderr, Progress::is_terminal(stderr));
///   p.set_total(14);
///   p.begin("bars64 owner K=2");
///   p.end("bars64 owner K=2: live 1.85x");   // "[ 1/14  12s] bars64 owner K=2: live 1.85x"
class Progress {
 public:
  /// `out` nullptr: silent. `bar`: redraw a bar line under the run lines (a terminal).
  Progress(std::FILE* out, bool bar);
  /// True when `f` is a terminal.
  static bool is_terminal(std::FILE* f);
  /// Runs expected (the bar's 100 %).
  void set_total(std::size_t total) { total_ = total; }
  /// A run starts (the bar shows it).
  void begin(const std::string& what);
  /// The run started last has finished: its line.
  void end(const std::string& line);
  /// A line that is not a run (a phase, a warning).
  void note(const std::string& line);
  /// The experiment is over: removes the bar.
  void finish();
  /// Runs finished so far.
  std::size_t done() const { return done_; }

 private:
  void clear_bar();
  void draw_bar();
  std::FILE* out_;
  bool bar_;
  std::size_t total_ = 0, done_ = 0;
  std::string current_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace tgraph::experiment
