// The balance stages of a World step: the support regions, the force margins (thesis 3.93-3.95)
// and the multi-contact balance controller in the loop (Algorithm 5, 4.4.2).
#include "world_state.hpp"

namespace mannequin::sim {

void World::updateBalanceController() {
  PhysicsData& P = *data_->physics;
  const PhysicsConfig& pc = model_.config.physics;
  const BalanceControllerConfig& bc = pc.balance_controller;
  for (std::size_t m = 0; m < data_->mannequins.size(); ++m) {
    const skeleton::Model& model = model_.mannequins[m].model;
    MannequinData& man = data_->mannequins[m];
    PhysicsData::BalanceLoop& L = P.balance_loops[m];
    MannequinDiagnostics& md = data_->mannequin_diagnostics[m];
    if (!man.calibrated) continue;
    const skeleton::Data& d = man.stepper->data();  // the simulated mannequin's kinematics at q_{k+1}
    // Algorithm 5 iterates on the controller's own configuration q_b (from the simulated q at the
    // start): q_b ← q_b ⊕ δq. Re-starting each solve from the simulated q instead would make the sag
    // of the couplings under gravity the next solve's starting point, and the body would sink.
    if (!L.driving) {
      L.q_b = man.stepper->q();
      skeleton::forwardKinematics(model, L.data, L.q_b);
      L.fraction = 0.0;
    }
    balance::VariationalBalanceProblem& bp = L.problem;
    // the touching contacts with the static scene, as in the force margins, on the joints of their segments
    bp.contacts.clear();
    for (const ContactReport& r : data_->contacts) {
      const int ma = P.body_mannequin[static_cast<std::size_t>(r.body_a)], mb = P.body_mannequin[static_cast<std::size_t>(r.body_b)];
      const bool on_a = ma == static_cast<int>(m), on_b = mb == static_cast<int>(m);
      if (on_a == on_b) continue;
      const int other = on_a ? r.body_b : r.body_a;
      if (P.cw.bodyKind(other) != collision::BodyKind::kStatic) continue;
      if (!(r.normal_force > 0 || r.distance <= pc.foot_contact_tolerance)) continue;
      const int joint = P.body_joint[static_cast<std::size_t>(on_a ? r.body_a : r.body_b)];
      if (joint < 0) continue;
      balance::BodyContact c;
      c.joint = joint;
      c.local_point = d.oMi[static_cast<std::size_t>(joint)].actInv(r.point);
      c.normal = on_b ? r.normal : math::Vector3(-r.normal);
      c.mu = P.contacts->friction(r.body_a, r.body_b);
      // desired force (3.69): what the contact carries now (the LCP's normal force). With 0 the criterion
      // would spread the weight evenly over the points and pull the CoM to their centroid, and a hand
      // on the wall would be asked to let go.
      c.desired_force = r.normal_force * c.normal;
      bp.contacts.push_back(c);
    }
    // each body in contact held (Alg. 5's first loop) where the simulation has it: the controller's body is
    // brought there by log(H_d H⁻¹), at most max_task_step (m) and max_step (rad) per solve, so that the
    // equality rows stay within the step's bounds (the controller follows the contacts as simulated)
    bp.held = balance::holdCurrentPoses(bp.contacts, L.data.oMi);
    for (balance::HeldBody& h : bp.held) {
      const math::SE3& sim = d.oMi[static_cast<std::size_t>(h.joint)];
      math::Vector3 dp = sim.p - h.desired.p;
      if (dp.norm() > bc.max_task_step) dp *= bc.max_task_step / dp.norm();
      math::Vector3 dr = math::logSO3(sim.R * h.desired.R.transpose());
      if (dr.norm() > bc.max_step) dr *= bc.max_step / dr.norm();
      h.desired = math::SE3(math::expSO3(dr) * h.desired.R, h.desired.p + dp);
    }
    // the other driven frames reach for their mocap targets (3.106), unless their body is held
    bp.tasks.clear();
    for (std::size_t i = 0; i < man.frames.size(); ++i) {
      if (L.taken[i] || man.weights[i] <= 0) continue;
      const int fi = man.frames[i].frame_index;
      const int joint = model.frames[static_cast<std::size_t>(fi)].joint;
      bool held = false;
      for (const balance::HeldBody& h : bp.held) held = held || h.joint == joint;
      if (!held) bp.tasks.push_back({fi, man.frames[i].target.p});
    }
    bp.gravity = pc.gravity;
    bp.edges = bc.edges;
    bp.max_step = bc.max_step;
    bp.max_task_step = bc.max_task_step;
    bp.dq_weight = bc.dq_weight;
    bp.com_margins.clear();
    bp.margins_at_com = true;  // each push held at the posture's own CoM (what forceMargin measures)
    // the internal control (4.1): back towards the calibrated posture where nothing else decides
    control::differenceInPlace(model, L.q_b, man.q_posture, bp.dq_desired);
    bp.dq_desired *= bc.posture_gain;
    md.balance_contacts = static_cast<int>(bp.contacts.size());
    if (bp.contacts.empty()) {
      // nothing holds it (a jump): no static equilibrium; the mocap and q_c take back over
      md.balance_status = balance::BalanceStatus::kInfeasible;
      md.balance_margin_fraction = 0.0;
      ++md.balance_failures;
      if (L.driving) {
        man.stepper->setPosture(man.q_posture);
        man.controller->controller().clearJointCoupling();
      }
      L.driving = false;
      md.balance_driving = false;
      continue;
    }
    // the margins as a continuation: a posture far from holding the pushes asked for cannot get there in
    // one small step (|δq| ≤ max_step), so each solve asks for a fraction s of them — 5 % more than
    // the last solve held, else what it held, 20 % less, none — and the fraction grows to 1 as the body
    // moves (MannequinDiagnostics::balance_margin_fraction). Infeasible even with none: reported as such.
    const math::Vector3 com_b = skeleton::centerOfMass(model, L.data);  // the controller's CoM, at q_b
    const double last = L.fraction;
    double tries[4] = {std::min(1.0, last + 0.05), last, std::max(0.0, last - 0.2), 0.0};
    const int ntries = bc.force_margins.empty() ? 1 : 4;
    const balance::VariationalBalanceResult* result = nullptr;
    md.balance_tasks_dropped = false;
    for (int t = 0; t < ntries; ++t) {
      if (t > 0 && tries[t] >= tries[t - 1]) continue;  // the same fraction again
      bp.force_margins.clear();
      for (const math::Vector3& F : bc.force_margins) {
        // a push s F at the CoM: the wrench (moment about the world origin, force) = (x_com × sF, sF)
        const math::Vector3 sF = tries[t] * F;
        math::Vector6 w;
        w << com_b.cross(sF), sF;
        bp.force_margins.push_back(w);
      }
      result = &L.solver->solve(bp, L.q_b);
      ++md.balance_solves;
      if (result->status == balance::BalanceStatus::kDegenerate && !bp.tasks.empty()) {
        // the tasks repeat held rows (a hand whose forearm leans on the wall): the contacts come first
        bp.tasks.clear();
        md.balance_tasks_dropped = true;
        result = &L.solver->solve(bp, L.q_b);
        ++md.balance_solves;
      }
      if (result->status == balance::BalanceStatus::kSolved) {
        L.fraction = bc.force_margins.empty() ? 1.0 : tries[t];
        break;
      }
    }
    const balance::VariationalBalanceResult& res = *result;
    md.balance_status = res.status;
    md.balance_margin_fraction = res.status == balance::BalanceStatus::kSolved ? L.fraction : 0.0;
    if (res.status == balance::BalanceStatus::kSolved) {
      L.q_b = skeleton::integrate(model, L.q_b, res.dq);
      skeleton::forwardKinematics(model, L.data, L.q_b);
      md.balance_com = res.com;
      L.driving = true;
      man.stepper->setPosture(L.q_b);
      man.controller->controller().setJointCoupling(L.q_b, L.k, L.b);
    } else {
      ++md.balance_failures;
      // no equilibrium with these contacts even without margins: q_b holds (the last posture in equilibrium)
    }
    md.balance_driving = L.driving;
  }
}

void World::applyBalanceTargets(std::size_t m) {
  // the frames the balance controller took over: their poses at q_b, held (V_d = 0)
  const PhysicsData::BalanceLoop& L = data_->physics->balance_loops[m];
  if (!L.driving) return;
  MannequinData& man = data_->mannequins[m];
  for (const int i : model_.mannequins[m].balance_frames) {
    DrivenFrame& st = man.frames[static_cast<std::size_t>(i)];
    st.target = L.data.oMf[static_cast<std::size_t>(st.frame_index)];
    man.stepper->setTarget(i, st.target, math::Vector6::Zero(), man.weights[static_cast<std::size_t>(i)]);
  }
}

void World::updateForceMargins() {
  PhysicsData& P = *data_->physics;
  const PhysicsConfig& pc = model_.config.physics;
  static const std::vector<math::Vector3> kHorizontal = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}};
  for (std::size_t m = 0; m < data_->mannequins.size(); ++m) {
    MannequinDiagnostics& md = data_->mannequin_diagnostics[m];
    if (!data_->mannequins[m].calibrated) {
      md.force_margin_n = std::numeric_limits<double>::quiet_NaN();
      md.force_margin_contacts = 0;
      continue;
    }
    balance::StaticBalanceProblem& bp = P.margin_problem;
    bp.contacts.clear();
    for (const ContactReport& r : data_->contacts) {
      const int ma = P.body_mannequin[static_cast<std::size_t>(r.body_a)], mb = P.body_mannequin[static_cast<std::size_t>(r.body_b)];
      const bool on_a = ma == static_cast<int>(m), on_b = mb == static_cast<int>(m);
      if (on_a == on_b) continue;  // not this mannequin's, or a self contact
      const int other = on_a ? r.body_b : r.body_a;
      if (P.cw.bodyKind(other) != collision::BodyKind::kStatic) continue;  // objects and mannequins move
      if (!(r.normal_force > 0 || r.distance <= pc.foot_contact_tolerance)) continue;
      // the normal points from a to b: the scene pushes the mannequin along it when the mannequin is b
      bp.contacts.push_back({r.point, on_b ? r.normal : math::Vector3(-r.normal), P.contacts->friction(r.body_a, r.body_b), math::Vector3::Zero()});
    }
    md.force_margin_contacts = static_cast<int>(bp.contacts.size());
    if (bp.contacts.empty()) {
      md.force_margin_n = 0.0;  // nothing holds it
      continue;
    }
    bp.mass = model_.mannequins[m].model.totalMass();
    bp.gravity = pc.gravity;
    bp.fix_com = true;
    bp.desired_com = md.com;
    bp.alpha = 1.0;
    const balance::ForceMarginResult res = balance::forceMargin(P.margin_solver, bp, kHorizontal, md.com, pc.force_margin_max, 1.0);
    md.force_margin_n = res.status == balance::BalanceStatus::kSolved ? res.margin_n : 0.0;
  }
}

