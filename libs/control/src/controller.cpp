#include "mannequin/control/controller.hpp"

#include "mannequin/core/check.hpp"

#include <spdlog/spdlog.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "mannequin/skeleton/anthropometry.hpp"

namespace mannequin::control {

namespace {
bool finiteGains(const Vector6& g) { return g.allFinite() && (g.array() >= 0).all(); }
const char* kAxis[6] = {"rot x", "rot y", "rot z", "lin x", "lin y", "lin z"};
}  // namespace

Controller::Controller(const skeleton::Model& model, const ControllerConfig& config)
    : Controller(model, config, skeleton::standingConfiguration(model)) {}

Controller::Controller(const skeleton::Model& model, const ControllerConfig& config, const VectorX& q0)
    : model_(model), data_(model_), config_(config) {
  build(q0);
}

std::string Controller::describe(int i) const { return "control frame '" + frames_[i].name + "'"; }

void Controller::checkFrame(int i) const {
  if (i < 0 || i >= numFrames())
    throw std::invalid_argument("control frame index " + std::to_string(i) + " out of range (" +
                                std::to_string(numFrames()) + " control frames)");
}

int Controller::frameIndex(const std::string& name) const {
  for (int i = 0; i < numFrames(); ++i)
    if (frames_[i].name == name) return i;
  std::string list;
  for (int i = 0; i < numFrames(); ++i) list += (i ? ", " : "") + frames_[i].name;
  throw std::invalid_argument("no control frame '" + name + "' (control frames: " + list + ")");
}

void Controller::build(const VectorX& q0) {
  const ControllerConfig& c = config_;
  const auto fail = [&](const std::string& where, const std::string& field, const std::string& msg) {
    throw std::invalid_argument((where.empty() ? "" : where + ": ") + field + ": " + msg);
  };
  const std::string& src = c.source;
  if (!std::isfinite(c.dt) || c.dt <= 0) fail(src, "dt_s", "must be > 0");
  if (!c.gravity.allFinite()) fail(src, "gravity", "must be finite");
  if (!(c.b_a.root_linear > 0) || !(c.b_a.root_angular > 0) || !(c.b_a.joints > 0) || !std::isfinite(c.b_a.root_linear) ||
      !std::isfinite(c.b_a.root_angular) || !std::isfinite(c.b_a.joints))
    fail(src, "b_a", "every friction must be finite and > 0 (b_a SPD, 2.4)");
  if (!(c.rank_tolerance > 0 && c.rank_tolerance < 1)) fail(src, "rank_tolerance", "must be in (0, 1)");
  if (!std::isfinite(c.internal.stiffness) || c.internal.stiffness < 0 || !std::isfinite(c.internal.damping) ||
      c.internal.damping < 0)
    fail(src, "internal", "stiffness and damping must be finite and >= 0");
  dt_ = c.dt;
  nv_ = model_.nv;
  if (model_.joints.empty() || model_.joints[0].type != skeleton::JointType::kFreeFlyer)
    fail(src, "model", "the controller expects a free-flyer root (model '" + model_.name + "')");
  total_mass_ = model_.totalMass();

  // b_a, k_int, b_int per velocity coordinate (root: body twist (ω, v))
  const auto names = model_.coordinateNames();
  b_a_.setConstant(nv_, c.b_a.joints);
  b_a_.head<3>().setConstant(c.b_a.root_angular);
  b_a_.segment<3>(3).setConstant(c.b_a.root_linear);
  k_int_.setConstant(nv_, c.internal.enabled ? c.internal.stiffness : 0.0);
  b_int_.setConstant(nv_, c.internal.enabled ? c.internal.damping : 0.0);
  k_int_.head<6>().setZero();
  b_int_.head<6>().setZero();
  const auto coordinate = [&](const std::string& field, const std::string& name) {
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end() || it - names.begin() < 6) {
      std::string list;
      for (size_t k = 6; k < names.size(); ++k) list += (k > 6 ? ", " : "") + names[k];
      fail(src, field, "unknown coordinate '" + name + "' (root: use root_linear/root_angular; coordinates: " + list + ")");
    }
    return static_cast<int>(it - names.begin());
  };
  for (const auto& [name, v] : c.b_a.coordinates) {
    if (!(v > 0) || !std::isfinite(v)) fail(src, "b_a.coordinates." + name, "must be finite and > 0");
    b_a_(coordinate("b_a.coordinates", name)) = v;
  }
  for (const auto& [name, v] : c.internal.coordinates) {
    if (!(v >= 0) || !std::isfinite(v)) fail(src, "internal.coordinates." + name, "must be finite and >= 0");
    if (c.internal.enabled) k_int_(coordinate("internal.coordinates", name)) = v;
  }
  b_a_inv_ = b_a_.cwiseInverse();
  q_d_ = c.internal.posture == "neutral" ? model_.neutralConfiguration() : skeleton::standingConfiguration(model_);
  if (c.internal.posture != "neutral" && c.internal.posture != "standing")
    fail(src, "internal.posture", "expected 'standing' or 'neutral'");

