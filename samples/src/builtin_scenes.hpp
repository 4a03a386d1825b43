// SPDX-License-Identifier: MIT
// Internal: the built-in scene files, {name, text}, generated from samples/scenes/*.scene into
// the build folder's builtin_scenes.cpp (samples/src/builtin_scenes.cpp.in); read by
// scene_file.cpp.
#pragma once

#include <cstddef>

namespace tgraph::samples::detail {

struct BuiltinScene {
  const char* name;
  const char* text;
};
extern const BuiltinScene kBuiltinScenes[];
extern const std::size_t kBuiltinSceneCount;

}  // namespace tgraph::samples::detail
