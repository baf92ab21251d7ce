// Semi-implicit (symplectic) Euler on the manifold: v⁺ = v + h f(t, q, v),
// q⁺ = retract(q, h T(q) v⁺). For a separable Hamiltonian it is symplectic,
// and with exact rotation updates it keeps quaternions unit (Hairer, Lubich,
// Wanner, Geometric Numerical Integration, §VI.3).
#include "integrators/integrators_impl.hpp"

namespace appell::detail {

SymplecticEuler::SymplecticEuler(const Model& model)
    : model_(model), a_(model.nv), v1_(model.nv), theta_(model.nv), q1_(model.nq) {}

StepResult SymplecticEuler::step(AccelerationField& f, double& t, VecX& q, VecX& v, double h) {
  StepResult r;
  r.evaluations = 1;
  theta_.setZero();
  if (!f(t, q, v, a_) || !a_.allFinite()) return {false, 0, h, 0, 0, 1, {}};
  StageRates p;
  readRates(f, p);
  for (int i = 0; i < AccelerationField::kMaxRates; ++i) r.integrals[i] = h * p[i];  // order 1, as v
  v1_ = v + h * a_;
  localRate(model_, q, theta_, v1_, theta_);  // θ = 0 on entry: T(q, 0) v⁺
  theta_ *= h;
  retract(model_, q, theta_, q1_);
  if (!v1_.allFinite() || !q1_.allFinite()) return {false, 0, h, 0, 0, 1, {}};
  q = q1_;
  v = v1_;
  t += h;
  r.h_taken = r.h_next = h;
  return r;
}

}  // namespace appell::detail
