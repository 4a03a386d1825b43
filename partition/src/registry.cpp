// SPDX-License-Identifier: MIT
// The name -> factory map, filled in this one function (no static self-registration).
#include <functional>
#include <map>
#include <string>

#include "strategies.hpp"
#include "tgraph/graph/error.hpp"

namespace tgraph::partition {

namespace {

using Factory = std::function<std::unique_ptr<Strategy>()>;

const std::map<std::string, Factory, std::less<>>& registry() {
  static const std::map<std::string, Factory, std::less<>> map = {
      {"single", detail::make_single},   // null object: everything on processor 0
      {"roundrobin", detail::make_roundrobin},
      {"random", detail::make_random},
      {"owner", detail::make_owner},
      {"metis", detail::make_metis},
      {"metis-relabel", detail::make_metis_relabel},
      {"scotch", detail::make_scotch},
      {"sticky", detail::make_sticky},
      {"list", detail::make_list},
  };
  return map;
}

}  // namespace

std::unique_ptr<Strategy> make_strategy(std::string_view name) {
  const auto& map = registry();
  if (auto it = map.find(name); it != map.end()) return it->second();
  std::string known;
  for (const auto& [n, f] : map) known += (known.empty() ? "" : ", ") + n;
  throw UsageError("unknown method '" + std::string(name) + "' (known: " + known + ")");
}

std::vector<std::string> strategy_names() {
  std::vector<std::string> names;
  for (const auto& [n, f] : registry()) names.push_back(n);
  return names;
}

}  // namespace tgraph::partition