void World::updateSupport() {
  // each mannequin's support: the floor-side witness points of its feet's floor contacts within the
  // tolerance (the contact set of the last query, at the segment poses of that query)
  PhysicsData& P = *data_->physics;
  for (auto& sp : P.support) sp.clear();
  if (P.floor_body >= 0)
    for (const collision::Contact& c : P.set.contacts) {
      if (c.distance > model_.config.physics.foot_contact_tolerance) continue;
      const bool a_floor = c.body_a == P.floor_body, b_floor = c.body_b == P.floor_body;
      if (a_floor == b_floor) continue;
      const int foot = a_floor ? c.body_b : c.body_a;
      if (!P.body_is_foot[static_cast<std::size_t>(foot)]) continue;
      const int m = P.body_mannequin[static_cast<std::size_t>(foot)];
      std::vector<math::Vector3>& sp = P.support[static_cast<std::size_t>(m)];
      if (sp.size() == sp.capacity()) continue;  // beyond max_points: the hull of the first ones
      sp.push_back(P.cw.bodyPose(foot).act(a_floor ? c.point_b : c.point_a));
    }
  for (std::size_t m = 0; m < data_->mannequins.size(); ++m) {
    P.balance[m]->setSupport(P.support[m]);
    if (!model_.config.physics.balance_rows) P.balance[m]->evaluate();  // the distance without the row
  }
}

}  // namespace mannequin::sim
