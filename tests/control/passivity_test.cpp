// Passivity (thesis 2.1, 2.2.1.4, 2.2.2.2) on the planar 3-DoF system of Fig. 2.9 / 2.19: two
// position ports (tip and end of link 2), a cyclic joint motion imposed on the first two joints,
// the port wrenches computed so that the system performs the cycle, E = ∫ W₁ᵀV₁ + W₂ᵀV₂ dt.
// Also the energy observer (end of 2.2.1.4) and the controller's port energies on the mannequin.
#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <vector>

#include "common.hpp"

using namespace mannequin;
using namespace mannequin::control;
using namespace mannequin::control::testing;

namespace {

using Vec3 = Eigen::Vector3d;
using Mat23 = Eigen::Matrix<double, 2, 3>;

// planar 3R arm, unit links: Jacobian of the end of link `upto` (2 or 3)
Mat23 pointJacobian(const Vec3& q, int upto) {
  Mat23 J = Mat23::Zero();
  double th = 0;
  std::vector<double> s(3), c(3);
  for (int i = 0; i < 3; ++i) {
    th += q(i);
    s[i] = std::sin(th);
    c[i] = std::cos(th);
  }
  for (int j = 0; j < 3; ++j)
    for (int i = j; i < upto; ++i) {
      J(0, j) -= s[i];
      J(1, j) += c[i];
    }
  return J;
}

enum class Law {
  kTask1ProjectedPotential,  // Fig. 2.10a: Γ = J₁ᵀW₁ − αΠ₁ᵀ∇U, q₃ free
  kTwoPortsPotential,        // Fig. 2.10b: Γ = J₁ᵀW₁ + J₂ᵀW₂ − α∇U
  kTwoPortsProjectedPotential,  // Fig. 2.10c: Γ = J₁ᵀW₁ + J₂ᵀW₂ − αΠ₁ᵀ∇U
  kTwoPorts,                 // Fig. 2.19c: Γ = J₁ᵀW₁ + J₂ᵀW₂
  kTwoPortsProjectedTask2,   // Fig. 2.19d: Γ = J₁ᵀW₁ + Π₁ᵀJ₂ᵀW₂
};

struct CycleRun {
  std::vector<double> cycle_end_energy;  // E after each cycle
  double min_energy = 0;
  double final_alpha = 1;
};

struct Params {
  Vec3 b_a = Vec3(0.2, 0.2, 0.2);  // joint friction
  double k = 10.0;                 // internal potential U = ½ k ‖q_d − q‖²
  Vec3 q_d = Vec3(0.3, 0.9, 0.6);
  Vec3 qc = Vec3(0.7, 1.2, 0.3);   // centre of the joint cycle
  double r = 0.5, period = 20.0, dt = 1e-3, direction = 1.0;
};

CycleRun simulate(Law law, int cycles, bool observer, const Params& P = Params()) {
  const Vec3 b_a = P.b_a;
  const double k = P.k;
  const Vec3 q_d = P.q_d, qc = P.qc;
  const double r = P.r, period = P.period, dt = P.dt;
  const double w = 2 * M_PI / period;
  const int steps = static_cast<int>(period / dt);
  EnergyObserverOptions opt;
  opt.budget = 0.2;
  EnergyObserver obs(opt);
  Vec3 q(qc(0) + r, qc(1), qc(2));
  CycleRun out;
  double E = 0;
  Vec3 gamma_prev = Vec3::Zero(), q_prev = q;
  WeightedNullSpace pi1(2, 3, ProjectorMethod::kSvd, 1e-9);
  for (int n = 0; n < cycles * steps; ++n) {
    const double t = n * dt;
    const Mat23 J1 = pointJacobian(q, 3), J2 = pointJacobian(q, 2);
    pi1.compute(J1, b_a.cwiseInverse());
    // internal torque −α∇U (projected or not), α from the observer
    const Vec3 dq = q_d - q;
    const double alpha = observer ? obs.alpha() : 1.0;
    VectorX g = alpha * k * dq, gp(3);
    pi1.projectTorque(g, gp);
    Vec3 gamma_int = Vec3::Zero();
    if (law == Law::kTwoPortsPotential) gamma_int = g;
    if (law == Law::kTask1ProjectedPotential || law == Law::kTwoPortsProjectedPotential) gamma_int = gp;
    if (observer) {
      // work of Γ_int over the last step (trapezoid), then the new α scales the torque
      obs.update(n > 0 ? 0.5 * (gamma_prev + gamma_int).dot(q - q_prev) : 0.0, 0.5 * k * dq.squaredNorm(), dt);
      gamma_int *= obs.alpha() / alpha;
    }
    // the imposed cycle: q₁, q₂ on a circle (Fig. 2.9b), q₃ still
    Vec3 qdot(-r * w * std::sin(w * t), P.direction * r * w * std::cos(w * t), 0.0);
    double power = 0;
    if (law == Law::kTask1ProjectedPotential) {
      // unknowns (W₁, q̇₃): J₁ᵀW₁ − b_a₃ e₃ q̇₃ = b_a q̇₁₂ − Γ_int
      Eigen::Matrix3d A;
      A.leftCols<2>() = J1.transpose();
      A.col(2) = -b_a(2) * Vec3::UnitZ();
      Vec3 rhs = b_a.cwiseProduct(qdot) - gamma_int;
      const Vec3 x = A.partialPivLu().solve(rhs);
      qdot(2) = x(2);
      power = x.head<2>().dot(J1 * qdot);
    } else {
      // unknowns (W₁, W₂), minimum norm: A W = b_a q̇ − Γ_int
      Eigen::Matrix<double, 3, 4> A;
      A.leftCols<2>() = J1.transpose();
      if (law == Law::kTwoPortsProjectedTask2) {
        for (int c = 0; c < 2; ++c) {
          VectorX col = J2.row(c).transpose(), pc(3);
          pi1.projectTorque(col, pc);
          A.col(2 + c) = pc;
        }
      } else {
        A.rightCols<2>() = J2.transpose();
      }
      const Vec3 rhs = b_a.cwiseProduct(qdot) - gamma_int;
      const Eigen::Vector4d W = A.completeOrthogonalDecomposition().solve(rhs);
      power = W.head<2>().dot(J1 * qdot) + W.tail<2>().dot(J2 * qdot);
    }
    gamma_prev = gamma_int;
    q_prev = q;
    E += power * dt;
    out.min_energy = std::min(out.min_energy, E);
    q += qdot * dt;
    if ((n + 1) % steps == 0) out.cycle_end_energy.push_back(E);
  }
  out.final_alpha = obs.alpha();
  return out;
}

void print(const char* name, const CycleRun& r) {
  std::printf("%-28s min %.4f  cycles:", name, r.min_energy);
  for (double e : r.cycle_end_energy) std::printf(" %.4f", e);
  std::printf("  alpha %.3f\n", r.final_alpha);
}

}  // namespace

