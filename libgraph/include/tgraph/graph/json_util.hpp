// SPDX-License-Identifier: MIT
// The helpers the modules' JSON writers share (each links nlohmann-json itself; this header is
// for them, not for the data model's users).
#pragma once

#include <nlohmann/json.hpp>
#include <optional>

namespace tgraph {

/// `v` as JSON, null when it holds nothing: how every report writes a figure it may lack.
template <class T>
nlohmann::json optional_json(const std::optional<T>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

}  // namespace tgraph
