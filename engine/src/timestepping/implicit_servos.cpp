// Servos taken implicitly in a Moreau–Jean step (implicit_servos.hpp states
// the law and the elimination).
#include "timestepping/implicit_servos.hpp"

#include <algorithm>
#include <cmath>

namespace appell::timestepping {

namespace {
// Passes of the active-set loop over the limited servos; each changes the
// set, and a set repeats only through round-off at a limit, so this bound
// is never reached in practice (reported as unconverged when it is).
int maxPasses(int servos) { return 2 * servos + 4; }
}  // namespace

ImplicitServos::ImplicitServos(const Model& model, std::vector<Actuator> servos, int contact_rows)
    : servos_(std::move(servos)) {
  const int ns = size();
  for (const Actuator& a : servos_) dof_.push_back(model.joints[a.joint].idx_v);
  limited_.assign(ns, 0);
  implicit_.assign(ns, 1);
  implicit_count_ = ns;
  a_ = D_ = bound_ = dsq_ = P_ = rhs_ = y_ = u_s_ = P0_ = VecX::Zero(ns);
  S_ = MatX::Zero(ns, ns);
  Z_ = SZ_ = MatX::Zero(ns, std::max(contact_rows, 1));
  llt_ = Eigen::LLT<MatX>(ns);
}

void ImplicitServos::law(const Model& model, double t, const VecX& q, const VecX& v, double h,
                         double theta) {
  h_ = h;
  const double t1 = t + h;
  for (int i = 0; i < size(); ++i) {
    const Actuator& s = servos_[i];
    const Joint& j = model.joints[s.joint];
    const double qd = q[j.idx_q], vd = v[j.idx_v];
    double k = s.kv;
    if (s.type == ActuatorType::Position) {
      k += h * theta * s.kp;
      a_[i] = s.kp * (s.setpoint.at(t1) - qd - h * (1 - theta) * vd) + s.kv * s.setpoint.rate(t1);
    } else {
      a_[i] = s.kv * s.setpoint.at(t1);
    }
    D_[i] = h * k;
    bound_[i] = h * s.effort_limit;  // (∞ for an unlimited servo)
  }
}

void ImplicitServos::gate(const VecX& mobility) {
  const int ns = size();
  double explicit_sum = 0;
  for (int i = 0; i < ns; ++i) {
    implicit_[i] = 0;
    explicit_sum += D_[i] * mobility[i];
  }
  implicit_count_ = 0;
  while (explicit_sum > kExplicitBound && implicit_count_ < ns) {
    int stiffest = -1;
    for (int i = 0; i < ns; ++i)
      if (!implicit_[i] && (stiffest < 0 || D_[i] * mobility[i] > D_[stiffest] * mobility[stiffest]))
        stiffest = i;
    implicit_[stiffest] = 1;
    ++implicit_count_;
    explicit_sum -= D_[stiffest] * mobility[stiffest];
  }
  for (int i = 0; i < ns; ++i)
    if (!implicit_[i]) limited_[i] = 0;
  gate_age_ = 0;
}

void ImplicitServos::addExplicit(const Model& model, double t, const VecX& q, const VecX& v,
                                 VecX& tau) const {
  for (int i = 0; i < size(); ++i) {
    if (implicit_[i]) continue;
    const Joint& j = model.joints[servos_[i].joint];
    tau[j.idx_v] += servos_[i].force(t, q[j.idx_q], v[j.idx_v]);
  }
}

void ImplicitServos::factor(const Eigen::Ref<const MatX>& W_s) {
  const int ns = size();
  for (int i = 0; i < ns; ++i) dsq_[i] = limited_[i] || !implicit_[i] ? 0.0 : std::sqrt(D_[i]);
  for (int i = 0; i < ns; ++i)
    for (int j = 0; j < ns; ++j) S_(i, j) = (i == j ? 1.0 : 0.0) + dsq_[i] * W_s(i, j) * dsq_[j];
  llt_.compute(S_);
}

// P of the current set for servo free velocities u (the limited servos'
// impulses included in neither): the limited at their bound, the others
// D^½ S⁻¹ (D^-½ h a − D^½ u_eff), u_eff = u + W_s P_limited.
bool ImplicitServos::solveAlone(const MatX& W, const VecX& u_free) {
  const int ns = size();
  for (int pass = 0; pass < maxPasses(ns); ++pass) {
    const auto W_s = W.topLeftCorner(ns, ns);
    factor(W);
    for (int i = 0; i < ns; ++i) P0_[i] = limited_[i] ? limited_[i] * bound_[i] : 0.0;
    u_s_ = u_free;
    for (int i = 0; i < ns; ++i)
      if (limited_[i]) u_s_.noalias() += W_s.col(i) * P0_[i];
    for (int i = 0; i < ns; ++i)
      rhs_[i] = dsq_[i] == 0 ? 0.0 : h_ * a_[i] / dsq_[i] - dsq_[i] * u_s_[i];
    y_ = rhs_;
    llt_.solveInPlace(y_);
    for (int i = 0; i < ns; ++i) P_[i] = dsq_[i] == 0 ? P0_[i] : dsq_[i] * y_[i];
    u_s_ = u_free;
    u_s_.noalias() += W_s * P_;
    if (updateSet(u_s_)) return true;
  }
  for (int i = 0; i < ns; ++i) P_[i] = std::clamp(P_[i], -bound_[i], bound_[i]);
  return false;
}

// Limits a free servo whose impulse left its bound, frees a limited one
// whose law at u lies within it; true when nothing changed.
bool ImplicitServos::updateSet(const VecX& u) {
  bool settled = true;
  for (int i = 0; i < size(); ++i) {
    if (!implicit_[i]) continue;
    const double demand = h_ * a_[i] - D_[i] * u[i];
    if (!limited_[i] && std::abs(P_[i]) > bound_[i]) {
      limited_[i] = P_[i] > 0 ? 1 : -1;
      settled = false;
    } else if (limited_[i] && !(limited_[i] * demand > bound_[i])) {
      limited_[i] = 0;
      settled = false;
    }
  }
  return settled;
}

void ImplicitServos::eliminate(const MatX& W_all, int n, const VecX& u_free_s, MatX& W_c,
                               VecX& u_c) {
  const int ns = size();
  const auto W_s = W_all.block(n, n, ns, ns);
  const auto W_sc = W_all.block(n, 0, ns, n);
  factor(W_s);
  for (int i = 0; i < ns; ++i) P0_[i] = limited_[i] ? limited_[i] * bound_[i] : 0.0;
  u_s_ = u_free_s;
  u_s_.noalias() += W_s * P0_;
  for (int i = 0; i < ns; ++i)
    rhs_[i] = dsq_[i] == 0 ? 0.0 : h_ * a_[i] / dsq_[i] - dsq_[i] * u_s_[i];
  y_ = rhs_;
  llt_.solveInPlace(y_);
  for (int i = 0; i < ns; ++i)
    if (dsq_[i] != 0) P0_[i] = dsq_[i] * y_[i];
  // The contacts' Schur complement and their free velocities with P₀.
  for (int i = 0; i < ns; ++i) Z_.row(i).head(n) = dsq_[i] * W_sc.row(i);
  SZ_.leftCols(n) = Z_.leftCols(n);
  llt_.solveInPlace(SZ_.leftCols(n));
  W_c.topLeftCorner(n, n) = W_all.topLeftCorner(n, n);
  W_c.topLeftCorner(n, n).noalias() -= Z_.leftCols(n).transpose() * SZ_.leftCols(n);
  u_c.head(n).noalias() += W_all.block(0, n, n, ns) * P0_;
  u_s_ = u_free_s;  // (kept for impulses())
}

bool ImplicitServos::impulses(const MatX& W_all, int n, const VecX& P_c) {
  const int ns = size();
  y_.noalias() = SZ_.leftCols(n) * P_c.head(n);
  for (int i = 0; i < ns; ++i) P_[i] = dsq_[i] == 0 ? P0_[i] : P0_[i] - dsq_[i] * y_[i];
  rhs_ = u_s_;  // the servos' velocities at (P_c, P)
  rhs_.noalias() += W_all.block(n, 0, ns, n) * P_c.head(n);
  rhs_.noalias() += W_all.block(n, n, ns, ns) * P_;
  return updateSet(rhs_);
}

}  // namespace appell::timestepping