  // control frames
  frames_.clear();
  support_cols_.clear();
  mechanisms_.clear();
  std::vector<const ControlFrameConfig*> with_mechanism;
  for (const ControlFrameConfig& cf : c.frames) {
    const std::string where = cf.where.empty() ? src : cf.where;
    const std::string field = "control frame '" + cf.name + "'";
    if (cf.name.empty()) fail(where, "control frame", "empty name");
    for (const auto& f : frames_)
      if (f.name == cf.name) fail(where, field, "duplicate name");
    int fidx = model_.findFrame(cf.frame);
    if (fidx < 0) {
      const int seg = model_.findSegment(cf.frame);
      if (seg >= 0)
        for (size_t k = 0; k < model_.frames.size() && fidx < 0; ++k)
          if (model_.frames[k].joint == model_.segments[seg].joint) fidx = static_cast<int>(k);
    }
    if (fidx < 0) {
      std::string list;
      for (const auto& fr : model_.frames) list += (list.empty() ? "" : ", ") + fr.name;
      fail(where, field + ".frame", "no frame or segment '" + cf.frame + "' in model '" + model_.name + "' (frames: " + list + ")");
    }
    if (!cf.offset.allFinite() || !math::isRotation(cf.offset.R, 1e-6)) fail(where, field + ".offset", "not a rigid transform");
    if (!finiteGains(cf.stiffness) || !finiteGains(cf.damping))
      fail(where, field, "stiffness and damping must be finite and >= 0");
    if (!(cf.weight > 0) || !std::isfinite(cf.weight)) fail(where, field + ".weight", "must be finite and > 0");
    if (cf.priority < 0) fail(where, field + ".priority", "must be >= 0");
    ControlFrameState s;
    s.name = cf.name;
    s.frame = fidx;
    s.priority = cf.priority;
    s.enabled = cf.enabled;
    s.offset = cf.offset;
    s.stiffness = cf.stiffness * cf.weight;
    s.damping = cf.damping * cf.weight;
    frames_.push_back(s);
    std::vector<int> cols;
    for (int k : model_.support[model_.frames[fidx].joint])
      for (int v = 0; v < model_.joints[k].nv; ++v) cols.push_back(model_.joints[k].idx_v + v);
    support_cols_.push_back(cols);
    mechanisms_.emplace_back();
    if (cf.mechanism) with_mechanism.push_back(&cf);
  }
  const int nf = numFrames();
  rows_ = 6 * nf;

