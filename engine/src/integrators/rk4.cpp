// Classic RK4 in the Runge–Kutta–Munthe-Kaas form: the stages live in the local
// coordinates θ around the step's start, so fourth order holds on SO(3) too
// (Munthe-Kaas, BIT 38 (1998) 92–111).
#include "integrators/integrators_impl.hpp"

namespace appell::detail {

RungeKutta4::RungeKutta4(const Model& model)
    : model_(model), theta_(model.nv), vs_(model.nv), qs_(model.nq) {
  for (auto& k : kth_) k.resize(model.nv);
  for (auto& k : kv_) k.resize(model.nv);
}

StepResult RungeKutta4::step(AccelerationField& f, double& t, VecX& q, VecX& v, double h) {
  static constexpr double c[4] = {0, 0.5, 0.5, 1};
  static constexpr double w[4] = {1.0 / 6, 1.0 / 3, 1.0 / 3, 1.0 / 6};
  StepResult r;
  for (int s = 0; s < 4; ++s) {
    if (s == 0) {
      theta_.setZero();
      vs_ = v;
      qs_ = q;
      localRate(model_, q, theta_, vs_, kth_[s]);
    } else {
      theta_ = (c[s] * h) * kth_[s - 1];
      vs_ = v + (c[s] * h) * kv_[s - 1];
      retractWithRate(model_, q, theta_, vs_, qs_, kth_[s]);
    }
    ++r.evaluations;
    if (!f(t + c[s] * h, qs_, vs_, kv_[s]) || !kv_[s].allFinite()) {
      r.ok = false;
      return r;
    }
    readRates(f, rates_[s]);
  }
  theta_ = h * (w[0] * kth_[0] + w[1] * kth_[1] + w[2] * kth_[2] + w[3] * kth_[3]);
  vs_ = v + h * (w[0] * kv_[0] + w[1] * kv_[1] + w[2] * kv_[2] + w[3] * kv_[3]);
  retract(model_, q, theta_, qs_);
  if (!qs_.allFinite() || !vs_.allFinite()) {
    r.ok = false;
    return r;
  }
  q = qs_;
  v = vs_;
  t += h;
  r.h_taken = r.h_next = h;
  integrateRates(h, w, 4, rates_, r);
  return r;
}

}  // namespace appell::detail
