// SPDX-License-Identifier: MIT
#include "tgraph/model/cost_model.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"

namespace tgraph::model {

CostModel CostModel::ideal() {
  CostModel m;
  m.sync_latency_ns = 0.0;
  m.per_byte_ns = 0.0;
  m.source = "ideal";
  m.mpi_latency_ns = 0.0;
  m.mpi_per_byte_ns = 0.0;
  m.task_overhead_ns = 0.0;
  m.mpi_message_overhead_ns = 0.0;
  return m;
}

namespace {

// A curve's value at `x` processors: from (1, `at_one`) to its first point, linear between
// points, beyond the last the last.
double curve_at(const std::vector<ThreadsPoint>& curve, double x, double at_one) {
  double x0 = 1.0, y0 = at_one;
  for (const ThreadsPoint& p : curve) {
    const double x1 = p.threads, y1 = p.value;
    if (x <= x1) return x1 <= x0 ? y1 : y0 + (y1 - y0) * (x - x0) / (x1 - x0);
    x0 = x1;
    y0 = y1;
  }
  return y0;
}

}  // namespace

double CostModel::inflation_at(double busy) const {
  if (inflation.empty() || busy <= 1.0) return 1.0;
  return curve_at(inflation, busy, 1.0);
}

double CostModel::compute_inflation_at(double busy) const {
  if (compute_inflation.empty() || busy <= 1.0) return 1.0;
  return curve_at(compute_inflation, busy, 1.0);
}

double CostModel::task_inflation(double busy, double cost_ns, double bytes) const {
  if (inflation_ns_per_byte <= 0 || cost_ns <= 0) return inflation_at(busy);
  const double memory = std::min(cost_ns, bytes * inflation_ns_per_byte);
  return (memory * inflation_at(busy) + (cost_ns - memory) * compute_inflation_at(busy)) / cost_ns;
}

const ThreadInterruptions* CostModel::interruptions_at(std::uint32_t k, std::uint32_t p) const {
  if (interruptions.empty()) return nullptr;
  const InterruptionsPoint* at = &interruptions.front();
  for (const InterruptionsPoint& q : interruptions)
    if (q.threads <= k) at = &q;
  if (at->cpus.empty()) return nullptr;
  const ThreadInterruptions& t = at->cpus[p % at->cpus.size()];
  return t.lost > 0 && !t.lengths_ns.empty() ? &t : nullptr;
}

double CostModel::executor_overhead_at(std::uint32_t k) const {
  if (executor_overhead.empty() || k <= 1) return 0.0;
  return curve_at(executor_overhead, k, 0.0);
}

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

std::vector<std::uint64_t> serial_work(const std::string& live,
                                       std::optional<std::uint64_t> serial_ns, std::size_t steps) {
  if (serial_ns) return std::vector<std::uint64_t>(steps, *serial_ns);
  if (live.empty()) return {};
  std::vector<std::uint64_t> v = load_serial_work(live);
  if (v.size() < steps)
    throw OptionError("live", live + ": the run has " + std::to_string(v.size()) +
                                  " steps, the trace " + std::to_string(steps));
  v.resize(steps);
  return v;
}

std::vector<std::uint64_t> SerialWork::per_step(std::size_t steps) const {
  return serial_work(live, serial_ns, steps);
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
  // A list of {"threads": K, <value>: v} sorted by K, each K in [1, 65536] once.
  auto curve = [&](const char* key, const char* value_key, double min_value) {
    std::vector<ThreadsPoint> out;
    const nlohmann::json& list = j[key];
    const std::string what =
        std::string("expected \"") + key + "\" as a list of {\"threads\": K, \"" + value_key +
        "\": v} with K rising from 1 and v in [" + (min_value > 0 ? "0.001" : "0") + ", 1e9]";
    if (!list.is_array() || list.size() > 1024) throw InputError(name, std::nullopt, what);
    for (const nlohmann::json& e : list) {
      if (!e.is_object() || !e.contains("threads") || !e["threads"].is_number_integer() ||
          !e.contains(value_key) || !e[value_key].is_number())
        throw InputError(name, std::nullopt, what + ", found " + e.dump());
      const auto k = e["threads"].get<std::int64_t>();
      const double v = e[value_key].get<double>();
      if (k < 1 || k > 65536 || !std::isfinite(v) || v < min_value || v > 1e9 ||
          (!out.empty() && static_cast<std::uint32_t>(k) <= out.back().threads))
        throw InputError(name, std::nullopt, what + ", found " + e.dump());
      out.push_back({static_cast<std::uint32_t>(k), v});
    }
    return out;
  };
  CostModel m;
  // Files written before "spin_handoff_ns" existed have only "sync_latency_ns" (the same
  // measurement); either names the spinning hand-off.
  m.sync_latency_ns =
      j.is_object() && !j.contains("sync_latency_ns") && j.contains("spin_handoff_ns")
          ? number("spin_handoff_ns")
          : number("sync_latency_ns");
  m.per_byte_ns = number("per_byte_ns");
  // The terms of issue 39 are optional: an older file predicts as it did.
  if (j.contains("park_wake_ns")) m.park_wake_ns = number("park_wake_ns");
  if (j.contains("spin_budget_ns")) m.spin_budget_ns = number("spin_budget_ns");
  if (j.contains("inflation")) m.inflation = curve("inflation", "factor", 0.001);
  if (j.contains("compute_inflation"))
    m.compute_inflation = curve("compute_inflation", "factor", 0.001);
  if (j.contains("inflation_ns_per_byte"))
    m.inflation_ns_per_byte = number("inflation_ns_per_byte");
  if (j.contains("reduction")) m.reduction = curve("reduction", "ns", 0.0);
  if (j.contains("executor_overhead")) m.executor_overhead = curve("executor_overhead", "ns", 0.0);
  if (j.contains("interruptions")) {
    const std::string what =
        "expected \"interruptions\" as a list of {\"threads\": K, \"cpus\": [{\"lost\": "
        "share in [0, 0.5], \"lengths_ns\": [ns in [0, 1e9], ...]}, ...]} with K rising from 1";
    const nlohmann::json& list = j["interruptions"];
    if (!list.is_array() || list.size() > 1024) throw InputError(name, std::nullopt, what);
    for (const nlohmann::json& e : list) {
      const auto bad = [&] { return InputError(name, std::nullopt, what + ", found " + e.dump()); };
      if (!e.is_object() || !e.contains("threads") || !e["threads"].is_number_integer() ||
          !e.contains("cpus") || !e["cpus"].is_array() || e["cpus"].size() > 65536)
        throw bad();
      const auto k = e["threads"].get<std::int64_t>();
      if (k < 1 || k > 65536 ||
          (!m.interruptions.empty() &&
           static_cast<std::uint32_t>(k) <= m.interruptions.back().threads))
        throw bad();
      InterruptionsPoint point{static_cast<std::uint32_t>(k), {}};
      for (const nlohmann::json& c : e["cpus"]) {
        if (!c.is_object() || !c.contains("lost") || !c["lost"].is_number() ||
            !c.contains("lengths_ns") || !c["lengths_ns"].is_array() ||
            c["lengths_ns"].size() > 1024)
          throw bad();
        ThreadInterruptions t;
        t.lost = c["lost"].get<double>();
        if (!std::isfinite(t.lost) || t.lost < 0 || t.lost > 0.5) throw bad();
        for (const nlohmann::json& x : c["lengths_ns"]) {
          if (!x.is_number()) throw bad();
          const double v = x.get<double>();
          if (!std::isfinite(v) || v < 0 || v > 1e9) throw bad();
          t.lengths_ns.push_back(v);
        }
        point.cpus.push_back(std::move(t));
      }
      m.interruptions.push_back(std::move(point));
    }
  }
  // Inter-node fields are optional: files written before they existed keep their meaning.
  if (j.contains("mpi_latency_ns")) m.mpi_latency_ns = number("mpi_latency_ns");
  if (j.contains("mpi_per_byte_ns")) m.mpi_per_byte_ns = number("mpi_per_byte_ns");
  if (j.contains("task_overhead_ns")) m.task_overhead_ns = number("task_overhead_ns");
  if (j.contains("mpi_message_overhead_ns"))
    m.mpi_message_overhead_ns = number("mpi_message_overhead_ns");
  m.source = name;
  return m;
}

std::vector<std::uint64_t> load_serial_work(const std::string& path) {
  const std::vector<std::uint8_t> bytes = read_file_bytes(path);
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(bytes.begin(), bytes.end());
  } catch (const nlohmann::json::exception&) {
    throw InputError(path, std::nullopt, "expected a live run's JSON report (malformed JSON)");
  }
  const char* what =
      "expected a live run's JSON report: per_step[] with record_ns, "
      "partition_ns and prepare_ns";
  if (!j.is_object() || !j.contains("per_step") || !j["per_step"].is_array())
    throw InputError(path, std::nullopt, what);
  std::vector<std::uint64_t> out;
  for (const nlohmann::json& s : j["per_step"]) {
    std::int64_t sum = 0;
    for (const char* key : {"record_ns", "partition_ns", "prepare_ns"}) {
      if (!s.is_object() || !s.contains(key) || !s[key].is_number_integer() ||
          s[key].get<std::int64_t>() < 0)
        throw InputError(path, std::nullopt, what);
      sum += s[key].get<std::int64_t>();
    }
    out.push_back(static_cast<std::uint64_t>(sum));
  }
  return out;
}

