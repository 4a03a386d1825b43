// SPDX-License-Identifier: MIT
#include "tgraph/model/platform.hpp"

#include <charconv>
#include <cstdio>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"

namespace tgraph::model {

namespace {

OptionError not_a_shape(std::string_view whole, std::string_view field) {
  return OptionError(std::string(field), "expected NxC (nodes x cores, e.g. 64x16), found '" +
                                             std::string(whole) + "'");
}

std::uint64_t parse_count(std::string_view text, std::string_view whole, std::string_view field) {
  std::uint64_t v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size())
    throw not_a_shape(whole, field);
  return v;
}

// A SimGrid quantity: the value with full precision and its unit ("100ns", "2e+10Bps").
std::string quantity(double value, const char* unit) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g%s", value, unit);
  return buf;
}

std::string bandwidth(double per_byte_ns) {
  return quantity(per_byte_ns > 0 ? 1e9 / per_byte_ns : 1e18, "Bps");
}

}  // namespace

ClusterShape cluster_shape(std::uint64_t nodes, std::uint64_t cores) {
  if (nodes < 1 || nodes > kMaxNodes)
    throw OptionError(
        "nodes", "expected 1 to " + std::to_string(kMaxNodes) + ", found " + std::to_string(nodes));
  if (cores < 1 || cores > kMaxCores)
    throw OptionError(
        "cores", "expected 1 to " + std::to_string(kMaxCores) + ", found " + std::to_string(cores));
  return {static_cast<std::uint32_t>(nodes), static_cast<std::uint32_t>(cores)};
}

ClusterShape parse_cluster(std::string_view text, std::string_view field) {
  const auto x = text.find_first_of("xX");
  if (x == std::string_view::npos) throw not_a_shape(text, field);
  const std::uint64_t n = parse_count(text.substr(0, x), text, field);
  const std::uint64_t c = parse_count(text.substr(x + 1), text, field);
  if (n < 1 || n > kMaxNodes || c < 1 || c > kMaxCores)
    throw OptionError(std::string(field), "expected 1 to " + std::to_string(kMaxNodes) +
                                              " nodes of 1 to " + std::to_string(kMaxCores) +
                                              " cores, found '" + std::string(text) + "'");
  return {static_cast<std::uint32_t>(n), static_cast<std::uint32_t>(c)};
}

std::string platform_xml(const ClusterShape& c, const CostModel& m) {
  std::string source;  // inside an XML comment: no double hyphen, no markup
  for (char ch : m.source) source += ch == '-' || ch == '<' || ch == '>' || ch == '&' ? '_' : ch;
  std::string config;
  for (std::string_view item : kSimgridNetworkConfig) {
    const auto colon = item.find(':');
    config += "    <prop id=\"" + std::string(item.substr(0, colon)) + "\" value=\"" +
              std::string(item.substr(colon + 1)) + "\"/>\n";
  }
  return "<?xml version='1.0'?>\n"
         "<!DOCTYPE platform SYSTEM \"https://simgrid.org/simgrid.dtd\">\n"
         "<!-- tgraph platform: " +
         std::to_string(c.nodes) + " nodes x " + std::to_string(c.cores) + " cores; costs from " +
         source +
         " -->\n"
         "<platform version=\"4.1\">\n"
         "  <config>\n" +
         config +
         "  </config>\n"
         "  <zone id=\"world\" routing=\"Full\">\n"
         "    <cluster id=\"cluster\" prefix=\"node-\" suffix=\"\" radical=\"0-" +
         std::to_string(c.nodes - 1) + "\" speed=\"1Gf\" core=\"" + std::to_string(c.cores) +
         "\"\n             bw=\"" + bandwidth(m.mpi_per_byte_ns) + "\" lat=\"" +
         quantity(m.mpi_latency_ns / 2, "ns") + "\"\n             loopback_bw=\"" +
         bandwidth(m.per_byte_ns) + "\" loopback_lat=\"" + quantity(m.sync_latency_ns, "ns") +
         "\"/>\n"
         "  </zone>\n"
         "</platform>\n";
}

std::string write_platform(const std::string& output, std::uint64_t nodes, std::uint64_t cores,
                           const std::string& calibration) {
  const ClusterShape c = cluster_shape(nodes, cores);
  const CostModel m = select_cost_model("calibrated", calibration);
  write_file_atomic(output, platform_xml(c, m));
  return "wrote " + output + ": " + std::to_string(c.nodes) + " nodes x " +
         std::to_string(c.cores) + " cores, costs from " + m.source + "\n";
}

}  // namespace tgraph::model
