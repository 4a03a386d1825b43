// SPDX-License-Identifier: MIT
// The Standard Task Graph Set files under tests/data/stg (TGRAPH_TEST_DATA), sorted.
#pragma once

#include <algorithm>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

namespace tgraph::test {

/// Paths of the .stg files of tests/data/stg/50 and tests/data/stg/100, sorted.
inline std::vector<std::string> stg_files() {
  std::vector<std::string> files;
  for (const char* dir : {"50", "100"}) {
    const std::filesystem::path p = std::filesystem::path(TGRAPH_TEST_DATA) / "stg" / dir;
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(p, ec))
      if (e.path().extension() == ".stg") files.push_back(e.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace tgraph::test
