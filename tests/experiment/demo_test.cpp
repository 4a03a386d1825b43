// SPDX-License-Identifier: MIT
// The demo on a tiny scene: its table and report name the cost model of the predictions
// (the defaults, or the calibration file read) and give the report's absolute path.
#include "tgraph/experiment/demo.hpp"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "../scratch_dir.hpp"
#include "tgraph/graph/file_util.hpp"

namespace tgraph::experiment {
namespace {

namespace fs = std::filesystem;

// Sets an environment variable for the scope, then puts back what was there.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    ::setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (old_)
      ::setenv(name_, old_->c_str(), 1);
    else
      ::unsetenv(name_);
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
  std::optional<std::string> old_;
};

DemoResult tiny_demo(const fs::path& out) {
  DemoOptions o;
  o.scene = "fig2";
  o.steps = 2;
  o.threads = 2;
  o.repeat = 1;
  o.out = out.string();
  return run_demo(o);
}

TEST(Demo, NamesTheCostModelOfItsPredictionsAndTheReportsAbsolutePath) {
  const fs::path dir = test::scratch_dir("tgraph_demo_");
  // No calibration file where `tgraph calibrate` writes it: the defaults.
  ScopedEnv config("XDG_CONFIG_HOME", (dir / "config").string());
  {
    const DemoResult r = tiny_demo(dir / "plain");
    EXPECT_EQ(r.cost_model, "defaults");
    EXPECT_EQ(nlohmann::json::parse(demo_json(r))["cost_model"], "defaults");
    const std::string text = demo_text(r);
    EXPECT_NE(text.find("\npredicted: cost model defaults (no calibration file)\n"),
              std::string::npos)
        << text;
    const std::string report = (dir / "plain" / "report.html").lexically_normal().string();
    ASSERT_TRUE(fs::path(report).is_absolute());
    EXPECT_NE(text.find("\nreport: " + report + "\n"), std::string::npos) << text;
    EXPECT_NE(read_file_text(report).find("with its defaults (100 ns a signal, 0.05 ns a byte"),
              std::string::npos);
  }
  // A calibration file at the default path: read, and named.
  fs::create_directories(dir / "config" / "tgraph");
  const std::string calibration = (dir / "config" / "tgraph" / "calibration.json").string();
  write_file_atomic(calibration, R"({"sync_latency_ns": 85.2, "per_byte_ns": 0.04, "cpus": [0, 1]})");
  {
    const DemoResult r = tiny_demo(dir / "calibrated");
    EXPECT_EQ(r.cost_model, calibration);
    EXPECT_NE(demo_text(r).find("\npredicted: cost model from " + calibration + "\n"),
              std::string::npos)
        << demo_text(r);
    EXPECT_NE(read_file_text(r.report_path)
                  .find("with the calibration file " + calibration + " (85 ns a signal, 0.04 ns a byte)"),
              std::string::npos);
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace tgraph::experiment
