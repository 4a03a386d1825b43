// SPDX-License-Identifier: MIT
#include "tgraph/viz/palette.hpp"

#include <array>
#include <cmath>
#include <cstdio>

namespace tgraph::viz {
namespace {

struct Rgb {
  int r, g, b;
};

Rgb parse(const std::string& hex) {
  Rgb c{0, 0, 0};
  if (hex.size() == 7 && hex[0] == '#') std::sscanf(hex.c_str() + 1, "%2x%2x%2x", &c.r, &c.g, &c.b);
  return c;
}

std::string format(Rgb c) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "#%02X%02X%02X", c.r & 0xff, c.g & 0xff, c.b & 0xff);
  return buf;
}

// Okabe & Ito, "Color Universal Design" (2008), without black and vermillion.
constexpr std::array<const char*, 6> kProcessors = {"#E69F00", "#56B4E9", "#009E73",
                                                    "#F0E442", "#0072B2", "#CC79A7"};
// Paul Tol, "muted" qualitative scheme (2021).
constexpr std::array<const char*, kKindColours> kKinds = {
    "#CC6677", "#332288", "#DDCC77", "#117733", "#88CCEE",
    "#882255", "#44AA99", "#999933", "#AA4499"};

}  // namespace

std::string processor_colour(std::uint32_t p) {
  const Rgb base = parse(kProcessors[p % kProcessors.size()]);
  // Rounds 1, 2, ... are mixed with white (1/2, 3/4, then 1/2 again): still distinct from
  // the first round, and the label names the processor.
  const std::uint32_t round = p / static_cast<std::uint32_t>(kProcessors.size());
  if (round == 0) return format(base);
  const double keep = round % 2 == 1 ? 0.5 : 0.25;
  auto mix = [keep](int v) { return static_cast<int>(v * keep + 255 * (1 - keep) + 0.5); };
  return format({mix(base.r), mix(base.g), mix(base.b)});
}

std::string kind_colour(std::uint32_t i) { return i < kKinds.size() ? kKinds[i] : "#DDDDDD"; }

std::string text_colour_on(const std::string& fill) {
  const Rgb c = parse(fill);
  // Relative luminance (sRGB approximated by a 2.2 gamma); white text below 0.2.
  auto lin = [](int v) { return std::pow(v / 255.0, 2.2); };
  const double y = 0.2126 * lin(c.r) + 0.7152 * lin(c.g) + 0.0722 * lin(c.b);
  return y < 0.2 ? "#FFFFFF" : "#000000";
}

}  // namespace tgraph::viz