// the cycle of Fig. 2.9b: q₁, q₂ on a circle of radius 0.5 rad in 40 s around (1.0, 1.2), q₃ = 2.0,
// U = ½·100‖q_d − q‖²; for Fig. 2.19 the cycle runs the other way around (1.0, 0.3), q₃ = 2.0
Params fig2_10() {
  Params P;
  P.qc = Vec3(1.0, 1.2, 2.0);
  P.k = 100;
  P.period = 40;
  return P;
}
Params fig2_19() {
  Params P = fig2_10();
  P.qc = Vec3(1.0, 0.3, 2.0);
  P.direction = -1;
  return P;
}
double initialPotential(const Params& P) { return 0.5 * P.k * (P.q_d - (P.qc + Vec3(P.r, 0, 0))).squaredNorm(); }

TEST(Passivity, Fig2_10_ProjectedPotentialLosesPassivityWithASecondPort) {
  const int cycles = 6;
  const Params P = fig2_10();
  const double U0 = initialPotential(P);
  const CycleRun a = simulate(Law::kTask1ProjectedPotential, cycles, false, P);
  const CycleRun b = simulate(Law::kTwoPortsPotential, cycles, false, P);
  const CycleRun c = simulate(Law::kTwoPortsProjectedPotential, cycles, false, P);
  print("2.10a task1+projected U", a);
  print("2.10b two ports + U", b);
  print("2.10c two ports+projected U", c);
  // a) W₁ᵀV₁ = W₁ᵀJ₁b_a⁻¹J₁ᵀW₁ ≥ 0 (2.45): E never goes below 0
  EXPECT_GE(a.min_energy, -1e-9);
  // b) E = ∫q̇ᵀb_aq̇ + α(U − U₀) ≥ −αU₀ (2.51): bounded below, and each cycle dissipates
  EXPECT_GT(b.min_energy, -U0);
  for (int i = 1; i < cycles; ++i) EXPECT_GT(b.cycle_end_energy[i], b.cycle_end_energy[i - 1]);
  // c) E falls by the same amount every cycle (no asymptote, 2.47) and crosses the passive bound
  const double drop = c.cycle_end_energy[0] - c.cycle_end_energy[1];
  EXPECT_GT(drop, 10.0);
  for (int i = 2; i < cycles; ++i) EXPECT_NEAR(c.cycle_end_energy[i - 1] - c.cycle_end_energy[i], drop, 0.05 * drop);
  EXPECT_LT(c.cycle_end_energy.back(), -U0);
}