  // priority order (stable), rows, levels
  order_.resize(nf);
  for (int i = 0; i < nf; ++i) order_[i] = i;
  std::stable_sort(order_.begin(), order_.end(), [&](int a, int b) { return frames_[a].priority < frames_[b].priority; });
  frame_row_.assign(nf, 0);
  level_begin_.clear();
  for (int k = 0; k < nf; ++k) {
    frame_row_[order_[k]] = 6 * k;
    if (k == 0 || frames_[order_[k]].priority != frames_[order_[k - 1]].priority) level_begin_.push_back(k);
  }
  level_projectors_.clear();
  if (c.projector == ProjectorMethod::kSvd) {
    for (size_t l = 0; l < level_begin_.size(); ++l)
      level_projectors_.emplace_back(6 * level_begin_[l], nv_, c.projector, c.rank_tolerance);
    internal_projector_ = WeightedNullSpace(rows_, nv_, c.projector, c.rank_tolerance);
  } else {
    gram_factor_ = PriorityGramFactor(rows_, nv_, c.rank_tolerance);
  }
  frame_pairs_.clear();
  for (int a = 0; a < nf; ++a)
    for (int b = 0; b < nf; ++b) {
      if (frame_row_[a] < frame_row_[b]) continue;
      FramePair fp;
      fp.frame_a = a;
      fp.frame_b = b;
      for (int col : support_cols_[a])
        if (std::find(support_cols_[b].begin(), support_cols_[b].end(), col) != support_cols_[b].end())
          fp.cols.push_back(col);
      if (!fp.cols.empty()) frame_pairs_.push_back(std::move(fp));
    }
  gram_.setZero(rows_, rows_);

  // buffers
  for (VectorX* v : {&qdot_, &qdot_prev_, &qdot_free_, &dq_int_, &gamma0_, &gamma_task_, &gamma_level_, &gamma_int_,
                     &gamma_g_, &gamma_c_, &gamma_, &tmp_, &k_j_, &b_j_, &dq_j_, &gamma_j_})
    v->setZero(nv_);
  q_next_.setZero(model_.nq);
  q_j_.setZero(model_.nq);
  J_.setZero(rows_, nv_);
  JB_.setZero(rows_, nv_);
  factor_ = math::TreeCholesky(model_.velocityParents());
  b_diag_.setOnes(nv_);
  b_lower_.setZero(factor_.packedSize());
  factor_.computePacked(b_diag_, b_lower_);
  b_stale_ = true;
  b_slots_.assign(static_cast<std::size_t>(nf), {});
  for (int i = 0; i < nf; ++i) {
    const std::vector<int>& cols = support_cols_[static_cast<std::size_t>(i)];
    for (std::size_t a = 0; a < cols.size(); ++a)
      for (std::size_t b = 0; b < a; ++b) {
        const int slot = factor_.packedIndex(std::max(cols[a], cols[b]), std::min(cols[a], cols[b]));
        if (slot < 0)  // a frame's support is a chain of the tree: every pair is ancestor and descendant
          throw std::logic_error("controller: control frame '" + frames_[static_cast<std::size_t>(i)].name + "': columns " +
                                 std::to_string(cols[a]) + " and " + std::to_string(cols[b]) + " of its support are not on one branch");
        b_slots_[static_cast<std::size_t>(i)].push_back(slot);
      }
  }
  wrench_ff_.assign(nf, Vector6::Zero());
  damping_total_.assign(nf, Vector6::Zero());
  vd_c_.assign(nf, Vector6::Zero());
  ve_c_.assign(nf, Vector6::Zero());
  observer_ = EnergyObserver(c.internal.observer);

  reset(q0);
  for (const ControlFrameConfig* cf : with_mechanism) {
    try {
      attachMechanism(frameIndex(cf->name), *cf->mechanism);
    } catch (const std::invalid_argument& e) {
      fail(cf->where.empty() ? src : cf->where, "control frame '" + cf->name + "'.mechanism", e.what());
    }
  }
  for (const StabilityEntry& e : checkStability())
    if (e.ratio >= 2.0)
      spdlog::warn("control: {} is unstable with explicit Euler: k·dt/b = {:.3g} >= 2 (thesis 2.11); raise its damping or "
                   "lower its stiffness",
                   e.what, e.ratio);
}

