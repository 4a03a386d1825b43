// SPDX-License-Identifier: MIT
#include "tgraph/samples/live_engine.hpp"

#include <utility>

#include "tgraph/graph/error.hpp"

namespace tgraph::samples {
namespace {

class SceneEngine final : public replay::LiveEngine {
 public:
  explicit SceneEngine(std::unique_ptr<Scene> scene)
      : scene_(std::move(scene)), rec_(capture::Mode::kDeferred), plain_(capture::Mode::kOff) {}

  replay::LiveStep record_step() override {
    if (!scene_->step_if_changed(rec_)) {
      replay::LiveStep same;
      same.reuse_previous = true;
      return same;
    }
    capture::StepProgram p = rec_.end_step_program();
    if (rec_.errors() != 0)
      throw UsageError("scene " + scene_->name() + ": the recorder counted " +
                       std::to_string(rec_.errors()) + " API misuses");
    last_data_ = p.graph.data;
    replay::LiveStep step;
    step.graph = std::move(p.graph);
    step.bodies = std::move(p.bodies);
    step.conditions = std::move(p.conditions);
    step.accumulators = std::move(p.accumulators);
    return step;
  }

  void plain_step() override {
    scene_->step(plain_);
    plain_.end_step();
  }

  std::vector<replay::StateRegion> state() const override {
    std::vector<replay::StateRegion> r;
    for (DatumId d = 0; d < last_data_.size(); ++d)
      if (rec_.datum_ptr(d) != nullptr)
        r.push_back({last_data_[d].name, rec_.datum_ptr(d), last_data_[d].bytes});
    return r;
  }

 private:
  std::unique_ptr<Scene> scene_;
  capture::Recorder rec_;
  capture::Recorder plain_;
  std::vector<Datum> last_data_;
};

}  // namespace

std::unique_ptr<replay::LiveEngine> make_live_engine(const std::string& scene,
                                                     const SceneOptions& options) {
  return std::make_unique<SceneEngine>(make_scene(scene, options));
}

}  // namespace tgraph::samples