TEST(Passivity, Fig2_19_ProjectingTask2LosesPassivity) {
  const int cycles = 6;
  const CycleRun c = simulate(Law::kTwoPorts, cycles, false, fig2_19());
  const CycleRun d = simulate(Law::kTwoPortsProjectedTask2, cycles, false, fig2_19());
  print("2.19c two ports", c);
  print("2.19d task 2 projected", d);
  // c) Γ = ΣJᵀW = b_a q̇: E = ∫q̇ᵀb_aq̇ ≥ 0, growing every cycle
  EXPECT_GE(c.min_energy, -1e-9);
  for (int i = 1; i < cycles; ++i) EXPECT_GT(c.cycle_end_energy[i], c.cycle_end_energy[i - 1]);
  // d) with Π₁ᵀJ₂ᵀW₂ the same cycle gives energy back every time: E decreases without asymptote
  const double drop = d.cycle_end_energy[0] - d.cycle_end_energy[1];
  EXPECT_GT(drop, 0.02);
  for (int i = 2; i < cycles; ++i) EXPECT_NEAR(d.cycle_end_energy[i - 1] - d.cycle_end_energy[i], drop, 0.05 * drop);
}

TEST(Passivity, EnergyObserverBoundsTheEnergyOfTheProjectedPotential) {
  // the thesis's remedy: reduce α while the projected potential creates energy
  const int cycles = 6;
  const Params P = fig2_10();
  const double U0 = initialPotential(P);
  const CycleRun without = simulate(Law::kTwoPortsProjectedPotential, cycles, false, P);
  const CycleRun with = simulate(Law::kTwoPortsProjectedPotential, cycles, true, P);
  print("2.10c with energy observer", with);
  const double first_drop = without.cycle_end_energy[0] - without.cycle_end_energy[1];
  const double last_drop = with.cycle_end_energy[cycles - 2] - with.cycle_end_energy[cycles - 1];
  EXPECT_LT(last_drop, 0.01 * first_drop);  // the drift has stopped
  EXPECT_LT(with.final_alpha, 0.05);
  // E stops just past the passive bound −αU₀ (what was created before α reacted), while without the
  // observer it keeps falling
  EXPECT_GT(with.min_energy, -1.05 * U0);
  EXPECT_LT(without.min_energy, -1.5 * U0);
}

TEST(Passivity, ObserverIsQuietForATruePotential) {
  // Γ_int = −α∇U without projection creates nothing: α stays 1
  EnergyObserverOptions opt;
  opt.budget = 0.01;
  EnergyObserver obs(opt);
  const double k = 10, dt = 1e-3;
  double x = 1.0, x_prev = 1.0, f_prev = 0;
  for (int i = 0; i < 5000; ++i) {
    const double f = -obs.alpha() * k * x;  // b ẋ = f, b = 1, explicit Euler
    obs.update(i > 0 ? 0.5 * (f_prev + f) * (x - x_prev) : 0.0, 0.5 * k * x * x, dt);
    f_prev = f;
    x_prev = x;
    x += f * dt;
  }
  EXPECT_EQ(obs.alpha(), 1.0);
  EXPECT_LE(obs.created(), 1e-12);  // gives back at most what it stored (trapezoidal work exact)
  EXPECT_NEAR(obs.injected(), 0.5 * k * (1.0 - x_prev * x_prev), 1e-9);
}

