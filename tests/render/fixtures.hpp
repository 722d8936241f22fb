#pragma once
// Shared by the render tests: a standing mannequin as a WorldState.
#include <cstdlib>
#include <string>

#include "mannequin/render/scene.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/skeleton/kinematics.hpp"
#include "mannequin/v1/world.pb.h"

namespace mannequin::render::testing {

inline std::string sourcePath(const std::string& rel) {
  const char* root = std::getenv("MANNEQUIN_SOURCE_DIR");
  return (root ? std::string(root) : std::string(".")) + "/" + rel;
}

inline skeleton::Model male50() {
  return skeleton::buildMannequin(skeleton::loadMannequinSpec(sourcePath("configs/mannequins/male_50th.yaml")));
}

inline void toMsg(const math::Vector3& p, v1::Vec3& out) {
  out.set_x(p.x());
  out.set_y(p.y());
  out.set_z(p.z());
}

inline void toMsg(const SE3& pose, v1::Pose& out) {
  toMsg(pose.p, *out.mutable_position());
  const Eigen::Quaterniond q(pose.R);
  out.mutable_orientation()->set_w(q.w());
  out.mutable_orientation()->set_x(q.x());
  out.mutable_orientation()->set_y(q.y());
  out.mutable_orientation()->set_z(q.z());
}

/// Adds mannequin `name` in configuration q (as services/sim's toWorldState fills it).
inline v1::MannequinState* addMannequin(v1::WorldState& ws, const skeleton::Model& model, const math::VectorX& q,
                                        const std::string& name) {
  skeleton::Data d(model);
  skeleton::forwardKinematics(model, d, q);
  v1::MannequinState* ms = ws.add_mannequins();
  ms->set_name(name);
  ms->set_model(model.name);
  for (const skeleton::Segment& s : model.segments) {
    v1::NamedPose* np = ms->add_segments();
    np->set_name(s.name);
    toMsg(d.oMi[static_cast<std::size_t>(s.joint)], *np->mutable_pose());
  }
  return ms;
}

inline v1::ContactPoint* addContact(v1::MannequinState& ms, const math::Vector3& point, const math::Vector3& normal,
                                    const math::Vector3& force, const std::string& a, const std::string& b) {
  v1::ContactPoint* c = ms.add_contacts();
  c->set_body_a(a);
  c->set_body_b(b);
  toMsg(point, *c->mutable_point());
  toMsg(normal, *c->mutable_normal());
  toMsg(force, *c->mutable_force());
  c->set_normal_force(force.norm());
  return c;
}

/// Adds control frame `frame` with its achieved pose and target (world) to a mannequin.
inline v1::ControlFrameState* addControlFrame(v1::MannequinState& ms, const std::string& frame, const SE3& actual,
                                              const SE3& target, bool tracked = true) {
  v1::ControlFrameState* cf = ms.add_control_frames();
  cf->set_frame(frame);
  cf->set_mode("free");
  toMsg(actual, *cf->mutable_actual());
  toMsg(target, *cf->mutable_target());
  cf->set_position_error((target.p - actual.p).norm());
  cf->set_tracked(tracked);
  cf->set_weight(tracked ? 1.0 : 0.0);
  return cf;
}

}  // namespace mannequin::render::testing
