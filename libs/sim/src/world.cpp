// The World: construction from the mannequins' setups and the config, its accessors, and the step
// as the list of its stages (each stage in its own file beside this one).
#include "world_state.hpp"

namespace mannequin::sim {

World::World(std::vector<MannequinSetup> setups, const SimConfig& config)
    : World(buildWorldModel(std::move(setups), config)) {}

World::World(WorldModel model) : model_(std::move(model)), data_(std::make_unique<WorldData>()) {
  WorldData& D = *data_;
  D.sources.resize(model_.sources.size());
  D.mannequins.resize(model_.mannequins.size());
  for (std::size_t k = 0; k < model_.mannequins.size(); ++k) {
    const MannequinModel& mm = model_.mannequins[k];
    MannequinData& md = D.mannequins[k];
    for (std::size_t i = 0; i < mm.control_frames.size(); ++i) {
      DrivenFrame st;
      st.frame = mm.control_frames[i].frame;
      st.body = mm.control_frames[i].body;
      st.frame_index = mm.frame_indices[i];
      md.frames.push_back(st);
    }
    const std::size_t n = md.frames.size();
    md.weights.assign(n, 0.0);
    md.catch_p.assign(n, math::Vector3::Zero());
    md.catch_r.assign(n, math::Vector3::Zero());
    if (mm.controller) {
      try {
        auto controller = std::make_unique<ControllerStepper>(mm.model, *mm.controller, mm.frame_indices, model_.config.step,
                                                              mm.q_standing, model_.config.joint_limits);
        md.controller = controller.get();
        md.stepper = std::move(controller);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument("sim: mannequin '" + mm.name + "': " + e.what());
      }
    } else {
      md.stepper = std::make_unique<KinematicTracker>(mm.model, mm.frame_indices, model_.config.gains, mm.q_standing);
    }
    md.previous_targets.resize(n);
    md.have_previous.assign(n, false);
    for (auto& st : md.frames) st.target = st.actual = md.stepper->data().oMf[st.frame_index];
  }
  D.mannequin_diagnostics.assign(model_.mannequins.size(), MannequinDiagnostics{});
  if (model_.physics) buildPhysics();
}

const skeleton::VectorX* World::balanceConfiguration(int m) const {
  if (!data_->physics || data_->physics->balance_loops.empty()) return nullptr;
  const PhysicsData::BalanceLoop& L = data_->physics->balance_loops.at(static_cast<std::size_t>(m));
  return L.driving ? &L.q_b : nullptr;
}

const MannequinDiagnostics& World::mannequinDiagnostics(int m) const {
  return data_->mannequin_diagnostics.at(static_cast<std::size_t>(m));
}

World::~World() = default;


std::uint64_t World::stepCount() const { return data_->steps; }
std::uint64_t World::failedSteps() const { return data_->failed_steps; }
const MocapGlitches& World::mocapGlitches() const { return data_->glitches; }
const StepDiagnostics& World::diagnostics() const { return data_->diagnostics; }
const std::vector<ContactReport>& World::contacts() const { return data_->contacts; }
const std::string& World::name(int m) const { return model_.mannequins.at(static_cast<std::size_t>(m)).name; }
const skeleton::Model& World::model(int m) const { return model_.mannequins.at(static_cast<std::size_t>(m)).model; }
const skeleton::Data& World::data(int m) const { return data_->mannequins.at(static_cast<std::size_t>(m)).stepper->data(); }
const skeleton::VectorX& World::q(int m) const { return data_->mannequins.at(static_cast<std::size_t>(m)).stepper->q(); }
const skeleton::VectorX& World::qdot(int m) const { return data_->mannequins.at(static_cast<std::size_t>(m)).stepper->qdot(); }
bool World::calibrated(int m) const { return data_->mannequins.at(static_cast<std::size_t>(m)).calibrated; }
const Stepper& World::stepper(int m) const { return *data_->mannequins.at(static_cast<std::size_t>(m)).stepper; }
const std::vector<DrivenFrame>& World::controlFrames(int m) const { return data_->mannequins.at(static_cast<std::size_t>(m)).frames; }

bool World::step() {
  detectStreamGaps();
  for (std::size_t m = 0; m < data_->mannequins.size(); ++m) driveTargets(m, model_.config.step);
  for (SourceData& src : data_->sources) src.back = false;  // the catch-ups after a gap or a re-anchor have started
  if (data_->physics && !data_->physics->balance_loops.empty())
    for (std::size_t m = 0; m < data_->mannequins.size(); ++m) applyBalanceTargets(m);
  if (data_->scenario) stepScenario();
  const bool ok = data_->physics ? physicsStep() : kinematicStep();
  data_->diagnostics.nan = !ok;
  updateFrameErrors();
  ++data_->steps;
  return ok;
}

}  // namespace mannequin::sim