TEST(Passivity, MannequinPortEnergiesBalanceUpToTheProjectionsPower) {
  // b q̇ = Γ with b = b_a + ΣJᵀBJ and the dampers inside the port wrenches W_i = K∘e + B∘(V_d − V):
  // Σ W_iᵀV_i + Γ_intᵀq̇ + Γ_gᵀq̇ + Γ_cᵀq̇ − q̇ᵀ b_a q̇ = (Σ_i J_iᵀW_ff,i − Γ_task)ᵀq̇ at every step,
  // W_ff,i = K∘e + B∘V_d the wrench before the implicit damping. With one level Γ_task = Σ J_iᵀW_ff,i
  // and the ports balance the dissipation exactly; with two levels the right-hand side is the power
  // of the priority projection, Σ_k ((I − Π_kᵀ)Γ_k)ᵀq̇ (2.93): the energy it creates or removes,
  // which is not zero. Both sides are evaluated in double precision: tolerance 1e-9 relative.
  for (bool levels : {false, true}) {
    ControllerConfig c = loadControllerConfig(sourceDir() + "/configs/control/default.yaml");
    if (!levels)
      for (auto& f : c.frames) f.priority = 0;
    Controller ctl(male50(), c);
    const int h = ctl.frameIndex("hand_r");
    const SE3 t0 = ctl.frame(h).target;
    double worst = 0, projection_energy = 0, max_projection_power = 0;
    VectorX gamma_tasks(ctl.model().nv);
    for (int i = 0; i < 800; ++i) {
      SE3 t = t0;
      t.p += Vector3(0.1 * std::sin(i * 0.005), 0.0, 0.1 * (1 - std::cos(i * 0.005)));
      ctl.setTarget(h, t);
      ASSERT_EQ(ctl.step(), StepStatus::kOk);
      double ports = ctl.internalPort().power + ctl.gravityPort().power + ctl.constraintPort().power;
      gamma_tasks.setZero();
      for (int k = 0; k < ctl.numFrames(); ++k) {
        const ControlFrameState& f = ctl.frame(k);
        ports += f.port.power;
        if (!f.enabled) continue;
        ASSERT_FALSE(f.mechanism_enabled) << "the balance below has no mechanism port";
        const Vector6 w_ff = f.wrench + f.damping.cwiseProduct(f.twist);  // K∘e + B∘V_d
        gamma_tasks += ctl.taskJacobian().middleRows<6>(ctl.frameRow(k)).transpose() * w_ff;
      }
      const double projection_power = (gamma_tasks - ctl.taskTorque()).dot(ctl.qdot());
      const double scale = 1 + ctl.dissipation().power + std::abs(projection_power);
      worst = std::max(worst, std::abs(ports - ctl.dissipation().power - projection_power) / scale);
      projection_energy += projection_power * c.dt;
      max_projection_power = std::max(max_projection_power, std::abs(projection_power) / (1 + ctl.dissipation().power));
    }
    std::printf("levels %d: worst balance %.2e, projection energy %.4f J, max |P_proj|/(1+P_diss) %.2e\n",
                levels ? 2 : 1, worst, projection_energy, max_projection_power);
    EXPECT_LT(worst, 1e-9) << (levels ? "two levels" : "one level");
    if (!levels) {
      EXPECT_LT(max_projection_power, 1e-9);  // one level: nothing projected
    } else {
      // the projection's power is a real term of the balance: resolvable, 1000× the balance's tolerance
      EXPECT_GT(max_projection_power, 1000 * 1e-9);
    }
    EXPECT_GT(ctl.dissipation().energy, 0.0);
  }
}

TEST(Passivity, MannequinObserverIsQuietInNormalUse) {
  // default config (6 frames, 2 levels, projected posture control k_int = 400, gravity), both hands
  // moving 30 cm up and down in circles for 3 s: the posture potential stores up to ~1 kJ (the
  // tasks bend the elbows by ~1.2 rad) and gives part of it back; it never gives more than it held,
  // so the observer does not touch α
  ControllerConfig c = loadControllerConfig(sourceDir() + "/configs/control/default.yaml");
  c.internal.stiffness = 400;
  Controller ctl(male50(), c);
  const int hl = ctl.frameIndex("hand_l"), hr = ctl.frameIndex("hand_r");
  const SE3 l0 = ctl.frame(hl).pose, r0 = ctl.frame(hr).pose;
  double min_alpha = 1.0, max_u = 0.0;
  for (int i = 0; i < 3000; ++i) {
    const double t = i * 1e-3;
    SE3 l = l0, r = r0;
    l.p += Vector3(0.15 * std::sin(2 * t), 0.0, 0.15 * (1 - std::cos(2 * t)));
    r.p += Vector3(0.15 * (1 - std::cos(2 * t)), 0.0, 0.15 * std::sin(2 * t));
    ctl.setTarget(hl, l);
    ctl.setTarget(hr, r);
    ASSERT_EQ(ctl.step(), StepStatus::kOk);
    min_alpha = std::min(min_alpha, ctl.alpha());
    max_u = std::max(max_u, ctl.internalPotential());
  }
  std::printf("mannequin: max U %.0f J, injected %.2f J, created %.1f J, min alpha %.3f\n", max_u,
              ctl.energyObserver().injected(), ctl.energyObserver().created(), min_alpha);
  EXPECT_TRUE(ctl.q().allFinite());
  EXPECT_EQ(min_alpha, 1.0);
  EXPECT_LT(ctl.energyObserver().created(), 0.0);
}
