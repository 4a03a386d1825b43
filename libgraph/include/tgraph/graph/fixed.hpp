// SPDX-License-Identifier: MIT
// Numbers as the tables, charts and reports print them.
#pragma once

#include <cstdio>
#include <string>

namespace tgraph {

/// `v` with `decimals` digits after the point ("%.*f").
inline std::string fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

}  // namespace tgraph