void Controller::reset(const VectorX& q0) {
  MANNEQUIN_CHECK_ARGUMENT_SIZE(q0.size(), model_.nq, "q");
  if (!q0.allFinite()) throw std::invalid_argument("reset: q has non-finite values");
  q_ = q0;
  kinematics_at_q_ = false;
  qdot_.setZero();
  qdot_prev_.setZero();
  clearJointCoupling();
  qdot_free_.setZero();
  gamma_c_.setZero();
  frameKinematics();
  for (int i = 0; i < numFrames(); ++i) {
    ControlFrameState& f = frames_[i];
    f.target = f.pose;
    f.target_twist.setZero();
    f.error.setZero();
    f.wrench.setZero();
    f.twist.setZero();
    f.port.reset();
    f.mechanism_port.reset();
    if (mechanisms_[i] && f.mechanism_enabled) mechanisms_[i]->attachTo(f.pose);
  }
  observer_.reset();
  port_internal_.reset();
  port_gravity_.reset();
  port_constraint_.reset();
  port_joint_.reset();
  dissipated_.reset();
  have_internal_power_ = false;
  potential_ = 0;
  time_ = 0;
  free_motion_ready_ = false;
  skeleton::centerOfMass(model_, data_);  // data(): the poses (frameKinematics) and the CoM at q0
}

TargetStatus Controller::setTarget(int i, const SE3& oMd) { return setTarget(i, oMd, Vector6::Zero()); }

TargetStatus Controller::setTarget(int i, const SE3& oMd, const Vector6& target_twist) {
  checkFrame(i);
  if (!oMd.allFinite() || !target_twist.allFinite()) return TargetStatus::kNonFinite;  // previous target kept
  if (!math::isRotation(oMd.R, 1e-6)) return TargetStatus::kNotRotation;
  frames_[i].target = oMd;
  frames_[i].target_twist = target_twist;
  return TargetStatus::kOk;
}

void Controller::setFrameEnabled(int i, bool enabled) {
  checkFrame(i);
  frames_[i].enabled = enabled;
}

void Controller::setGains(int i, const Vector6& stiffness, const Vector6& damping) {
  checkFrame(i);
  if (!finiteGains(stiffness) || !finiteGains(damping))
    throw std::invalid_argument(describe(i) + ": stiffness and damping must be finite and >= 0");
  frames_[i].stiffness = stiffness;
  frames_[i].damping = damping;
}

void Controller::attachMechanism(int i, const MechanismConfig& m) {
  checkFrame(i);
  if (!finiteGains(m.stiffness) || !finiteGains(m.damping))
    throw std::invalid_argument(describe(i) + ": mechanism stiffness and damping must be finite and >= 0");
  try {
    mechanisms_[i].emplace(m.spec);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(describe(i) + ": " + e.what());
  }
  ControlFrameState& f = frames_[i];
  f.has_mechanism = true;
  f.mechanism_enabled = false;
  f.mechanism_stiffness = m.stiffness;
  f.mechanism_damping = m.damping;
  if (m.enabled) setMechanismEnabled(i, true);
}

void Controller::setMechanismEnabled(int i, bool enabled) {
  checkFrame(i);
  if (!mechanisms_[i]) throw std::invalid_argument(describe(i) + ": no virtual mechanism attached");
  ControlFrameState& f = frames_[i];
  if (enabled && !f.mechanism_enabled) {
    // the effector starts at the projection of the control frame's current pose
    skeleton::forwardKinematics(model_, data_, q_);
    mechanisms_[i]->attachTo(data_.oMf[f.frame] * f.offset);
    free_motion_ready_ = false;
  }
  f.mechanism_enabled = enabled;
}

const VirtualMechanism& Controller::mechanism(int i) const {
  checkFrame(i);
  if (!mechanisms_[i]) throw std::invalid_argument(describe(i) + ": no virtual mechanism attached");
  return *mechanisms_[i];
}

VirtualMechanism& Controller::mechanism(int i) {
  checkFrame(i);
  if (!mechanisms_[i]) throw std::invalid_argument(describe(i) + ": no virtual mechanism attached");
  return *mechanisms_[i];
}

