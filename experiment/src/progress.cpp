// SPDX-License-Identifier: MIT
#include "tgraph/experiment/progress.hpp"

#include <unistd.h>

#include <algorithm>

namespace tgraph::experiment {

Progress::Progress(std::FILE* out, bool bar)
    : out_(out), bar_(bar && out != nullptr), start_(std::chrono::steady_clock::now()) {}

bool Progress::is_terminal(std::FILE* f) { return f != nullptr && isatty(fileno(f)) == 1; }

void Progress::clear_bar() {
  if (bar_) std::fputs("\r\033[K", out_);
}

void Progress::draw_bar() {
  if (!bar_) return;
  constexpr std::size_t kWidth = 30;
  const std::size_t filled = total_ ? std::min(kWidth, done_ * kWidth / total_) : 0;
  std::string bar(filled, '#');
  bar.resize(kWidth, '.');
  std::fprintf(out_, "[%s] %zu/%zu %s", bar.c_str(), done_, total_, current_.c_str());
  std::fflush(out_);
}

void Progress::begin(const std::string& what) {
  current_ = what;
  if (!bar_) return;
  clear_bar();
  draw_bar();
}

void Progress::end(const std::string& line) {
  ++done_;
  if (out_ == nullptr) return;
  const auto seconds =
      std::chrono::duration_cast<std::chrono::seconds>(std::chrono::steady_clock::now() - start_)
          .count();
  clear_bar();
  const int width = static_cast<int>(std::to_string(std::max(total_, done_)).size());
  std::fprintf(out_, "[%*zu/%zu %4llds] %s\n", width, done_, std::max(total_, done_),
               static_cast<long long>(seconds), line.c_str());
  current_.clear();
  draw_bar();
  std::fflush(out_);
}

void Progress::finish() {
  if (!bar_) return;
  clear_bar();
  std::fflush(out_);
}

void Progress::note(const std::string& line) {
  if (out_ == nullptr) return;
  clear_bar();
  std::fprintf(out_, "%s\n", line.c_str());
  draw_bar();
  std::fflush(out_);
}

}  // namespace tgraph::experiment
