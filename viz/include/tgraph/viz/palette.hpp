// SPDX-License-Identifier: MIT
// Colour-blind-safe colours shared by every picture: processors, task kinds, highlights.
#pragma once

#include <cstdint>
#include <string>

namespace tgraph::viz {

/// Okabe & Ito (2008) colours, safe for the common colour-vision deficiencies.
/// Processors use the six light-to-mid tones; vermillion marks what crosses processors.
inline constexpr const char* kCrossColour = "#D55E00";  ///< vermillion: cross-processor edges
inline constexpr const char* kInkColour = "#000000";    ///< black: critical path
inline constexpr const char* kNeutralFill = "#E8E8E8";  ///< no processor known
inline constexpr const char* kWaitFill = "#9E9E9E";     ///< waits in timelines (hatched)

/// Fill colour of processor `p`: Okabe-Ito orange, sky blue, bluish green, yellow, blue,
/// reddish purple, then the same six lightened for p >= 6 (labels carry "p<N>" as well,
/// so colour is never the only cue).
std::string processor_colour(std::uint32_t p);

/// Colour of the i-th task kind (kinds ranked by total time): Paul Tol's "muted" scheme,
/// nine colours; i >= 9 gets pale grey ("other kinds").
std::string kind_colour(std::uint32_t i);
/// Number of distinct kind colours before "other".
inline constexpr std::uint32_t kKindColours = 9;

/// Black or white, whichever reads better on `fill` ("#RRGGBB").
std::string text_colour_on(const std::string& fill);

}  // namespace tgraph::viz