void Controller::setJointCoupling(const VectorX& q_j, const VectorX& stiffness, const VectorX& damping) {
  if (q_j.size() != model_.nq || stiffness.size() != nv_ || damping.size() != nv_)
    throw std::invalid_argument("setJointCoupling: sizes " + std::to_string(q_j.size()) + ", " + std::to_string(stiffness.size()) +
                                ", " + std::to_string(damping.size()) + ", expected " + std::to_string(model_.nq) + ", " +
                                std::to_string(nv_) + ", " + std::to_string(nv_));
  // name the argument and the coordinate (ball and free-flyer q entries share their joint's names)
  const auto coordinate = [&](Eigen::Index k) {
    const std::vector<std::string> names = model_.coordinateNames();
    return std::to_string(k) + (k < static_cast<Eigen::Index>(names.size()) ? " ('" + names[static_cast<std::size_t>(k)] + "')" : "");
  };
  for (const auto& [what, v] : {std::pair<const char*, const VectorX*>{"q_j", &q_j}, {"stiffness", &stiffness}, {"damping", &damping}})
    for (Eigen::Index k = 0; k < v->size(); ++k)
      if (!std::isfinite((*v)(k)))
        throw std::invalid_argument(std::string("setJointCoupling: ") + what + "(" + coordinate(k) + ") is not finite (coupling kept)");
  for (const auto& [what, v] : {std::pair<const char*, const VectorX*>{"stiffness", &stiffness}, {"damping", &damping}})
    for (Eigen::Index k = 0; k < v->size(); ++k)
      if ((*v)(k) < 0)
        throw std::invalid_argument(std::string("setJointCoupling: ") + what + "(" + coordinate(k) + ") = " + std::to_string((*v)(k)) +
                                    " is negative (coupling kept)");
  q_j_ = q_j;
  k_j_ = stiffness;
  b_j_ = damping;
  joint_coupling_ = true;
}

void Controller::clearJointCoupling() {
  joint_coupling_ = false;
  gamma_j_.setZero();
}

void Controller::setPosture(const VectorX& q_d) {
  MANNEQUIN_CHECK_ARGUMENT_SIZE(q_d.size(), model_.nq, "q_d");
  if (!q_d.allFinite()) throw std::invalid_argument("setPosture: q_d has non-finite values (posture kept)");
  q_d_ = q_d;
}

//---- stage 1 pieces ----

void Controller::frameKinematics() {
  if (!kinematics_at_q_) skeleton::forwardKinematics(model_, data_, q_);
  kinematics_at_q_ = true;
  skeleton::computeJointJacobians(model_, data_);
  for (int i = 0; i < numFrames(); ++i) {
    ControlFrameState& f = frames_[i];
    f.pose = data_.oMf[f.frame] * f.offset;
    const int r = frame_row_[i];
    const Matrix3 Rt = f.pose.R.transpose();
    const Vector3& p = f.pose.p;
    // body Jacobian of the control frame: ω_b = Rᵀω, v_b = Rᵀ(v − p × ω) on the supporting columns
    for (int col : support_cols_[i]) {
      if (!f.enabled) {
        J_.block<6, 1>(r, col).setZero();
        continue;
      }
      const Vector3 w = data_.J.col(col).head<3>();
      const Vector3 v = data_.J.col(col).tail<3>();
      J_.block<3, 1>(r, col) = Rt * w;
      J_.block<3, 1>(r + 3, col) = Rt * (v - p.cross(w));
    }
  }
}

void Controller::couplingTerms() {
  for (int i = 0; i < numFrames(); ++i) {
    ControlFrameState& f = frames_[i];
    const int r = frame_row_[i];
    if (!f.enabled) {
      wrench_ff_[i].setZero();
      damping_total_[i].setZero();
      JB_.middleRows<6>(r).setZero();
      continue;
    }
    // target coupling (2.12): spring on e = (log(RᵀR_d), Rᵀ(p_d − p)), feed-forward of the target twist
    const SE3 cMd = f.pose.inverse() * f.target;
    f.error = couplingError(f.pose, f.target, config_.coupling_error);
    vd_c_[i] = math::actTwist(cMd, f.target_twist);
    Vector6 W = f.stiffness.cwiseProduct(f.error) + f.damping.cwiseProduct(vd_c_[i]);
    Vector6 B = f.damping;
    // virtual mechanism coupling (constrained mode)
    if (f.mechanism_enabled && mechanisms_[i]) {
      const SE3 cMe = f.pose.inverse() * mechanisms_[i]->pose();
      f.mechanism_error = couplingError(f.pose, mechanisms_[i]->pose(), config_.coupling_error);
      ve_c_[i] = math::actTwist(cMe, mechanisms_[i]->twist());
      W += f.mechanism_stiffness.cwiseProduct(f.mechanism_error) + f.mechanism_damping.cwiseProduct(ve_c_[i]);
      B += f.mechanism_damping;
    } else {
      f.mechanism_error.setZero();
      ve_c_[i].setZero();
    }
    wrench_ff_[i] = W;
    damping_total_[i] = B;
    JB_.middleRows<6>(r) = B.cwiseSqrt().asDiagonal() * J_.middleRows<6>(r);
  }
}

