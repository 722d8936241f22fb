// Calibration of a mannequin on a mocap frame (thesis Fig. 1.10): q_c, the offsets bMf, the floor
// clearance of the soles (thesis 4.4.3).
#include "world_state.hpp"

namespace mannequin::sim {

void World::calibrate(std::size_t index, const mocap::Frame& frame) {
  const MannequinModel& mm = model_.mannequins[index];
  MannequinData& m = data_->mannequins[index];
  auto find = [&](const std::string& body) -> const mocap::Body* {
    for (const mocap::Body& b : frame.bodies)
      if (b.name == body) return &b;
    return nullptr;
  };
  for (const auto& st : m.frames) {
    const mocap::Body* b = find(st.body);
    if (b == nullptr || !b->tracked) return;  // not every body visible: wait
  }
  if (model_.config.calibration_needs_flag && !frame.calibration_pose) return;
  // calibration configuration: standing, moved horizontally (and turned about z) under the root's body
  skeleton::VectorX qc = mm.q_standing;
  if (mm.root_frame >= 0)
    for (const auto& st : m.frames)
      if (st.frame_index == mm.root_frame) {
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
  if (model_.config.calibration_fit_steps > 0) {
    // fit the posture to the bodies' positions first (orientations free), so that the offsets only
    // hold what differs between the tracker's and the model's frames, not a posture mismatch
    KinematicTracker fit(mm.model, mm.frame_indices, model_.config.gains, qc);
    for (int k = 0; k < model_.config.calibration_fit_steps; ++k) {
      for (std::size_t i = 0; i < m.frames.size(); ++i) {
        math::SE3 T = fit.data().oMf[m.frames[i].frame_index];
        T.p = find(m.frames[i].body)->pose.p;
        fit.setTarget(static_cast<int>(i), T, 1.0);
      }
      if (!fit.step(model_.config.step)) break;
    }
    qc = fit.q();
  }
  if (data_->physics) {
    // the contact–control paradox (thesis 4.4.3): a foot target calibrated below the floor would press
    // the sole into it for the whole session. Put the lowest sole's margin shell of q_c at
    // `calibration_clearance` above the floor's, so the foot targets at the calibration pose rest on
    // the floor (the sole `margins + clearance` above it), not in it.
    const double gap = soleGap(index, qc);
    if (std::isfinite(gap)) qc(2) += model_.config.physics.calibration_clearance - gap;
  }
  m.stepper->reset(qc);
  m.stepper->setPosture(qc);
  m.q_posture = qc;
  if (data_->physics && !data_->physics->balance_loops.empty()) {
    data_->physics->balance_loops[index].driving = false;  // recalibrated: the mocap drives until the next solve
  }
  std::fill(m.have_previous.begin(), m.have_previous.end(), false);
  const skeleton::Data& d = m.stepper->data();
  for (auto& st : m.frames) {
    const mocap::Body* b = find(st.body);
    st.offset = b->pose.inverse() * d.oMf[st.frame_index];
    st.target = st.actual = d.oMf[st.frame_index];
  }
  std::fill(m.weights.begin(), m.weights.end(), 1.0);
  m.calibrated = true;
  if (data_->physics) {
    data_->physics->cw.setMannequinPlaced(data_->physics->cw_mannequin[index], true);
  }
}

double World::soleGap(std::size_t index, const skeleton::VectorX& q) {
  PhysicsData& P = *data_->physics;
  const skeleton::Model& model = model_.mannequins[index].model;
  skeleton::Data d(model);
  skeleton::forwardKinematics(model, d, q);
  const double activation = P.cw.activationDistance();
  P.cw.setActivationDistance(2.0);  // the soles may be far above or below the floor here
  P.cw.updateMannequin(P.cw_mannequin[index], d);
  collision::ContactSet set;
  P.cw.query(data_->steps, set);
  P.cw.setActivationDistance(activation);
  double gap = std::numeric_limits<double>::infinity();
  for (const collision::Contact& c : set.contacts) {
    const bool foot_floor = (c.body_a == P.floor_body && P.body_is_foot[static_cast<std::size_t>(c.body_b)] &&
                             P.body_mannequin[static_cast<std::size_t>(c.body_b)] == static_cast<int>(index)) ||
                            (c.body_b == P.floor_body && P.body_is_foot[static_cast<std::size_t>(c.body_a)] &&
                             P.body_mannequin[static_cast<std::size_t>(c.body_a)] == static_cast<int>(index));
    if (foot_floor) gap = std::min(gap, c.distance);  // after margins: 0 = the margin shells touch
  }
  return gap;
}

}  // namespace mannequin::sim
