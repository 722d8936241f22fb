// A World's diagnostics after a step: the contacts as reports, each mannequin's diagnostics (contacts,
// soles, joint-limit excess, balance at q_k), and the driven frames' errors to their targets.
#include "world_state.hpp"

namespace mannequin::sim {

/// max over limited coordinates of how far q is past a limit (rad, ≥ 0): revolute coordinates against
/// their bounds, ball joints against their swing ellipse and twist range (Annex D.2, swing_twist.hpp).
double worstLimitExcess(const skeleton::Model& model, const skeleton::VectorX& q) {
  double worst = 0.0;
  for (const skeleton::Joint& j : model.joints) {
    if (j.type == skeleton::JointType::kFreeFlyer) continue;
    if (j.type == skeleton::JointType::kBall) {
      // the rotation angle θ = |q| bounds the swing angle and |twist| (swing_twist.hpp), and every point of
      // the swing ellipse is at least min(a, b) − |c| from s = 0: inside both, nothing to decompose
      const skeleton::BallLimit& l = j.ball_limit;
      const double theta = q.segment<3>(j.idx_q).norm();
      if (theta < std::min(l.swing_a, l.swing_b) - std::hypot(l.swing_cx, l.swing_cy) && theta < -l.twist_lower &&
          theta < l.twist_upper)
        continue;
      const constraints::BallLimitDistances bd = constraints::ballLimitDistances(l, math::expSO3(q.segment<3>(j.idx_q)), false);
      worst = std::max(worst, bd.swing_excess);
      if (!bd.singular) worst = std::max({worst, -bd.twist_lower, -bd.twist_upper});
      continue;
    }
    for (int c = 0; c < j.nq; ++c) {
      const int k = j.idx_q + c;
      const double lo = model.lower_limit(k), hi = model.upper_limit(k);
      if (std::isfinite(lo)) worst = std::max(worst, lo - q(k));
      if (std::isfinite(hi)) worst = std::max(worst, q(k) - hi);
    }
  }
  return worst;
}

void World::computeDiagnostics() {
  const PhysicsData& P = *data_->physics;
  const auto& cts = P.contacts->contacts();
  const auto& states = P.contacts->states();
  data_->contacts.clear();
  data_->diagnostics.contacts = 0;
  data_->diagnostics.active_contacts = 0;
  data_->diagnostics.max_penetration_m = P.contacts->maxPenetration();
  for (MannequinDiagnostics& md : data_->mannequin_diagnostics) {
    md.contacts = 0;
    md.foot_contact = false;
    md.sole_height_m = std::numeric_limits<double>::infinity();
  }
  for (std::size_t i = 0; i < cts.size(); ++i) {
    const collision::Contact& c = cts[i];
    const auto& st = states[i];
    if (st.row < 0) continue;
    ++data_->diagnostics.contacts;
    if (st.normal_force > 0) ++data_->diagnostics.active_contacts;
    ContactReport r;
    r.body_a = c.body_a;
    r.body_b = c.body_b;
    r.point = st.point;
    r.normal = c.normal;
    r.distance = st.distance;
    r.normal_force = st.normal_force;
    r.friction_force = st.friction_force;
    data_->contacts.push_back(r);
    for (const int b : {c.body_a, c.body_b}) {
      const int m = P.body_mannequin[static_cast<std::size_t>(b)];
      if (m < 0) continue;
      MannequinDiagnostics& md = data_->mannequin_diagnostics[static_cast<std::size_t>(m)];
      ++md.contacts;
      const int other = b == c.body_a ? c.body_b : c.body_a;
      if (P.body_is_foot[static_cast<std::size_t>(b)] && other == P.floor_body) {
        // real geometry: the distance after margins plus both margins
        const double gap = st.distance + P.cw.margin(c.body_a) + P.cw.margin(c.body_b);
        md.sole_height_m = std::min(md.sole_height_m, gap);
        // touching: pressed, or its margin shell within 1 mm of the floor's
        if (st.normal_force > 0 || st.distance <= model_.config.physics.foot_contact_tolerance) md.foot_contact = true;
      }
    }
  }
  for (std::size_t m = 0; m < data_->mannequins.size(); ++m) {
    MannequinDiagnostics& md = data_->mannequin_diagnostics[m];
    // no foot–floor pair in range: the soles are at least the activation distance (plus margins) up
    if (!std::isfinite(md.sole_height_m)) md.sole_height_m = model_.config.physics.activation_distance;
    md.worst_joint_limit_excess_rad = worstLimitExcess(model_.mannequins[m].model, data_->mannequins[m].controller->q());
    // balance at q_k (the support and CoM the step's row saw)
    const constraints::BalanceRows::State& bs = P.balance[m]->state();
    md.balance_distance_m = bs.distance.polygon_m;
    md.com = bs.com;
    md.support_points = static_cast<int>(P.support[m].size());
  }
}

void World::updateFrameErrors() {
  for (MannequinData& m : data_->mannequins) {
    const skeleton::Data& d = m.stepper->data();
    for (std::size_t i = 0; i < m.frames.size(); ++i) {
      DrivenFrame& st = m.frames[i];
      st.actual = d.oMf[st.frame_index];
      st.weight = m.weights[i];
      st.position_error = (st.target.p - st.actual.p).norm();
      st.orientation_error = math::logSO3(st.actual.R.transpose() * st.target.R).norm();
    }
  }
}

}  // namespace mannequin::sim