void Controller::assembleFriction() {
  // b = b_a + Σ Jᵀ B J (2.17): per frame over its support columns only (JB_ is zero elsewhere), on the
  // tree's pattern (a frame's support is one branch: every pair of its columns is in it), packed
  b_diag_ = b_a_;
  b_lower_.setZero();
  double* lower = b_lower_.data();
  for (int i = 0; i < numFrames(); ++i) {
    if (!frames_[i].enabled) continue;
    const int r = frame_row_[i];
    const std::vector<int>& cols = support_cols_[i];
    const int* slot = b_slots_[static_cast<std::size_t>(i)].data();
    for (std::size_t a = 0; a < cols.size(); ++a) {
      const auto ja = JB_.block<6, 1>(r, cols[a]);
      for (std::size_t b = 0; b < a; ++b) lower[*slot++] += ja.dot(JB_.block<6, 1>(r, cols[b]));
      b_diag_(cols[a]) += ja.squaredNorm();
    }
  }
  factor_.computePacked(b_diag_, b_lower_);
  b_stale_ = true;
}

const MatrixX& Controller::apparentFriction() const {
  if (b_stale_) {
    b_.setZero(nv_, nv_);
    b_.diagonal() = b_diag_;
    const std::vector<int>& parent = factor_.parents();
    for (int k = 0; k < nv_; ++k)
      for (int i = parent[static_cast<std::size_t>(k)]; i >= 0; i = parent[static_cast<std::size_t>(i)]) {
        const int slot = factor_.packedIndex(k, i);
        b_(k, i) = b_(i, k) = b_lower_(slot);
      }
    b_stale_ = false;
  }
  return b_;
}

void Controller::gramOfTasks() {
  // G = J b_a⁻¹ Jᵀ, lower triangle, block by block over the columns both frames' rows reach (the
  // blocks of frames sharing no column are never written: zero since build())
  for (const FramePair& fp : frame_pairs_) {
    const int ra = frame_row_[fp.frame_a], rb = frame_row_[fp.frame_b];
    if (!frames_[fp.frame_a].enabled || !frames_[fp.frame_b].enabled) {
      gram_.block<6, 6>(ra, rb).setZero();
      continue;
    }
    Matrix6 block = Matrix6::Zero();
    for (int col : fp.cols) block.noalias() += (b_a_inv_(col) * J_.block<6, 1>(ra, col)) * J_.block<6, 1>(rb, col).transpose();
    gram_.block<6, 6>(ra, rb) = block;
  }
}

void Controller::factorGramOfTasks() {
  gramOfTasks();
  gram_factor_.compute(gram_);
}

