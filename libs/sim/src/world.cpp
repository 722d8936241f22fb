#include "mannequin/sim/world.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include "mannequin/math/so3.hpp"
#include "mannequin/sim/controller_stepper.hpp"
#include "mannequin/skeleton/anthropometry.hpp"

namespace mannequin::sim {

struct World::Mannequin {
  std::string name;
  skeleton::Model model;
  std::vector<ControlFrameSpec> specs;
  int root_frame = -1;
  std::vector<int> frame_indices;
  std::unique_ptr<Stepper> stepper;
  std::vector<DrivenFrame> frames;
  std::vector<math::SE3> previous_targets;  // targets of the previous step (target twist)
  std::vector<bool> have_previous;
  std::vector<double> weights;  // current weights (rate-limited)
  bool calibrated = false;
  skeleton::VectorX q_standing;
};

World::World(std::vector<MannequinSetup> setups, const SimConfig& config) : config_(config), buffer_(2.0) {
  if (!(config_.step > 0) || !std::isfinite(config_.step)) throw std::invalid_argument("sim: step must be > 0");
  std::set<std::string> names;
  for (MannequinSetup& s : setups) {
    if (!names.insert(s.name).second) throw std::invalid_argument("sim: two mannequins named '" + s.name + "'");
    auto m = std::make_unique<Mannequin>();
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
    m->q_standing = skeleton::standingConfiguration(m->model);
    m->frame_indices = idx;
    if (s.controller) {
      try {
        m->stepper = std::make_unique<ControllerStepper>(m->model, *s.controller, idx, config_.step, m->q_standing,
                                                         config_.joint_limits);
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

void World::anchor(std::int64_t capture_ns) {
  anchored_ = true;
  anchor_capture_ns_ = capture_ns;
  anchor_step_ = steps_;
}

std::int64_t World::captureTimeNs() const {
  const double dt_ns = config_.step * 1e9;
  return anchor_capture_ns_ + static_cast<std::int64_t>(std::llround(static_cast<double>(steps_ - anchor_step_) * dt_ns)) -
         static_cast<std::int64_t>(std::llround(config_.interpolation_delay * 1e9));
}

void World::calibrate(Mannequin& m, const mocap::Frame& frame) {
  auto find = [&](const std::string& body) -> const mocap::Body* {
    for (const mocap::Body& b : frame.bodies)
      if (b.name == body) return &b;
    return nullptr;
  };
  for (const auto& st : m.frames) {
    const mocap::Body* b = find(st.body);
    if (b == nullptr || !b->tracked) return;  // not every body visible: wait
  }
  if (config_.calibration_needs_flag && !frame.calibration_pose) return;
  // calibration configuration: standing, moved horizontally (and turned about z) under the root's body
  skeleton::VectorX qc = m.q_standing;
  if (m.root_frame >= 0)
    for (const auto& st : m.frames)
      if (st.frame_index == m.root_frame) {
        const mocap::Body* b = find(st.body);
        qc(0) = b->pose.p.x();
        qc(1) = b->pose.p.y();
        // heading of the body's x axis projected on the floor
        const math::Vector3 x = b->pose.R.col(0);
        if (std::hypot(x.x(), x.y()) > 1e-3) {
          const double yaw = std::atan2(x.y(), x.x());
          const math::Matrix3 R = math::expSO3(math::Vector3(0, 0, yaw)) * math::expSO3(qc.segment<3>(3));
          qc.segment<3>(3) = math::logSO3(R);
        }
      }
  if (config_.calibration_fit_steps > 0) {
    // fit the posture to the bodies' positions first (orientations free), so that the offsets only
    // hold what differs between the tracker's and the model's frames, not a posture mismatch
    KinematicTracker fit(m.model, m.frame_indices, config_.gains, qc);
    for (int k = 0; k < config_.calibration_fit_steps; ++k) {
      for (std::size_t i = 0; i < m.frames.size(); ++i) {
        math::SE3 T = fit.data().oMf[m.frames[i].frame_index];
        T.p = find(m.frames[i].body)->pose.p;
        fit.setTarget(static_cast<int>(i), T, 1.0);
      }
      if (!fit.step(config_.step)) break;
    }
    qc = fit.q();
  }
  m.stepper->reset(qc);
  m.stepper->setPosture(qc);
  std::fill(m.have_previous.begin(), m.have_previous.end(), false);
  const skeleton::Data& d = m.stepper->data();
  for (auto& st : m.frames) {
    const mocap::Body* b = find(st.body);
    st.offset = b->pose.inverse() * d.oMf[st.frame_index];
    st.target = st.actual = d.oMf[st.frame_index];
  }
  std::fill(m.weights.begin(), m.weights.end(), 1.0);
  m.calibrated = true;
}

void World::addMocap(const mocap::Frame& frame) {
  if (!buffer_.add(frame)) return;
  for (auto& m : mannequins_)
    if (!m->calibrated) calibrate(*m, frame);
}

math::Vector6 World::targetTwist(Mannequin& m, std::size_t i, double dt) const {
  const math::SE3& T = m.frames[i].target;
  math::Vector6 V = math::Vector6::Zero();
  if (config_.target_twist && m.have_previous[i]) {
    const math::SE3& P = m.previous_targets[i];
    V.head<3>() = math::logSO3(P.R.transpose() * T.R) / dt;
    V.tail<3>() = T.R.transpose() * (T.p - P.p) / dt;
    // a jump (re-tracked body, re-anchored clock) is not a motion to feed forward
    if (!V.allFinite() || V.tail<3>().norm() > config_.max_target_speed ||
        0.3 * V.head<3>().norm() > config_.max_target_speed)
      V.setZero();
  }
  m.previous_targets[i] = T;
  m.have_previous[i] = true;
  return V;
}

bool World::step() {
  const std::int64_t t = captureTimeNs();
  const double dt = config_.step;
  bool ok = true;
  for (auto& mp : mannequins_) {
    Mannequin& m = *mp;
    if (m.calibrated && anchored_) {
      for (std::size_t i = 0; i < m.frames.size(); ++i) {
        DrivenFrame& st = m.frames[i];
        const BodySample s = buffer_.sample(st.body, t);
        double goal = 1.0;
        if (s.tracked) {
          st.target = s.pose * st.offset;
        } else {
          const double since = static_cast<double>(t - s.last_tracked_ns) * 1e-9;
          if (s.ever_tracked) st.target = s.pose * st.offset;  // hold the last tracked pose
          goal = since <= config_.occlusion_hold
                     ? 1.0
                     : std::max(0.0, 1.0 - (since - config_.occlusion_hold) / std::max(config_.occlusion_blend, 1e-9));
        }
        st.tracked = s.tracked;
        // weights move towards their goal at 1/blend per second (back in after an occlusion: no jump)
        const double rate = dt / std::max(config_.occlusion_blend, 1e-9);
        double& w = m.weights[i];
        w = goal > w ? std::min(goal, w + rate) : goal;
        m.stepper->setTarget(static_cast<int>(i), st.target, targetTwist(m, i, dt), w);
      }
    } else {
      for (std::size_t i = 0; i < m.frames.size(); ++i)
        m.stepper->setTarget(static_cast<int>(i), m.frames[i].target, math::Vector6::Zero(), 0.0);
    }
    if (!m.stepper->step(dt)) {
      ok = false;
      ++failed_steps_;
    }
    const skeleton::Data& d = m.stepper->data();
    for (std::size_t i = 0; i < m.frames.size(); ++i) {
      DrivenFrame& st = m.frames[i];
      st.actual = d.oMf[st.frame_index];
      st.weight = m.weights[i];
      st.position_error = (st.target.p - st.actual.p).norm();
      st.orientation_error = math::logSO3(st.actual.R.transpose() * st.target.R).norm();
    }
  }
  ++steps_;
  return ok;
}

}  // namespace mannequin::sim
