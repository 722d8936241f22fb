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
  const double dt = model_.config.step;
  const auto t0 = Clock::now();
  bool ok = computeFreeMotion();
  const auto t1 = Clock::now();
  updateContacts();
  updateSupport();
  const auto t2 = Clock::now();
  // stage 2: every row in one LCP (systems that failed stage 1 get no force: their q̇ is zero)
  data_->diagnostics.solver = data_->physics->solver->solve(dt);
  const auto t3 = Clock::now();
  ok = integrate() && ok;
  const auto t4 = Clock::now();
  data_->diagnostics.free_motion_s = seconds(t0, t1);
  data_->diagnostics.collision_s = seconds(t1, t2);
  data_->diagnostics.constraints_s = seconds(t2, t3);
  data_->diagnostics.integrate_s = seconds(t3, t4);
  computeDiagnostics();
  if (model_.config.physics.force_margin_period > 0) {
    const auto every = static_cast<std::uint64_t>(std::max(1.0, std::round(model_.config.physics.force_margin_period / dt)));
    if (data_->steps % every == 0) updateForceMargins();
  }
  if (!data_->physics->balance_loops.empty()) {
    const auto every = static_cast<std::uint64_t>(std::max(1.0, std::round(model_.config.physics.balance_controller.period / dt)));
    if (data_->steps % every == 0) updateBalanceController();
  }
  return ok;
}

bool World::computeFreeMotion() {
  PhysicsData& P = *data_->physics;
  const double dt = model_.config.step;
  bool ok = true;
  // every mannequin at q_k (kinematics and Jacobians at q_k in its controller)
  for (std::size_t m = 0; m < data_->mannequins.size(); ++m) {
    P.stepping[m] = data_->mannequins[m].controller->beginStep(dt, /*own_limits=*/false) ? 1 : 0;  // the limits are rows of the shared LCP
    if (!P.stepping[m]) {
      ok = false;
      ++data_->failed_steps;
    }
  }
  for (constraints::RigidObject& o : P.objects) o.computeFreeMotion(model_.config.physics.gravity, dt);
  return ok;
}

void World::updateContacts() {
  PhysicsData& P = *data_->physics;
  // contacts at q_k: a query every query_period_steps; in between, the last query's witness points are
  // re-evaluated at q_k by the contact rows
  data_->diagnostics.failed_collision_pairs = 0;
  if (data_->steps % static_cast<std::uint64_t>(model_.config.physics.query_period_steps) != 0) return;
  for (std::size_t m = 0; m < data_->mannequins.size(); ++m)
    P.cw.updateMannequin(P.cw_mannequin[m], data_->mannequins[m].controller->controller().data());
  P.cw.query(data_->steps, P.set);
  data_->diagnostics.failed_collision_pairs = P.set.stats.failed_pairs;
  // a held object and the mannequin holding it: the grasp rows couple them, no contact rows
  bool any_grasp = false;
  for (const PhysicsData::GraspRecord& g : P.grasp_records) any_grasp = any_grasp || g.object >= 0;
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
  PhysicsData& P = *data_->physics;
  bool ok = true;
  // stage 3: integration, kinematics at q_{k+1}
  for (std::size_t m = 0; m < data_->mannequins.size(); ++m)
    if (P.stepping[m] && !data_->mannequins[m].controller->endStep()) {
      ok = false;
      ++data_->failed_steps;
    }
  for (std::size_t i = 0; i < P.objects.size(); ++i) {
    P.objects[i].integrate(model_.config.step);
    P.cw.setBodyPose(P.object_body[i], P.objects[i].pose());
  }
  return ok;
}

bool World::kinematicStep() {
  bool ok = true;
  for (MannequinData& md : data_->mannequins)
    if (!md.stepper->step(model_.config.step)) {
      ok = false;
      ++data_->failed_steps;
    }
  for (std::size_t m = 0; m < data_->mannequins.size(); ++m)
    data_->mannequin_diagnostics[m].worst_joint_limit_excess_rad = worstLimitExcess(model_.mannequins[m].model, data_->mannequins[m].stepper->q());
  return ok;
}

}  // namespace mannequin::sim