StepStatus Controller::computeFreeMotion() {
  frameKinematics();
  couplingTerms();
  assembleFriction();

  // gravity Γ_g = M J_comᵀ g (the weight of every segment, 3.32)
  if (config_.gravity.squaredNorm() > 0) {
    skeleton::jacobianCenterOfMass(model_, data_);
    gamma_g_.noalias() = data_.Jcom.transpose() * (total_mass_ * config_.gravity);
  } else {
    gamma_g_.setZero();
  }

  // task torques by priority level (2.78–2.80): Γ = Γ_0 + Σ_k Π_prev(k)ᵀ Γ_k
  gamma_task_.setZero();
  bool gram_ready = false;  // gram_ of this step's J_
  const int nl = static_cast<int>(level_begin_.size());
  for (int l = 0; l < nl; ++l) {
    const int k0 = level_begin_[l];
    const int k1 = l + 1 < nl ? level_begin_[l + 1] : numFrames();
    gamma_level_.setZero();
    for (int k = k0; k < k1; ++k) {
      const int i = order_[k];
      gamma_level_.noalias() += J_.middleRows<6>(frame_row_[i]).transpose() * wrench_ff_[i];
    }
    if (l > 0) {
      if (config_.projector == ProjectorMethod::kSvd) {
        level_projectors_[l].compute(J_.topRows(6 * k0), b_a_inv_);
        level_projectors_[l].projectTorque(gamma_level_, gamma_level_);
      } else {
        if (!gram_ready) factorGramOfTasks();
        gram_ready = true;
        gram_factor_.projectTorque(J_, b_a_inv_, 6 * k0, gamma_level_, gamma_level_);
      }
    }
    gamma_task_ += gamma_level_;
  }

  // internal control (2.25) with the observer's α
  if (config_.internal.enabled) {
    differenceInPlace(model_, q_, q_d_, dq_int_);  // q_d ⊖ q
    potential_ = 0.5 * dq_int_.cwiseProduct(dq_int_).dot(k_int_);
    const double alpha = observer_.alpha();
    gamma0_ = alpha * (k_int_.cwiseProduct(dq_int_) - b_int_.cwiseProduct(qdot_prev_));
    if (config_.internal.projection == InternalProjection::kDynamic && rows_ > 0) {
      if (config_.projector == ProjectorMethod::kSvd) {
        internal_projector_.compute(J_, b_a_inv_);
        internal_projector_.projectTorque(gamma0_, gamma_level_);
      } else {
        if (!gram_ready) factorGramOfTasks();
        gram_ready = true;
        gram_factor_.projectTorque(J_, b_a_inv_, rows_, gamma0_, gamma_level_);
      }
    } else {
      gamma_level_ = gamma0_;
    }
    // observer: work of Γ_int over the last step by the trapezoidal rule, then the new α
    const double work = have_internal_power_ ? 0.5 * (gamma_int_ + gamma_level_).dot(qdot_prev_) * dt_ : 0.0;
    observer_.update(work, potential_, dt_);
    gamma_int_ = (alpha > 0 ? observer_.alpha() / alpha : 0.0) * gamma_level_;
  } else {
    gamma_int_.setZero();
  }

  // joint coupling (4.4.2): Γ_j = k_j∘(q_j ⊖ q) − b_j∘q̇_prev, every coordinate
  if (joint_coupling_) {
    differenceInPlace(model_, q_, q_j_, dq_j_);
    gamma_j_ = k_j_.cwiseProduct(dq_j_) - b_j_.cwiseProduct(qdot_prev_);
  }

  // free motion q̇_free = b⁻¹ Γ (2.19–2.20)
  gamma_ = gamma_task_ + gamma_int_ + gamma_g_ + gamma_j_;
  qdot_free_ = gamma_;
  gamma_c_.setZero();
  if (factor_.info() == Eigen::Success) factor_.solveInPlace(qdot_free_);
  if (!qdot_free_.allFinite() || factor_.info() != Eigen::Success) {
    ++non_finite_steps_;
    qdot_free_.setZero();
    qdot_.setZero();
    free_motion_ready_ = false;
    return StepStatus::kNonFinite;
  }
  qdot_ = qdot_free_;
  free_motion_ready_ = true;
  return StepStatus::kOk;
}

ForceStatus Controller::applyConstraintForce(const VectorX& gamma_c) {
  MANNEQUIN_CHECK_ARGUMENT_SIZE(gamma_c.size(), nv_, "constraint torque gamma_c");
  if (!gamma_c.allFinite()) return ForceStatus::kNonFinite;
  if (!free_motion_ready_) return ForceStatus::kNoFreeMotion;
  // q̇ = q̇_free + b⁻¹ J_cᵀ W_c (Alg. 4)
  tmp_ = gamma_c;
  factor_.solveInPlace(tmp_);
  qdot_ += tmp_;
  gamma_c_ += gamma_c;
  return ForceStatus::kOk;
}

