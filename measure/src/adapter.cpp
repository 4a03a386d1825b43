// SPDX-License-Identifier: MIT
// An outside engine's callbacks behind LiveEngine, and its live run.
#include "tgraph/measure/adapter.hpp"

#include <nlohmann/json.hpp>
#include <optional>
#include <utility>

#include "recorded_step.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/measure/report.hpp"
#include "tgraph/partition/strategy.hpp"

namespace tgraph::measure {
namespace {

class CallbackEngine final : public LiveEngine {
 public:
  explicit CallbackEngine(EngineCallbacks c) : c_(std::move(c)) {
    if (!c_.declare || !c_.step)
      throw UsageError("engine callbacks: declare and step are required");
  }

  LiveStep record_step(bool allow_reuse) override {
    capture::Recorder& rec = recorder(capture::Mode::kDeferred);
    if (allow_reuse && c_.same_every_step && recorded_) {
      LiveStep same;
      same.reuse_previous = true;
      return same;
    }
    rec.begin_step();
    c_.step(rec);
    LiveStep step = detail::take_recorded_step(rec, "engine");
    recorded_ = true;
    return step;
  }

  void plain_step() override {
    capture::Recorder& rec = recorder(capture::Mode::kOff);
    rec.begin_step();
    c_.step(rec);
    rec.end_step();
  }

  std::vector<StateRegion> state() const override {
    if (c_.state) return c_.state();
    return rec_ ? detail::recorded_state(*rec_) : std::vector<StateRegion>{};
  }

 private:
  // The engine's recorder, made (and the engine declared on it) at the first step.
  capture::Recorder& recorder(capture::Mode mode) {
    if (!rec_) {
      rec_.emplace(mode);
      c_.declare(*rec_);
    } else if (rec_->mode() != mode) {
      throw UsageError("engine: stepped both recorded and plainly (make a fresh engine for each)");
    }
    return *rec_;
  }

  EngineCallbacks c_;
  std::optional<capture::Recorder> rec_;
  bool recorded_ = false;
};

}  // namespace

std::unique_ptr<LiveEngine> make_live_engine(EngineCallbacks callbacks) {
  return std::make_unique<CallbackEngine>(std::move(callbacks));
}

LiveResult run_engine_live(const CallbacksFactory& make, const MethodChoice& method,
                           LiveOptions options) {
  options.policy = method.policy;
  std::optional<partition::StepPartitioner> part;
  if (method.policy == replay::Policy::kPartition) {
    partition::Options po;
    po.sticky_threshold = live_sticky_threshold(options);
    po.loop_share = options.loop_share;
    part = partition::step_partitioner(method.method, po);
  }
  return run_live([make] { return make_live_engine(make()); }, part ? &*part : nullptr, options);
}

std::string to_json(const LiveResult& r, const std::string& engine, const std::string& method,
                    const std::vector<std::pair<std::string, double>>& extra) {
  auto j = nlohmann::json::parse(to_json(r, engine, method));
  for (const auto& [key, value] : extra) j[key] = value;
  return j.dump();
}

}  // namespace tgraph::measure
