// The physics stages of a World step (thesis Alg. 4): free motion at q_k, contacts, one LCP for every
// row, integration; then the step's diagnostics and the periodic balance stages.
#include "world_state.hpp"

namespace mannequin::sim {

namespace {
double seconds(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}
}  // namespace

bool World::physicsStep() {
  using Clock = std::chrono::steady_clock;
  const double dt = config_.step;
  const auto t0 = Clock::now();
  bool ok = computeFreeMotion();
  const auto t1 = Clock::now();
  updateContacts();
  updateSupport();
  const auto t2 = Clock::now();
  // stage 2: every row in one LCP (systems that failed stage 1 get no force: their q̇ is zero)
  diagnostics_.solver = physics_->solver->solve(dt);
  const auto t3 = Clock::now();
  ok = integrate() && ok;
  const auto t4 = Clock::now();
  diagnostics_.free_motion_s = seconds(t0, t1);
  diagnostics_.collision_s = seconds(t1, t2);
  diagnostics_.constraints_s = seconds(t2, t3);
  diagnostics_.integrate_s = seconds(t3, t4);
  computeDiagnostics();
  if (config_.physics.force_margin_period > 0) {
    const auto every = static_cast<std::uint64_t>(std::max(1.0, std::round(config_.physics.force_margin_period / dt)));
    if (steps_ % every == 0) updateForceMargins();
  }
  if (!physics_->balance_loops.empty()) {
    const auto every = static_cast<std::uint64_t>(std::max(1.0, std::round(config_.physics.balance_controller.period / dt)));
    if (steps_ % every == 0) updateBalanceController();
  }
  return ok;
}

bool World::computeFreeMotion() {
  Physics& P = *physics_;
  const double dt = config_.step;
  bool ok = true;
  // every mannequin at q_k (kinematics and Jacobians at q_k in its controller)
  for (std::size_t m = 0; m < mannequins_.size(); ++m) {
    P.stepping[m] = mannequins_[m]->controller->beginStep(dt, /*own_limits=*/false) ? 1 : 0;  // the limits are rows of the shared LCP
    if (!P.stepping[m]) {
      ok = false;
      ++failed_steps_;
    }
  }
  for (RigidObject& o : P.objects) o.computeFreeMotion(config_.physics.gravity, dt);
  return ok;
}

void World::updateContacts() {
  Physics& P = *physics_;
  // contacts at q_k: a query every query_period_steps; in between, the last query's witness points are
  // re-evaluated at q_k by the contact rows
  diagnostics_.failed_collision_pairs = 0;
  if (steps_ % static_cast<std::uint64_t>(config_.physics.query_period_steps) != 0) return;
  for (std::size_t m = 0; m < mannequins_.size(); ++m)
    P.cw.updateMannequin(P.cw_mannequin[m], mannequins_[m]->controller->controller().data());
  P.cw.query(steps_, P.set);
  diagnostics_.failed_collision_pairs = P.set.stats.failed_pairs;
  // a held object and the mannequin holding it: the grasp rows couple them, no contact rows
  bool any_grasp = false;
  for (const Physics::GraspRecord& g : P.grasp_records) any_grasp = any_grasp || g.object >= 0;
  if (any_grasp) {
    auto& v = P.set.contacts;
    v.erase(std::remove_if(v.begin(), v.end(),
                           [&](const collision::Contact& c) {
                             const int oa = P.body_object[static_cast<std::size_t>(c.body_a)];
                             const int ob = P.body_object[static_cast<std::size_t>(c.body_b)];
                             const int ma = P.body_mannequin[static_cast<std::size_t>(c.body_a)];
                             const int mb = P.body_mannequin[static_cast<std::size_t>(c.body_b)];
                             return (oa >= 0 && mb >= 0 && P.holds(mb, oa)) || (ob >= 0 && ma >= 0 && P.holds(ma, ob));
                           }),
            v.end());
  }
  P.contacts->setContacts(P.set);
}

bool World::integrate() {
  Physics& P = *physics_;
  bool ok = true;
  // stage 3: integration, kinematics at q_{k+1}
  for (std::size_t m = 0; m < mannequins_.size(); ++m)
    if (P.stepping[m] && !mannequins_[m]->controller->endStep()) {
      ok = false;
      ++failed_steps_;
    }
  for (std::size_t i = 0; i < P.objects.size(); ++i) {
    P.objects[i].integrate(config_.step);
    P.cw.setBodyPose(P.object_body[i], P.objects[i].pose());
  }
  return ok;
}

bool World::kinematicStep() {
  bool ok = true;
  for (auto& mp : mannequins_)
    if (!mp->stepper->step(config_.step)) {
      ok = false;
      ++failed_steps_;
    }
  for (std::size_t m = 0; m < mannequins_.size(); ++m)
    mannequin_diagnostics_[m].worst_joint_limit_excess_rad = worstLimitExcess(mannequins_[m]->model, mannequins_[m]->stepper->q());
  return ok;
}

}  // namespace mannequin::sim
