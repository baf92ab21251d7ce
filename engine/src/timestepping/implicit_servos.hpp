// Servos in a Moreau–Jean step, taken implicitly (moreau_jean.hpp).
//
// A servo on joint coordinate d applies f = k_p (q* − q) + k_v (q̇* − q̇),
// |f| ≤ τ_max (actuators.hpp). Evaluated at the step's start, as between
// events, it is an explicit spring: a step h is stable only while
// h √(k_p / m_eff) ≲ 2, and on a light link m_eff is the inverse of
// (M⁻¹)_dd, not M_dd — a neck joint of a robot whose links carry 10⁻⁶ kg m²
// diverged in five 1 ms steps under gains tuned on M_dd. So the step takes
// the servo at its end, as Drake's discrete SAP solver takes PD-controlled
// joint actuators and PhysX its "implicit" joint drives (MuJoCo takes only
// k_v so, in its implicit integrators): with
// q⁺_d = q_d + h (θ v⁺_d + (1 − θ) v_d) and the set-point
// at t + h, the servo's impulse over the step is
//     P = h a − D u,   a = k_p (q*(t+h) − q_d − h(1−θ) v_d) + k_v q̇*(t+h),
//                      D = h (h θ k_p + k_v),  u = v⁺_d,   |P| ≤ h τ_max,
// a backward-Euler spring and damper: stable at any gain, and dissipative.
// Its row is the coordinate itself (J = e_dᵀ, u = v_d), so its responses are
// the Delassus operator's (delassus.cpp) and, with Wₛₛ the servos' block,
//     u = u_free + Wₛₛ P  ⇒  (I + D Wₛₛ) P = h a − D u_free.
// With S = I + D^½ Wₛₛ D^½ (symmetric, ≥ I: one Cholesky) this is
// P = D^½ S⁻¹ (D^-½ h a − D^½ u_free). A servo at its effort limit holds
// P = ±h τ_max; its D^½ is set to 0, which makes its row and column of S the
// identity's — the set of limited servos is found by an active-set loop (a
// box-constrained problem in the symmetric positive definite W + D⁻¹).
// Only stiff servos need this: a servo whose ω h is small is as accurate
// and cheaper explicit (no response solves). Every 100 steps (and at the
// first) the stage computes every servo's mobility (M⁻¹)_dd (one solve
// each) and takes implicitly the fewest servos, stiffest first, that leave
// the others' Σ D_d (M⁻¹)_dd ≤ 0.1 — which bounds (ω h)² of every mode the
// explicit ones make, since the largest eigenvalue of D^½ M⁻¹ D^½ is at most
// its trace; the others are forces at the step's start, as between events
// (a car's steering servo: explicit; iCub's neck: implicit).
// With contacts, the servos are eliminated from the contact problem: for
// contact rows c, Z = D^½ W_sc, the contacts see
//     W_cc − Zᵀ S⁻¹ Z   (a Schur complement: symmetric, positive semidefinite)
//     u_free,c + W_cs P₀,   P₀ the servos' impulses at P_c = 0,
// and then P = P₀ − D^½ S⁻¹ Z P_c — the contact problem keeps its form, and
// its solver and finish are unchanged.
#pragma once

#include <appell/actuators.hpp>

#include <Eigen/Cholesky>

#include <vector>

namespace appell::timestepping {

class ImplicitServos {
 public:
  ImplicitServos() = default;
  ImplicitServos(const Model& model, std::vector<Actuator> servos, int contact_rows);

  int size() const { return static_cast<int>(servos_.size()); }
  bool empty() const { return servos_.empty(); }
  /// The servo's coordinate in v.
  int dof(int i) const { return dof_[i]; }

  /// The law over [t, t + h] at (q, v): a, D and the impulse bound; every
  /// servo starts unlimited unless it was limited at the last step.
  void law(const Model& model, double t, const VecX& q, const VecX& v, double h, double theta);
  /// Whether this step re-chooses the implicit servos (then call gate()).
  bool gateDue() const { return gate_age_ < 0 || gate_age_ >= kGateSteps; }
  /// Chooses the implicit servos from their mobilities (M⁻¹)_dd (after law()).
  void gate(const VecX& mobility);
  /// Counts a step since the last gate.
  void age() { ++gate_age_; }
  bool isImplicit(int i) const { return implicit_[i] != 0; }
  bool anyImplicit() const { return implicit_count_ > 0; }
  /// τ += the explicit servos' forces at (t, q, v).
  void addExplicit(const Model& model, double t, const VecX& q, const VecX& v, VecX& tau) const;

  /// The servos alone: P from their block W (size × size) and their free
  /// velocities; the limited set found by the active-set loop. false when it
  /// did not settle within its passes (P is then the last pass's, in bounds).
  bool solveAlone(const MatX& W, const VecX& u_free);

  /// With contacts: W_all over [contact rows 0…n, servo rows n…n+size], u_free
  /// of the servo rows. Writes the contacts' Schur complement into W_c (n × n)
  /// and adds the servos' P₀ response to u_c (n). Uses the current limited set.
  void eliminate(const MatX& W_all, int n, const VecX& u_free_s, MatX& W_c, VecX& u_c);
  /// The servos' impulses for contact impulses P_c (after eliminate), and
  /// whether the limited set is consistent with them; if not, the set is
  /// updated (call eliminate and solve the contacts again).
  bool impulses(const MatX& W_all, int n, const VecX& P_c);

  const VecX& P() const { return P_; }

 private:
  void factor(const Eigen::Ref<const MatX>& W_s);  ///< S and its Cholesky for the current set
  bool updateSet(const VecX& u);  ///< u: the servos' velocities at P

  std::vector<Actuator> servos_;
  std::vector<int> dof_;
  static constexpr int kGateSteps = 100;
  static constexpr double kExplicitBound = 0.1;  ///< Σ D_d (M⁻¹)_dd of the explicit servos
  std::vector<signed char> limited_;  ///< −1, 0, +1: at −h τ_max, free, at +h τ_max
  std::vector<char> implicit_;        ///< per servo: taken implicitly (else explicit, P = 0)
  int implicit_count_ = 0;
  int gate_age_ = -1;
  VecX a_, D_, bound_, dsq_, P_, rhs_, y_, u_s_, P0_;
  MatX S_, Z_, SZ_;
  Eigen::LLT<MatX> llt_;
  double h_ = 0;
};

}  // namespace appell::timestepping
