// SPDX-License-Identifier: MIT
// A test's own directory under the system's temporary directory.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>

namespace tgraph::test {

/// <tmp>/<prefix><pid>_<test name>, created empty. A parameterised test's name holds a '/'
/// ("Name/param"), which would make a nested directory whose parent removing the test's
/// directory leaves behind: it becomes '_'.
inline std::filesystem::path scratch_dir(const std::string& prefix) {
  std::string name = prefix;
  name += std::to_string(::getpid());
  name += '_';
  name += ::testing::UnitTest::GetInstance()->current_test_info()->name();
  std::replace(name.begin(), name.end(), '/', '_');
  const std::filesystem::path d = std::filesystem::temp_directory_path() / name;
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

}  // namespace tgraph::test
