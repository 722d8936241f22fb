// Stage 1 of a World step: the control frames' targets from their mocap bodies (occlusion policy,
// catch-up after a gap, target twists fed forward).
#include "world_state.hpp"

namespace mannequin::sim {

math::Vector6 World::targetTwist(std::size_t index, std::size_t i, double dt) {
  MannequinData& m = data_->mannequins[index];
  const math::SE3& T = m.frames[i].target;
  math::Vector6 V = math::Vector6::Zero();
  if (model_.config.target_twist && m.have_previous[i]) {
    const math::SE3& P = m.previous_targets[i];
    V.head<3>() = math::logSO3(P.R.transpose() * T.R) / dt;
    V.tail<3>() = T.R.transpose() * (T.p - P.p) / dt;
    // a jump (re-tracked body, re-anchored clock) is not a motion to feed forward
    if (!V.allFinite() || V.tail<3>().norm() > model_.config.max_target_speed ||
        0.3 * V.head<3>().norm() > model_.config.max_target_speed)
      V.setZero();
  }
  m.previous_targets[i] = T;
  m.have_previous[i] = true;
  return V;
}

void World::driveTargets(std::size_t index, double dt) {
  MannequinData& m = data_->mannequins[index];
  const int k_src = model_.mannequins[index].source;
  const SourceData& src = data_->sources[static_cast<std::size_t>(k_src)];
  if (m.calibrated && src.anchored) {
    // restored (World::restore) and holding its targets until now: the first live targets catch up from the
    // held ones, as after a stream gap (the actor may have moved while the sim was down)
    const bool was_holding = m.holding_restored;
    m.holding_restored = false;
    const std::int64_t t = sourceCaptureTimeNs(static_cast<std::size_t>(k_src));
    for (std::size_t i = 0; i < m.frames.size(); ++i) {
      DrivenFrame& st = m.frames[i];
      const math::SE3 held = st.target;
      const BodySample s = src.buffer.sample(st.body, t);
      double goal = 1.0;
      if (s.tracked) {
        st.target = s.pose * st.offset;
      } else {
        const double since = static_cast<double>(t - s.last_tracked_ns) * 1e-9;
        if (s.ever_tracked) st.target = s.pose * st.offset;  // hold the last tracked pose
        goal = since <= model_.config.occlusion_hold
                   ? 1.0
                   : std::max(0.0, 1.0 - (since - model_.config.occlusion_hold) / std::max(model_.config.occlusion_blend, 1e-9));
      }
      if (st.tracked && !s.tracked) ++data_->glitches.occlusions;
      st.tracked = s.tracked;
      // weights move towards their goal at 1/blend per second (back in after an occlusion: no jump)
      const double rate = dt / std::max(model_.config.occlusion_blend, 1e-9);
      double& w = m.weights[i];
      w = goal > w ? std::min(goal, w + rate) : goal;
      // back after a stream gap (or re-anchored) the body may be far from the target: the target keeps the offset it
      // had to the body then and the offset shrinks at kCatchUpSpeed (m/s, and kCatchUpSpeed / 0.3 m rad/s),
      // so it moves with the body and reaches it without a jump
      if (was_holding) {
        m.catch_p[i] = held.p - st.target.p;
        m.catch_r[i] = math::logSO3(held.R * st.target.R.transpose());
      } else if (src.back && m.have_previous[i]) {
        m.catch_p[i] = m.previous_targets[i].p - st.target.p;
        m.catch_r[i] = math::logSO3(m.previous_targets[i].R * st.target.R.transpose());
      }
      if (m.catch_p[i].squaredNorm() > 0 || m.catch_r[i].squaredNorm() > 0) {
        const auto shrink = [](math::Vector3& d, double by) { d = d.norm() <= by ? math::Vector3::Zero() : math::Vector3(d * (1.0 - by / d.norm())); };
        shrink(m.catch_p[i], kCatchUpSpeed * dt);
        shrink(m.catch_r[i], kCatchUpSpeed / 0.3 * dt);
        st.target.p += m.catch_p[i];
        st.target.R = math::expSO3(m.catch_r[i]) * st.target.R;
      }
      // a target moving faster than max_target_speed (m/s) jumped (a marker swap, a re-tracked body, a
      // re-anchored clock): counted (its twist is not fed forward, targetTwist)
      if (m.have_previous[i] && (st.target.p - m.previous_targets[i].p).norm() > model_.config.max_target_speed * dt) ++data_->glitches.target_jumps;
      m.stepper->setTarget(static_cast<int>(i), st.target, targetTwist(index, i, dt), w);
    }
  } else {
    // not calibrated: no target; restored (World::restore) and waiting for its source's first frame:
    // the restored targets held at their weights
    const bool hold = m.calibrated && m.holding_restored;
    for (std::size_t i = 0; i < m.frames.size(); ++i)
      m.stepper->setTarget(static_cast<int>(i), m.frames[i].target, math::Vector6::Zero(), hold ? m.weights[i] : 0.0);
  }
}

}  // namespace mannequin::sim