namespace {

nlohmann::json curve_json(const std::vector<ThreadsPoint>& v, const char* value_key) {
  nlohmann::json out = nlohmann::json::array();
  for (const ThreadsPoint& p : v) out.push_back({{"threads", p.threads}, {value_key, p.value}});
  return out;
}

}  // namespace

std::string calibration_json(const Calibration& c) {
  nlohmann::json j;
  j["sync_latency_ns"] = c.sync_latency_ns;
  j["spin_handoff_ns"] = c.sync_latency_ns;
  j["park_wake_ns"] = c.park_wake_ns;
  j["per_byte_ns"] = c.per_byte_ns;
  j["inflation"] = curve_json(c.inflation, "factor");
  j["inflation_bytes"] = c.inflation_bytes;
  if (!c.compute_inflation.empty()) {
    j["compute_inflation"] = curve_json(c.compute_inflation, "factor");
    j["inflation_ns_per_byte"] = c.inflation_ns_per_byte;
  }
  j["reduction"] = curve_json(c.reduction, "ns");
  if (!c.executor_overhead.empty()) j["executor_overhead"] = curve_json(c.executor_overhead, "ns");
  if (!c.interruptions.empty()) {
    j["interruptions"] = nlohmann::json::array();
    for (const InterruptionsPoint& p : c.interruptions) {
      nlohmann::json cpus = nlohmann::json::array();
      for (const ThreadInterruptions& t : p.cpus)
        cpus.push_back({{"lost", t.lost}, {"lengths_ns", t.lengths_ns}});
      j["interruptions"].push_back({{"threads", p.threads}, {"cpus", cpus}});
    }
  }
  // How far the samples spread: each value above is their median (the inflation's floored
  // at 1); a model built on a figure whose spread is wide predicts no better than that.
  auto spread = [](const Spread& s) {
    return nlohmann::json{{"min", s.min}, {"median", s.median}, {"max", s.max}};
  };
  auto curve_spread = [&spread](const std::vector<CurveSpread>& v) {
    nlohmann::json out = nlohmann::json::array();
    for (const CurveSpread& p : v) {
      out.push_back(spread(p.spread));
      out.back()["threads"] = p.threads;
    }
    return out;
  };
  j["samples"] = c.samples;
  j["spread"] = {{"spin_handoff_ns", spread(c.latency_spread)},
                 {"park_wake_ns", spread(c.park_wake_spread)},
                 {"per_byte_ns", spread(c.per_byte_spread)},
                 {"inflation", curve_spread(c.inflation_spread)},
                 {"compute_inflation", curve_spread(c.compute_inflation_spread)},
                 {"inflation_ns_per_byte", spread(c.inflation_pass_spread)},
                 {"reduction", curve_spread(c.reduction_spread)}};
  if (!c.executor_overhead_spread.empty())
    j["spread"]["executor_overhead"] = curve_spread(c.executor_overhead_spread);
  j["cpus"] = {c.cpu_a, c.cpu_b};
  j["rounds"] = c.rounds;
  j["park_rounds"] = c.park_rounds;
  j["buffer_bytes"] = c.buffer_bytes;
  j["seconds"] = c.seconds;
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
    nlohmann::json j = nlohmann::json::parse(calibration_json(c));
    j["output"] = path;
    return j.dump() + "\n";
  }
  char line[256];
  std::snprintf(line, sizeof line,
                "signal/wait latency %.1f ns spinning, %.1f ns to a parked thread; transfer %.4f "
                "ns/byte (CPUs %d and %d)\n",
                c.sync_latency_ns, c.park_wake_ns, c.per_byte_ns, c.cpu_a, c.cpu_b);
  std::string out = line;
  auto curve_text = [&](const char* title, const std::vector<ThreadsPoint>& v, const char* fmt) {
    out += title;
    for (const ThreadsPoint& p : v) {
      std::snprintf(line, sizeof line, fmt, p.threads, p.value);
      out += line;
    }
    out += "\n";
  };
  curve_text("inflation (threads: factor):", c.inflation, " %u: %.3f");
  if (!c.compute_inflation.empty()) {
    curve_text("compute inflation (threads: factor):", c.compute_inflation, " %u: %.3f");
    std::snprintf(line, sizeof line, "memory body alone: %.4f ns/byte\n", c.inflation_ns_per_byte);
    out += line;
  }
  curve_text("reduction (threads: ns):", c.reduction, " %u: %.0f");
  if (!c.executor_overhead.empty())
    curve_text("executor's time per task (threads: ns):", c.executor_overhead, " %u: %.1f");
  if (!c.interruptions.empty()) {
    out += "time lost to interruptions (threads: % per thread):";
    for (const InterruptionsPoint& p : c.interruptions) {
      std::snprintf(line, sizeof line, " %u:", p.threads);
      out += line;
      for (std::size_t i = 0; i < p.cpus.size(); ++i) {
        std::snprintf(line, sizeof line, "%s%.2f", i == 0 ? " " : "/", 100.0 * p.cpus[i].lost);
        out += line;
      }
    }
    out += "\n";
  }
  // The spread of each figure over the samples, so that a reader sees how far to trust it.
  auto range = [&](const char* what, const Spread& s, const char* fmt) {
    char a[64], b[64];
    std::snprintf(a, sizeof a, fmt, s.min);
    std::snprintf(b, sizeof b, fmt, s.max);
    return std::string(what) + " " + a + "-" + b;
  };
  out += "spread over " + std::to_string(c.samples) +
         " samples: " + range("spinning", c.latency_spread, "%.1f") + " ns, " +
         range("parked", c.park_wake_spread, "%.0f") + " ns, " +
         range("transfer", c.per_byte_spread, "%.4f") + " ns/byte";
  for (const CurveSpread& p : c.inflation_spread) {
    std::snprintf(line, sizeof line, ", inflation at %u %.3f-%.3f", p.threads, p.spread.min,
                  p.spread.max);
    out += line;
  }
  for (const CurveSpread& p : c.compute_inflation_spread) {
    std::snprintf(line, sizeof line, ", compute inflation at %u %.3f-%.3f", p.threads, p.spread.min,
                  p.spread.max);
    out += line;
  }
  for (const CurveSpread& p : c.executor_overhead_spread) {
    std::snprintf(line, sizeof line, ", executor at %u %.1f-%.1f ns", p.threads, p.spread.min,
                  p.spread.max);
    out += line;
  }
  out += "\n";
  std::snprintf(line, sizeof line, "measured in %.1f s\n", c.seconds);
  return out + line + "wrote " + path + "\n";
}

}  // namespace tgraph::model
