// SPDX-License-Identifier: MIT
#include "common.hpp"

#include <algorithm>
#include <ctime>
#include <filesystem>
#include <system_error>

#include "tgraph/graph/error.hpp"

namespace tgraph::experiment::detail {

std::vector<std::string> split_list(std::string_view text) {
  std::vector<std::string> out;
  std::size_t at = 0;
  while (at <= text.size()) {
    const std::size_t comma = std::min(text.find(',', at), text.size());
    out.emplace_back(text.substr(at, comma - at));
    at = comma + 1;
  }
  return out;
}

std::string join(const std::vector<std::string>& v, const char* sep) {
  std::string s;
  for (const std::string& x : v) {
    if (!s.empty()) s += sep;
    s += x;
  }
  return s;
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

void make_results_folder(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw UsageError("--out " + dir + ": cannot create the results folder" +
                     (ec ? " (" + ec.message() + ")" : std::string(" (a file is in the way)")));
}

}  // namespace tgraph::experiment::detail
