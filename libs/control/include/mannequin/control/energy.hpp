#pragma once
/// \file energy.hpp
/// \brief Energy at interaction ports (passivity, thesis 2.1, 2.3) and the energy observer that
/// limits the internal potential's gain α (end of 2.2.1.4, the remedy the thesis retains).
///
/// A port (W, V) is passive iff ∫₀ᵗ WᵀV dt ≥ −β² for all t (2.3). Ports here: each control
/// frame's coupling (W the wrench it applies to the mannequin, V the control frame's body twist,
/// both in control-frame axes, so WᵀV is the power it injects), the virtual-mechanism coupling,
/// the internal control (Γ_int, q̇), gravity and the constraint forces (Γ, q̇).
///
/// Energy observer. The internal control Γ_int = α Πᵀ(−∂U/∂q)ᵀ (2.21) is passive when it derives
/// from the potential αU: then its port (Γ_int, q̇) gives ∫Γ_intᵀq̇ dt = α(U(0) − U(t)) ≤ α max U,
/// it can only give back energy it has stored. The projection breaks this when other ports appear
/// (2.47, Fig. 2.10c): cycle after cycle it injects energy. The observer integrates the work of the
/// internal torque, w_k = ½(Γ_k + Γ_{k+1})ᵀ(q_{k+1} ⊖ q_k) (trapezoidal rule, exact for a quadratic
/// potential, so the Euler discretisation itself is not counted), and measures
///     E_created = Σ_k w_k − max_k α_k U(q_k)          (≤ 0 for a true potential),
/// the energy injected beyond the most the potential ever held. While E_created exceeds a budget it
/// reduces α exponentially (rate decay_per_s); below half the budget α recovers linearly
/// (recovery_per_s) up to 1.
namespace mannequin::control {

/// Work done at one port: power at the last step and its integral.
struct PortEnergy {
  double power = 0.0;   ///< WᵀV at the last step (W)
  double energy = 0.0;  ///< ∫ WᵀV dt since reset (J); passive iff bounded below (2.3)
  void add(double p, double dt) {
    power = p;
    energy += p * dt;
  }
  void reset() { power = energy = 0.0; }
};

struct EnergyObserverOptions {
  bool enabled = true;
  double budget = 0.5;          ///< J of created energy tolerated before α is reduced
  double decay_per_s = 5.0;     ///< α ← α·exp(−decay δt) while over budget
  double recovery_per_s = 0.2;  ///< α ← α + recovery δt while under half the budget (up to 1)
  double alpha_min = 0.0;       ///< α never goes below this
};

/// The observer's state. update() once per step, after the step's velocity is known.
class EnergyObserver {
 public:
  EnergyObserver() = default;
  explicit EnergyObserver(const EnergyObserverOptions& options) : options_(options) {}

  /// α = 1, E_created = 0.
  void reset() {
    alpha_ = 1.0;
    created_ = injected_ = peak_ = 0.0;
  }
  /// \param work w_k, work of the internal torque over the step just done (J, Γ_int scaled by α),
  /// \param potential U(q) (unscaled) at the configuration the step reached, \param dt the step.
  /// \return the α to use for the next step.
  double update(double work, double potential, double dt);

  double alpha() const { return alpha_; }
  double created() const { return created_; }
  double injected() const { return injected_; }  ///< Σ w_k (J)
  const EnergyObserverOptions& options() const { return options_; }

 private:
  EnergyObserverOptions options_;
  double alpha_ = 1.0;
  double created_ = 0.0;
  double injected_ = 0.0;  // Σ w_k
  double peak_ = 0.0;      // max α U
};

}  // namespace mannequin::control
