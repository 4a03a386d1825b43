// SPDX-License-Identifier: MIT
// libFuzzer target: any text given as a scene file builds a scene or gives a tgraph::Error
// naming the file and line. Scenes are capped at a few thousand nodes (SceneOptions::
// max_nodes) so that a large but valid scene is not mistaken for a hang.
#include <cstddef>
#include <cstdint>

#include "fuzz_util.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/samples/scene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  tgraph::samples::SceneOptions options;
  options.max_nodes = 4096;
  try {
    const auto scene =
        tgraph::samples::parse_scene(tgraph::fuzz::as_text(data, size), "fuzz.scene", options);
    if (scene->bodies().empty()) tgraph::fuzz::invariant_failed();
  } catch (const tgraph::Error&) {
  }
  return 0;
}
