// SPDX-License-Identifier: MIT
#include "tgraph/version.hpp"

namespace tgraph {

std::string_view linked_version() noexcept { return kVersionString; }

}  // namespace tgraph
