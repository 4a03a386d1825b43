// SPDX-License-Identifier: MIT
// The samples engine (a Scene) behind the live-run interface.
#include "tgraph/measure/engine.hpp"

#include <utility>

#include "recorded_step.hpp"
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
    return detail::take_recorded_step(rec_, "scene " + scene_->name());
  }

  void plain_step() override {
    scene_->step(plain_);
    plain_.end_step();
    used_ = &plain_;
  }

  std::vector<StateRegion> state() const override { return detail::recorded_state(*used_); }

 private:
  std::unique_ptr<samples::Scene> scene_;
  capture::Recorder rec_;
  capture::Recorder plain_;
  const capture::Recorder* used_ = &rec_;  // the recorder whose ids name the state
};

}  // namespace

LiveStep detail::take_recorded_step(capture::Recorder& rec, const std::string& engine) {
  capture::StepProgram p = rec.end_step_program();
  if (rec.errors() != 0)
    throw UsageError(engine + ": the recorder counted " + std::to_string(rec.errors()) +
                     " API misuses");
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
  return std::make_unique<SceneEngine>(samples::make_scene(scene, options));
}

}  // namespace tgraph::measure