void Controller::integrate() {
  if (!free_motion_ready_ && computeFreeMotion() != StepStatus::kOk) return;
  // energy at the ports with the final velocity (2.3)
  for (int i = 0; i < numFrames(); ++i) {
    ControlFrameState& f = frames_[i];
    if (!f.enabled) {
      f.twist.setZero();
      f.wrench.setZero();
      f.mechanism_wrench.setZero();
      f.port.add(0.0, dt_);
      f.mechanism_port.add(0.0, dt_);
      continue;
    }
    const Vector6 V = J_.middleRows<6>(frame_row_[i]) * qdot_;
    f.twist = V;
    f.wrench = f.stiffness.cwiseProduct(f.error) + f.damping.cwiseProduct(vd_c_[i] - V);
    f.port.add(f.wrench.dot(V), dt_);
    if (f.mechanism_enabled && mechanisms_[i]) {
      f.mechanism_wrench = f.mechanism_stiffness.cwiseProduct(f.mechanism_error) + f.mechanism_damping.cwiseProduct(ve_c_[i] - V);
      f.mechanism_port.add(f.mechanism_wrench.dot(V), dt_);
      // the mechanism moves under the coupling's reaction
      mechanisms_[i]->step(f.pose, V, f.mechanism_stiffness, f.mechanism_damping, dt_);
    } else {
      f.mechanism_wrench.setZero();
      f.mechanism_port.add(0.0, dt_);
    }
  }
  have_internal_power_ = config_.internal.enabled;
  port_internal_.add(gamma_int_.dot(qdot_), dt_);
  port_gravity_.add(gamma_g_.dot(qdot_), dt_);
  port_joint_.add(gamma_j_.dot(qdot_), dt_);
  port_constraint_.add(gamma_c_.dot(qdot_), dt_);
  dissipated_.add(qdot_.cwiseProduct(qdot_).dot(b_a_), dt_);

  // q_{k+1} = q_k ⊕ q̇ δt (2.7; SE(3) for the root)
  integrateInPlace(model_, q_, qdot_, dt_, q_next_);
  q_.swap(q_next_);
  qdot_prev_ = qdot_;
  time_ += dt_;
  free_motion_ready_ = false;
  // the poses and CoM at q_{k+1}: what the caller reads between steps, and stage 1's forward kinematics
  skeleton::forwardKinematics(model_, data_, q_);
  skeleton::centerOfMass(model_, data_);
  kinematics_at_q_ = true;
}

StepStatus Controller::step() {
  const StepStatus s = computeFreeMotion();
  if (s != StepStatus::kOk) return s;
  integrate();
  return StepStatus::kOk;
}

std::vector<StabilityEntry> Controller::checkStability() {
  frameKinematics();
  couplingTerms();
  assembleFriction();
  free_motion_ready_ = false;
  std::vector<StabilityEntry> out;
  // per axis: k δt e_aᵀ J b⁻¹ Jᵀ e_a, i.e. k δt / b_eff along that axis (2.11)
  MatrixX C = MatrixX::Zero(rows_, rows_);  // J b⁻¹ Jᵀ
  if (rows_ > 0) {
    MatrixX X = J_.transpose();
    factor_.solveInPlace(X);  // b⁻¹ Jᵀ
    C = J_ * X;
  }
  VectorX Ksqrt = VectorX::Zero(rows_);
  for (int i = 0; i < numFrames(); ++i) {
    const ControlFrameState& f = frames_[i];
    if (!f.enabled) continue;
    const int r = frame_row_[i];
    for (int a = 0; a < 6; ++a) {
      double k = f.stiffness(a) + (f.mechanism_enabled ? f.mechanism_stiffness(a) : 0.0);
      Ksqrt(r + a) = std::sqrt(k);
      if (k > 0) out.push_back({f.name + " " + kAxis[a], k * dt_ * C(r + a, r + a)});
    }
  }
  if (rows_ > 0) {
    const MatrixX S = Ksqrt.asDiagonal() * C * Ksqrt.asDiagonal();
    const Eigen::SelfAdjointEigenSolver<MatrixX> es(S, Eigen::EigenvaluesOnly);
    out.push_back({"coupled control frames", dt_ * es.eigenvalues().maxCoeff()});
  }
  const auto names = model_.coordinateNames();
  for (int k = 0; k < nv_; ++k)
    if (k_int_(k) > 0) out.push_back({"internal " + names[k], k_int_(k) * dt_ / b_a_(k)});
  return out;
}

}  // namespace mannequin::control
