// Dormand–Prince 5(4) (Dormand & Prince, J. Comput. Appl. Math. 6 (1980) 19–26)
// with the RKMK construction of rk4.cpp, FSAL reuse of the last acceleration,
// and the standard step controller h⁺ = h·min(5, max(0.2, 0.9·err^(−1/5)))
// (Hairer, Nørsett, Wanner, Solving ODEs I, §II.4).
#include "integrators/integrators_impl.hpp"

#include <algorithm>
#include <cmath>

namespace appell::detail {

namespace {

constexpr double C[7] = {0, 1.0 / 5, 3.0 / 10, 4.0 / 5, 8.0 / 9, 1, 1};
constexpr double A[7][6] = {
    {},
    {1.0 / 5},
    {3.0 / 40, 9.0 / 40},
    {44.0 / 45, -56.0 / 15, 32.0 / 9},
    {19372.0 / 6561, -25360.0 / 2187, 64448.0 / 6561, -212.0 / 729},
    {9017.0 / 3168, -355.0 / 33, 46732.0 / 5247, 49.0 / 176, -5103.0 / 18656},
    {35.0 / 384, 0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84}};
// Difference between the 5th-order weights (row 7 of A) and the embedded 4th-order ones.
constexpr double E[7] = {71.0 / 57600, 0, -71.0 / 16695, 71.0 / 1920, -17253.0 / 339200,
                         22.0 / 525, -1.0 / 40};
// The continuous extension's fifth coefficient (Hairer, Nørsett, Wanner I,
// §II.6; Shampine 1986): y(t₀ + s h) = y₀ + s(Δ + (1 − s)(r₃ + s(r₄ + (1 − s) r₅)))
// with Δ = y₁ − y₀, r₃ = h k₁ − Δ, r₄ = Δ − h k₇ − r₃, r₅ = h Σ D_i k_i.
constexpr double D[7] = {-12715105075.0 / 11282082432.0, 0, 87487479700.0 / 32700410799.0,
                         -10690763975.0 / 1880347072.0, 701980252875.0 / 199316789632.0,
                         -1453857185.0 / 822651844.0, 69997945.0 / 29380423.0};

}  // namespace

DormandPrince54::DormandPrince54(const Model& model, const IntegratorOptions& options)
    : model_(model), opt_(options), theta_(model.nv), vs_(model.nv), qs_(model.nq),
      err_th_(model.nv), err_v_(model.nv), scale_q_(model.nv), q_start_(model.nq),
      v_start_(model.nv), dth_(model.nv), dv_(model.nv) {
  for (auto& k : kth_) k.resize(model.nv);
  for (auto& k : kv_) k.resize(model.nv);
}

StepResult DormandPrince54::step(AccelerationField& f, double& t, VecX& q, VecX& v, double h) {
  StepResult r;
  dense_ = false;
  if (!(h > 0) || !std::isfinite(h)) {  // NaN would pass every `h < h_min` below
    r.ok = false;
    r.failure = "the step size is not positive and finite";
    return r;
  }
  h = std::min(h, opt_.h_max);
  coordinateScales(model_, q, scale_q_);
  if (!firstStage(model_, f, t, q, v, have_fsal_, theta_, kth_[0], kv_[0], rates_[0], r)) {
    r.ok = false;
    return r;
  }
  for (;;) {
    bool field_ok = true;
    for (int s = 1; s < 7 && field_ok; ++s) {
      theta_.setZero();
      vs_ = v;
      for (int k = 0; k < s; ++k) {
        if (A[s][k] == 0) continue;
        theta_ += (h * A[s][k]) * kth_[k];
        vs_ += (h * A[s][k]) * kv_[k];
      }
      retractWithRate(model_, q, theta_, vs_, qs_, kth_[s]);
      ++r.evaluations;
      field_ok = f(t + C[s] * h, qs_, vs_, kv_[s]) && kv_[s].allFinite() && qs_.allFinite();
      if (field_ok) readRates(f, rates_[s]);
    }
    double err = std::numeric_limits<double>::infinity();
    if (field_ok) {
      // Stage 7 sits at the 5th-order solution (θ, v) = (theta_, vs_), q = qs_.
      err_th_.setZero();
      err_v_.setZero();
      for (int k = 0; k < 7; ++k) {
        err_th_ += (h * E[k]) * kth_[k];
        err_v_ += (h * E[k]) * kv_[k];
      }
      double sum = 0;
      for (int i = 0; i < model_.nv; ++i) {
        const double sq = opt_.atol + opt_.rtol * std::max(scale_q_[i], scale_q_[i] + std::abs(theta_[i]));
        const double sv = opt_.atol + opt_.rtol * std::max(std::abs(v[i]), std::abs(vs_[i]));
        sum += std::pow(err_th_[i] / sq, 2) + std::pow(err_v_[i] / sv, 2);
      }
      err = model_.nv > 0 ? std::sqrt(sum / (2.0 * model_.nv)) : 0.0;
    }
    if (field_ok && err <= 1.0) {
      q_start_ = q;  // kept for the dense output
      v_start_ = v;
      h_last_ = h;
      dense_ = true;
      q = qs_;
      v = vs_;
      t += h;
      // FSAL: the last stage is the next step's first. Swapped, not copied:
      // kv_[6] keeps this step's k₁ for the dense output (kv_[0] is its k₇).
      // The rates by the same 5th-order weights (row 7 of A; b₇ = 0).
      integrateRates(h, A[6], 6, rates_, r);
      std::swap(kv_[0], kv_[6]);
      std::swap(rates_[0], rates_[6]);
      have_fsal_ = true;
      r.h_taken = h;
      r.error = err;
      const double grow = err > 0 ? opt_.safety * std::pow(err, -0.2) : 5.0;
      r.h_next = std::min(opt_.h_max, h * std::clamp(grow, 0.2, 5.0));
      return r;
    }
    ++r.rejected;
    h *= field_ok && std::isfinite(err) ? std::clamp(opt_.safety * std::pow(err, -0.2), 0.1, 0.9) : 0.25;
    if (!(h >= opt_.h_min)) {  // also a NaN h: never loop on it
      r.ok = false;
      r.h_next = h;
      have_fsal_ = false;
      return r;
    }
  }
}

// The FSAL stage k₇ = f(q, v) of the state before the move. Used as the next
// step's k₁ at the moved state, it is off by ‖∂f/∂x‖·|move|, which enters
// the next step as h b₁ ‖∂f/∂x‖ |move| — below the move itself for any step
// the method can take stably, so a move within the error tolerance (the
// same scaled RMS norm as the error control: the projection removing drift
// the steps' own errors left) costs no accuracy, and keeping the stage saves
// the seventh evaluation of the next step (issue 15, item 3).
void DormandPrince54::stateMoved(const VecX& dtheta, const VecX& dv) {
  if (!have_fsal_) return;
  const double moved = scaledMove(opt_, scale_q_, vs_, dtheta, dv);
  if (!(moved <= 1.0)) have_fsal_ = false;
}

bool DormandPrince54::denseOutput(double s, VecX& q, VecX& v) {
  if (!dense_) return false;
  const double h = h_last_;
  // Local coordinates θ about q₀ (θ₁ = theta_), and v; k₁ of θ is kth_[0],
  // k₇ kth_[6]; k₁ of v is kv_[6] and k₇ kv_[0] after the FSAL swap.
  auto interpolate = [&](const VecX& y1, const VecX& k1, const VecX& k7, const VecX* const* k,
                         const VecX& y0, VecX& out, VecX& r5) {
    r5.setZero();
    for (int i = 0; i < 7; ++i)
      if (D[i] != 0) r5 += (h * D[i]) * *k[i];
    for (int j = 0; j < y1.size(); ++j) {
      const double delta = y1[j] - y0[j];
      const double r3 = h * k1[j] - delta;
      const double r4 = delta - h * k7[j] - r3;
      out[j] = y0[j] + s * (delta + (1 - s) * (r3 + s * (r4 + (1 - s) * r5[j])));
    }
  };
  const VecX* kth[7] = {&kth_[0], &kth_[1], &kth_[2], &kth_[3], &kth_[4], &kth_[5], &kth_[6]};
  const VecX* kv[7] = {&kv_[6], &kv_[1], &kv_[2], &kv_[3], &kv_[4], &kv_[5], &kv_[0]};
  err_th_.setZero();  // θ₀ = 0
  interpolate(theta_, kth_[0], kth_[6], kth, err_th_, dth_, err_v_);
  interpolate(vs_, kv_[6], kv_[0], kv, v_start_, dv_, err_v_);
  v = dv_;
  retract(model_, q_start_, dth_, q);
  return true;
}

}  // namespace appell::detail
