// SPDX-License-Identifier: MIT
#include "common.hpp"

#include <algorithm>
#include <ctime>
#include <filesystem>
#include <optional>
#include <system_error>

#include "tgraph/graph/error.hpp"
#include "tgraph/partition/strategy.hpp"
#include "tgraph/replay/policy.hpp"

namespace tgraph::experiment::detail {

std::vector<std::string> check_methods(const std::vector<std::string>& methods) {
  const std::vector<std::string> strategies = partition::strategy_names();
  std::vector<std::string> out;
  for (const std::string& m : methods) {
    const std::optional<replay::Policy> p = replay::parse_policy(m);
    if (p == replay::Policy::kSequential)
      throw OptionError("methods", "sequential is every run's reference, not a method");
    if (p == replay::Policy::kPartition)
      throw OptionError("methods", "name the partitioning strategy (owner, metis, sticky, ...) "
                                   "instead of partition");
    if (!p && std::find(strategies.begin(), strategies.end(), m) == strategies.end())
      throw OptionError("methods", "unknown method '" + m + "' (expected strategies " +
                                       join(strategies, ", ") + " or baselines " +
                                       replay::policy_list("", true) + ")");
    for (const replay::PolicyInfo& info : replay::policies())
      if (p == info.policy && !info.built)
        throw OptionError("methods", m + " is not in this build (" + std::string(info.missing) +
                                         ")");
    if (std::find(out.begin(), out.end(), m) == out.end()) out.push_back(m);
  }
  return out;
}

measure::LiveOptions live_options(std::uint32_t threads, std::uint32_t steps, std::uint32_t repeat,
                                  bool observe) {
  measure::LiveOptions o;
  o.exec.threads = threads;
  o.steps = steps;
  o.repeat = repeat;
  o.observe = observe;
  return o;
}

std::string join(const std::vector<std::string>& v, const char* sep) {
  std::string s;
  for (const std::string& x : v) {
    if (!s.empty()) s += sep;
    s += x;
  }
  return s;
}

std::string join(const std::vector<std::uint32_t>& v) {
  std::vector<std::string> items;
  for (std::uint32_t x : v) items.push_back(std::to_string(x));
  return join(items);
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
    throw OptionError("out", "cannot create the results folder " + dir +
                                 (ec ? " (" + ec.message() + ")" : " (a file is in the way)"));
}

}  // namespace tgraph::experiment::detail
