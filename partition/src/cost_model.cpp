// SPDX-License-Identifier: MIT
#include "tgraph/partition/cost_model.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"

namespace tgraph::partition {

CostModel CostModel::ideal() { return CostModel{0.0, 0.0, "ideal", 0.0, 0.0, 0.0}; }

// Defaults: the middle of the 70-150 ns a cross-core spin handoff takes on current x86
// servers (`tgraph calibrate` measures it) and 0.05 ns/byte (20 GB/s cross-core).
CostModel CostModel::defaults() { return CostModel{}; }

std::string default_calibration_path() {
  if (const char* xdg = std::getenv("XDG_CONFIG_HOME"); xdg != nullptr && *xdg != '\0')
    return std::string(xdg) + "/tgraph/calibration.json";
  if (const char* home = std::getenv("HOME"); home != nullptr && *home != '\0')
    return std::string(home) + "/.config/tgraph/calibration.json";
  return "calibration.json";
}

CostModel select_cost_model(const std::string& model, const std::string& calibration) {
  if (model == "ideal") return CostModel::ideal();
  if (!calibration.empty()) return load_calibration(calibration);
  const std::string def = default_calibration_path();
  std::error_code ec;
  if (std::filesystem::exists(def, ec)) return load_calibration(def);
  return CostModel::defaults();
}

CostModel load_calibration(const std::string& path) {
  const std::vector<std::uint8_t> bytes = read_file_bytes(path);
  CostModel m = parse_calibration(
      std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), path);
  m.source = path;
  return m;
}

CostModel parse_calibration(std::string_view text, const std::string& name) {
  // A calibration file is a few hundred bytes: anything far larger or deeper is not one.
  constexpr std::size_t kMaxBytes = std::size_t{1} << 20;
  constexpr int kMaxDepth = 64;
  if (text.size() > kMaxBytes)
    throw InputError(name, kMaxBytes,
                     "expected a calibration file of at most 1 MiB, found " +
                         std::to_string(text.size()) + " bytes");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(
        text.begin(), text.end(), [&](int depth, nlohmann::json::parse_event_t, nlohmann::json&) {
          if (depth > kMaxDepth)
            throw InputError(name, std::nullopt,
                             "expected a JSON calibration object, found values nested more than " +
                                 std::to_string(kMaxDepth) + " deep");
          return true;
        });
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte is the 1-based position of the offending byte.
    throw InputError(name, e.byte > 0 ? std::optional<std::uint64_t>(e.byte - 1) : std::nullopt,
                     "expected a JSON calibration object (malformed JSON)");
  } catch (const nlohmann::json::out_of_range& e) {
    // A number beyond double range ("1e400"): nlohmann reports it without an offset.
    const std::string what = e.what();
    const auto at = what.find("] ");
    throw InputError(name, std::nullopt,
                     "expected numbers within double range, found a " +
                         (at == std::string::npos ? what : what.substr(at + 2)));
  }
  auto number = [&](const char* key) {
    if (!j.is_object() || !j.contains(key) || !j[key].is_number())
      throw InputError(name, std::nullopt, std::string("expected a number under \"") + key + "\"");
    const double v = j[key].get<double>();
    if (!std::isfinite(v) || v < 0 || v > 1e9)
      throw InputError(name, std::nullopt,
                       std::string("expected \"") + key + "\" in [0, 1e9], found " + j[key].dump());
    return v;
  };
  CostModel m;
  m.sync_latency_ns = number("sync_latency_ns");
  m.per_byte_ns = number("per_byte_ns");
  // Inter-node fields are optional: files written before they existed keep their meaning.
  if (j.contains("mpi_latency_ns")) m.mpi_latency_ns = number("mpi_latency_ns");
  if (j.contains("mpi_per_byte_ns")) m.mpi_per_byte_ns = number("mpi_per_byte_ns");
  if (j.contains("task_overhead_ns")) m.task_overhead_ns = number("task_overhead_ns");
  if (j.contains("mpi_message_overhead_ns"))
    m.mpi_message_overhead_ns = number("mpi_message_overhead_ns");
  m.source = name;
  return m;
}

std::string calibration_json(const Calibration& c) {
  nlohmann::json j;
  j["sync_latency_ns"] = c.sync_latency_ns;
  j["per_byte_ns"] = c.per_byte_ns;
  j["cpus"] = {c.cpu_a, c.cpu_b};
  j["rounds"] = c.rounds;
  j["buffer_bytes"] = c.buffer_bytes;
  j["tgraph_version"] = TGRAPH_VERSION;
  return j.dump(2) + "\n";
}

std::string save_calibration(const Calibration& c, const std::string& path) {
  const std::string out = path.empty() ? default_calibration_path() : path;
  const std::filesystem::path parent = std::filesystem::path(out).parent_path();
  std::error_code ec;  // a failure shows in the write below, naming the file
  if (!parent.empty()) std::filesystem::create_directories(parent, ec);
  write_file_atomic(out, calibration_json(c));
  return out;
}

std::string calibration_report(const Calibration& c, const std::string& path, bool json) {
  if (json) {
    const nlohmann::json j = {{"sync_latency_ns", c.sync_latency_ns},
                              {"per_byte_ns", c.per_byte_ns},
                              {"cpus", {c.cpu_a, c.cpu_b}},
                              {"output", path}};
    return j.dump() + "\n";
  }
  char line[256];
  std::snprintf(line, sizeof line,
                "signal/wait latency %.1f ns, transfer %.4f ns/byte (CPUs %d and %d)\n",
                c.sync_latency_ns, c.per_byte_ns, c.cpu_a, c.cpu_b);
  return line + ("wrote " + path + "\n");
}

}  // namespace tgraph::partition
