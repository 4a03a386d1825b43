// SPDX-License-Identifier: MIT
// The samples engine (a Scene) behind the live-run interface.
#include "tgraph/measure/engine.hpp"

#include <utility>

#include "recorded_step.hpp"
#include "tgraph/measure/adapter.hpp"
#include "tgraph/samples/tiled_heat.hpp"
#include "tgraph/graph/error.hpp"

namespace tgraph::measure {
namespace {

class SceneEngine final : public LiveEngine {
 public:
  explicit SceneEngine(std::unique_ptr<samples::Scene> scene)
      : scene_(std::move(scene)), rec_(capture::Mode::kDeferred), plain_(capture::Mode::kOff) {}

  LiveStep record_step(bool allow_reuse) override {
    if (!allow_reuse) {
      scene_->step(rec_);
    } else if (!scene_->step_if_changed(rec_)) {
      LiveStep same;
      same.reuse_previous = true;
      return same;
    }
    LiveStep step = detail::take_recorded_step(rec_, "scene " + scene_->name());
    last_graph_ = step.graph;
    return step;
  }

  void plain_step() override {
    scene_->step(plain_);
    plain_.end_step();
    used_ = &plain_;
  }

  std::vector<StateRegion> state() const override {
    std::vector<StateRegion> r = detail::recorded_state(*used_);
    if (used_ == &rec_ && !last_graph_.tasks.empty()) set_write_order(r, last_graph_);
    return r;
  }

 private:
  std::unique_ptr<samples::Scene> scene_;
  capture::Recorder rec_;
  capture::Recorder plain_;
  const capture::Recorder* used_ = &rec_;  // the recorder whose ids name the state
  StepGraph last_graph_;                   // the last step recorded: the state's write order
};

}  // namespace

LiveStep detail::take_recorded_step(capture::Recorder& rec, const std::string& engine) {
  capture::StepProgram p = rec.end_step_program();
  if (rec.errors() != 0) {
    // The first misuse names the call, the loop, the step and its task count.
    const std::vector<capture::Misuse>& m = rec.misuses();
    std::string what = m.empty() ? "API misuse" : capture::to_string(m[0]);
    if (rec.errors() > 1) what += " (" + std::to_string(rec.errors()) + " misuses in all)";
    throw UsageError(engine + ": " + what);
  }
  LiveStep step;
  step.graph = std::move(p.graph);
  step.bodies = std::move(p.bodies);
  step.conditions = std::move(p.conditions);
  step.accumulators = std::move(p.accumulators);
  step.graph_update_ns = rec.last_edge_update().ns;
  return step;
}

std::vector<StateRegion> detail::recorded_state(const capture::Recorder& rec) {
  std::vector<StateRegion> r;
  const std::vector<Datum>& data = rec.data();
  for (DatumId d = 0; d < data.size(); ++d)
    if (rec.datum_ptr(d) != nullptr) r.push_back({data[d].name, rec.datum_ptr(d), data[d].bytes});
  return r;
}

std::unique_ptr<LiveEngine> make_live_engine(const std::string& scene,
                                             const samples::SceneOptions& options) {
  if (samples::is_tiled_heat(scene)) {  // the test engine of --verify-accesses
    auto heat = std::make_shared<samples::TiledHeat>(samples::tiled_heat_options(scene));
    EngineCallbacks c;
    c.declare = [heat](capture::Recorder& rec) { heat->declare(rec); };
    c.step = [heat](capture::Recorder& rec) { heat->step(rec); };
    c.same_every_step = true;
    return make_live_engine(std::move(c));
  }
  return std::make_unique<SceneEngine>(samples::make_scene(scene, options));
}

}  // namespace tgraph::measure
