// The World: construction from the mannequins' setups and the config, its accessors, and the step
// as the list of its stages (each stage in its own file beside this one).
#include "world_state.hpp"

namespace mannequin::sim {

World::World(std::vector<MannequinSetup> setups, const SimConfig& config) : config_(config) {
  if (!(config_.step > 0) || !std::isfinite(config_.step)) throw std::invalid_argument("sim: step must be > 0");
  sources_.push_back(std::make_unique<Source>());  // the default source ""
  std::set<std::string> names;
  for (MannequinSetup& s : setups) {
    if (!names.insert(s.name).second) throw std::invalid_argument("sim: two mannequins named '" + s.name + "'");
    auto m = std::make_unique<Mannequin>();
    if (findSource(s.mocap_source) == nullptr) {
      sources_.push_back(std::make_unique<Source>());
      sources_.back()->name = s.mocap_source;
    }
    for (std::size_t i = 0; i < sources_.size(); ++i)
      if (sources_[i]->name == s.mocap_source) m->source = static_cast<int>(i);
    m->name = s.name;
    m->model = std::move(s.model);
    m->specs = s.frames;
    m->root_frame = m->model.findFrame(s.root_frame);
    std::vector<int> idx;
    for (const ControlFrameSpec& f : s.frames) {
      DrivenFrame st;
      st.frame = f.frame;
      st.body = f.body;
      try {
        st.frame_index = m->model.frameIndex(f.frame);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument("sim: mannequin '" + s.name + "': " + e.what());
      }
      idx.push_back(st.frame_index);
      m->frames.push_back(st);
    }
    m->weights.assign(m->frames.size(), 0.0);
    m->catch_p.assign(m->frames.size(), math::Vector3::Zero());
    m->catch_r.assign(m->frames.size(), math::Vector3::Zero());
    m->q_standing = skeleton::standingConfiguration(m->model);
    m->frame_indices = idx;
    if (s.controller && config_.physics.enabled) {
      if (!config_.physics.gravity.allFinite())
        throw std::invalid_argument("sim: physics.gravity must be finite");
      s.controller->gravity = config_.physics.gravity;
    }
    if (s.controller) {
      try {
        auto controller = std::make_unique<ControllerStepper>(m->model, *s.controller, idx, config_.step, m->q_standing,
                                                              config_.joint_limits);
        m->controller = controller.get();
        m->stepper = std::move(controller);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument("sim: mannequin '" + s.name + "': " + e.what());
      }
    } else {
      m->stepper = std::make_unique<KinematicTracker>(m->model, idx, config_.gains, m->q_standing);
    }
    m->previous_targets.resize(idx.size());
    m->have_previous.assign(idx.size(), false);
    for (auto& st : m->frames) st.target = st.actual = m->stepper->data().oMf[st.frame_index];
    mannequins_.push_back(std::move(m));
  }
  mannequin_diagnostics_.assign(mannequins_.size(), MannequinDiagnostics{});
  if (config_.physics.enabled) buildPhysics();
}

const skeleton::VectorX* World::balanceConfiguration(int m) const {
  if (!physics_ || physics_->balance_loops.empty()) return nullptr;
  const Physics::BalanceLoop& L = physics_->balance_loops.at(static_cast<std::size_t>(m));
  return L.driving ? &L.q_b : nullptr;
}

const MannequinDiagnostics& World::mannequinDiagnostics(int m) const {
  return mannequin_diagnostics_.at(static_cast<std::size_t>(m));
}

World::~World() = default;


const std::string& World::name(int m) const { return mannequins_.at(m)->name; }
const skeleton::Model& World::model(int m) const { return mannequins_.at(m)->model; }
const skeleton::Data& World::data(int m) const { return mannequins_.at(m)->stepper->data(); }
const skeleton::VectorX& World::q(int m) const { return mannequins_.at(m)->stepper->q(); }
const skeleton::VectorX& World::qdot(int m) const { return mannequins_.at(m)->stepper->qdot(); }
bool World::calibrated(int m) const { return mannequins_.at(m)->calibrated; }
const Stepper& World::stepper(int m) const { return *mannequins_.at(m)->stepper; }
const std::vector<DrivenFrame>& World::controlFrames(int m) const { return mannequins_.at(m)->frames; }

bool World::step() {
  detectStreamGaps();
  for (auto& mp : mannequins_) driveTargets(*mp, config_.step);
  for (auto& src : sources_) src->back = false;  // the catch-ups after a gap or a re-anchor have started
  if (physics_ && !physics_->balance_loops.empty())
    for (std::size_t m = 0; m < mannequins_.size(); ++m) applyBalanceTargets(m);
  if (scenario_) stepScenario();
  const bool ok = physics_ ? physicsStep() : kinematicStep();
  diagnostics_.nan = !ok;
  updateFrameErrors();
  ++steps_;
  return ok;
}

}  // namespace mannequin::sim
