// Dormand–Prince 8(5,3) — Hairer's DOP853 (Hairer, Nørsett & Wanner, Solving
// Ordinary Differential Equations I, 2nd ed., §II.10; the method of Prince &
// Dormand, J. Comput. Appl. Math. 7 (1981) 67–75, as revised there) — with
// the RKMK construction of rk4.cpp: 12 stages of order 8, the last stage
// f(t + h, y₁) reused as the next step's first (12 evaluations per accepted
// step), and the error estimate of order 8 built from the 5th- and 3rd-order
// embedded differences,
//     err = h ‖e₅‖² / √(N (‖e₅‖² + 0.01 ‖e₃‖²)),
// with the scaled RMS norm and the step controller of dormand_prince.cpp
// (exponent −1/8). Dense output is the 7th-order continuous extension: three
// more stages (13–15) evaluated on the first request after a step, then
//     y(t₀ + x h) = y₀ + x(F₀ + (1−x)(F₁ + x(F₂ + (1−x)(F₃ + x(F₄ + (1−x)(F₅ + x F₆))))))
// with F₀ = Δ, F₁ = h k₁ − Δ, F₂ = 2Δ − h(k₁ + k₁₃), F₃₊ᵢ = h Σⱼ Dᵢⱼ kⱼ.
// The coefficients are those of Hairer's dop853.f.
#include "integrators/integrators_impl.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace appell::detail {

// The coefficients (named: the unity build shares one translation unit with
// dormand_prince.cpp's).
namespace dop853 {

constexpr double C[16] = {0.0, 0.526001519587677318785587544488e-01, 0.789002279381515978178381316732e-01, 0.118350341907227396726757197510, 0.281649658092772603273242802490, 0.333333333333333333333333333333, 0.25, 0.307692307692307692307692307692, 0.651282051282051282051282051282, 0.6, 0.857142857142857142857142857142, 1.0, 1.0, 0.1, 0.2, 0.777777777777777777777777777778};
constexpr double A[16][16] = {
    {},
    {5.26001519587677318785587544488e-2},
    {1.97250569845378994544595329183e-2, 5.91751709536136983633785987549e-2},
    {2.95875854768068491816892993775e-2, 0, 8.87627564304205475450678981324e-2},
    {2.41365134159266685502369798665e-1, 0, -8.84549479328286085344864962717e-1, 9.24834003261792003115737966543e-1},
    {3.7037037037037037037037037037e-2, 0, 0, 1.70828608729473871279604482173e-1, 1.25467687566822425016691814123e-1},
    {3.7109375e-2, 0, 0, 1.70252211019544039314978060272e-1, 6.02165389804559606850219397283e-2, -1.7578125e-2},
    {3.70920001185047927108779319836e-2, 0, 0, 1.70383925712239993810214054705e-1, 1.07262030446373284651809199168e-1, -1.53194377486244017527936158236e-2, 8.27378916381402288758473766002e-3},
    {6.24110958716075717114429577812e-1, 0, 0, -3.36089262944694129406857109825, -8.68219346841726006818189891453e-1, 2.75920996994467083049415600797e1, 2.01540675504778934086186788979e1, -4.34898841810699588477366255144e1},
    {4.77662536438264365890433908527e-1, 0, 0, -2.48811461997166764192642586468, -5.90290826836842996371446475743e-1, 2.12300514481811942347288949897e1, 1.52792336328824235832596922938e1, -3.32882109689848629194453265587e1, -2.03312017085086261358222928593e-2},
    {-9.3714243008598732571704021658e-1, 0, 0, 5.18637242884406370830023853209, 1.09143734899672957818500254654, -8.14978701074692612513997267357, -1.85200656599969598641566180701e1, 2.27394870993505042818970056734e1, 2.49360555267965238987089396762, -3.0467644718982195003823669022},
    {2.27331014751653820792359768449, 0, 0, -1.05344954667372501984066689879e1, -2.00087205822486249909675718444, -1.79589318631187989172765950534e1, 2.79488845294199600508499808837e1, -2.85899827713502369474065508674, -8.87285693353062954433549289258, 1.23605671757943030647266201528e1, 6.43392746015763530355970484046e-1},
    {5.42937341165687622380535766363e-2, 0, 0, 0, 0, 4.45031289275240888144113950566, 1.89151789931450038304281599044, -5.8012039600105847814672114227, 3.1116436695781989440891606237e-1, -1.52160949662516078556178806805e-1, 2.01365400804030348374776537501e-1, 4.47106157277725905176885569043e-2},
    {5.61675022830479523392909219681e-2, 0, 0, 0, 0, 0, 2.53500210216624811088794765333e-1, -2.46239037470802489917441475441e-1, -1.24191423263816360469010140626e-1, 1.5329179827876569731206322685e-1, 8.20105229563468988491666602057e-3, 7.56789766054569976138603589584e-3, -8.298e-3},
    {3.18346481635021405060768473261e-2, 0, 0, 0, 0, 2.83009096723667755288322961402e-2, 5.35419883074385676223797384372e-2, -5.49237485713909884646569340306e-2, 0, 0, -1.08347328697249322858509316994e-4, 3.82571090835658412954920192323e-4, -3.40465008687404560802977114492e-4, 1.41312443674632500278074618366e-1},
    {-4.28896301583791923408573538692e-1, 0, 0, 0, 0, -4.69762141536116384314449447206, 7.68342119606259904184240953878, 4.06898981839711007970213554331, 3.56727187455281109270669543021e-1, 0, 0, 0, -1.39902416515901462129418009734e-3, 2.9475147891527723389556272149, -9.15095847217987001081870187138},
};
constexpr double E3[13] = {5.42937341165687622380535766363e-2 - 0.244094488188976377952755905512, 0, 0, 0, 0, 4.45031289275240888144113950566, 1.89151789931450038304281599044, -5.8012039600105847814672114227, 3.1116436695781989440891606237e-1 - 0.733846688281611857341361741547, -1.52160949662516078556178806805e-1, 2.01365400804030348374776537501e-1, 4.47106157277725905176885569043e-2 - 0.220588235294117647058823529412e-1, 0};
constexpr double E5[13] = {0.1312004499419488073250102996e-1, 0, 0, 0, 0, -0.1225156446376204440720569753e1, -0.4957589496572501915214079952, 0.1664377182454986536961530415e1, -0.3503288487499736816886487290, 0.3341791187130174790297318841, 0.8192320648511571246570742613e-1, -0.2235530786388629525884427845e-1, 0};
constexpr double D[4][16] = {
    {-0.84289382761090128651353491142e1, 0, 0, 0, 0, 0.56671495351937776962531783590, -0.30689499459498916912797304727e1, 0.23846676565120698287728149680e1, 0.21170345824450282767155149946e1, -0.87139158377797299206789907490, 0.22404374302607882758541771650e1, 0.63157877876946881815570249290, -0.88990336451333310820698117400e-1, 0.18148505520854727256656404962e2, -0.91946323924783554000451984436e1, -0.44360363875948939664310572000e1},
    {0.10427508642579134603413151009e2, 0, 0, 0, 0, 0.24228349177525818288430175319e3, 0.16520045171727028198505394887e3, -0.37454675472269020279518312152e3, -0.22113666853125306036270938578e2, 0.77334326684722638389603898808e1, -0.30674084731089398182061213626e2, -0.93321305264302278729567221706e1, 0.15697238121770843886131091075e2, -0.31139403219565177677282850411e2, -0.93529243588444783865713862664e1, 0.35816841486394083752465898540e2},
    {0.19985053242002433820987653617e2, 0, 0, 0, 0, -0.38703730874935176555105901742e3, -0.18917813819516756882830838328e3, 0.52780815920542364900561016686e3, -0.11573902539959630126141871134e2, 0.68812326946963000169666922661e1, -0.10006050966910838403183860980e1, 0.77771377980534432092869265740, -0.27782057523535084065932004339e1, -0.60196695231264120758267380846e2, 0.84320405506677161018159903784e2, 0.11992291136182789328035130030e2},
    {-0.25693933462703749003312586129e2, 0, 0, 0, 0, -0.15418974869023643374053993627e3, -0.23152937917604549567536039109e3, 0.35763911791061412378285349910e3, 0.93405324183624310003907691704e2, -0.37458323136451633156875139351e2, 0.10409964950896230045147246184e3, 0.29840293426660503123344363579e2, -0.43533456590011143754432175058e2, 0.96324553959188282948394950600e2, -0.39177261675615439165231486172e2, -0.14972683625798562581422125276e3},
};


constexpr int kStages = 12;  // of the step; stage 12 is f(t + h, y₁) (FSAL)

}  // namespace dop853

DormandPrince853::DormandPrince853(const Model& model, const IntegratorOptions& options)
    : model_(model), opt_(options), theta_(model.nv), vs_(model.nv), qs_(model.nq),
      theta1_(model.nv), v1_(model.nv), q1_(model.nq), err5_th_(model.nv), err5_v_(model.nv),
      err3_th_(model.nv), err3_v_(model.nv), scale_q_(model.nv), q_start_(model.nq),
      v_start_(model.nv), dth_(model.nv), dv_(model.nv) {
  for (auto& k : kth_) k.resize(model.nv);
  for (auto& k : kv_) k.resize(model.nv);
  for (auto& d : dsum_) d.resize(model.nv);
}

/// Stage s's state from the stages before it: θ = h Σ A[s][k] kθ_k about q,
/// v_s = v + h Σ A[s][k] kv_k, and q_s = q ⊕ θ.
void DormandPrince853::stageState(int s, double h, const VecX& q, const VecX& v) {
  theta_.setZero();
  vs_ = v;
  for (int k = 0; k < s; ++k) {
    if (dop853::A[s][k] == 0) continue;
    theta_ += (h * dop853::A[s][k]) * kth_[k];
    vs_ += (h * dop853::A[s][k]) * kv_[k];
  }
  retractWithRate(model_, q, theta_, vs_, qs_, kth_[s]);
}

// Hairer's error norm of dop853.f: the 5th- and 3rd-order estimates
// combined, err = h e₅ / √((e₅² + 0.01 e₃²) 2n) in the mixed scales of the
// coordinates and the velocities.
double DormandPrince853::errorNorm(double h, const VecX& v) {
  err5_th_.setZero();
  err5_v_.setZero();
  err3_th_.setZero();
  err3_v_.setZero();
  for (int k = 0; k <= dop853::kStages; ++k) {
    err5_th_ += dop853::E5[k] * kth_[k];
    err5_v_ += dop853::E5[k] * kv_[k];
    err3_th_ += dop853::E3[k] * kth_[k];
    err3_v_ += dop853::E3[k] * kv_[k];
  }
  double e5 = 0, e3 = 0;
  for (int i = 0; i < model_.nv; ++i) {
    const double sq = opt_.atol + opt_.rtol * std::max(scale_q_[i], scale_q_[i] + std::abs(theta1_[i]));
    const double sv = opt_.atol + opt_.rtol * std::max(std::abs(v[i]), std::abs(v1_[i]));
    e5 += std::pow(err5_th_[i] / sq, 2) + std::pow(err5_v_[i] / sv, 2);
    e3 += std::pow(err3_th_[i] / sq, 2) + std::pow(err3_v_[i] / sv, 2);
  }
  const double denom = e5 + 0.01 * e3;
  // A NaN or infinite sum is no error control: reject (not err = 0).
  return denom > 0 && std::isfinite(denom) ? h * e5 / std::sqrt(denom * 2.0 * model_.nv)
         : denom == 0                        ? 0.0
                                             : std::numeric_limits<double>::infinity();
}

StepResult DormandPrince853::step(AccelerationField& f, double& t, VecX& q, VecX& v, double h) {
  StepResult r;
  dense_ = extra_ = false;
  if (!(h > 0) || !std::isfinite(h)) {  // NaN would pass every `h < h_min` below
    r.ok = false;
    r.failure = "the step size is not positive and finite";
    return r;
  }
  h = std::min(h, opt_.h_max);
  coordinateScales(model_, q, scale_q_);
  // FSAL: the last step's f(t + h, y₁) is this step's k₁ — moved only now,
  // so that the dense output of the last step could still read its stages.
  if (have_fsal_ && fsal_pending_) {
    std::swap(kv_[0], kv_[dop853::kStages]);
    rates_[0] = rates_[dop853::kStages];
  }
  fsal_pending_ = false;
  if (!firstStage(model_, f, t, q, v, have_fsal_, theta_, kth_[0], kv_[0], rates_[0], r)) {
    r.ok = false;
    return r;
  }
  for (;;) {
    bool field_ok = true;
    for (int s = 1; s < dop853::kStages && field_ok; ++s) {
      stageState(s, h, q, v);
      ++r.evaluations;
      field_ok = f(t + dop853::C[s] * h, qs_, vs_, kv_[s]) && kv_[s].allFinite() && qs_.allFinite();
      if (field_ok) readRates(f, rates_[s]);
    }
    double err = std::numeric_limits<double>::infinity();
    if (field_ok) {
      // The 8th-order solution (row 12 of A: the weights b), and f there.
      stageState(dop853::kStages, h, q, v);
      theta1_ = theta_;
      v1_ = vs_;
      q1_ = qs_;
      ++r.evaluations;
      field_ok = f(t + h, q1_, v1_, kv_[dop853::kStages]) && kv_[dop853::kStages].allFinite() && q1_.allFinite();
      if (field_ok) readRates(f, rates_[dop853::kStages]);
    }
    if (field_ok) err = errorNorm(h, v);
    if (field_ok && err <= 1.0) {
      q_start_ = q;  // kept for the dense output
      v_start_ = v;
      t_start_ = t;
      h_last_ = h;
      field_ = &f;
      dense_ = true;
      q = q1_;
      v = v1_;
      t += h;
      integrateRates(h, dop853::A[dop853::kStages], dop853::kStages, rates_, r);
      have_fsal_ = true;
      fsal_pending_ = true;  // kv_[12] becomes the next k₁ once the dense output is done with it
      r.h_taken = h;
      r.error = err;
      // After a rejection in this call the next step may not grow (Hairer's
      // dop853.f): the error estimate just failed at a larger step.
      const double grow = err > 0 ? opt_.safety * std::pow(err, -1.0 / 8) : 6.0;
      r.h_next = std::min(opt_.h_max, h * std::clamp(grow, 0.2, r.rejected > 0 ? 1.0 : 6.0));
      return r;
    }
    ++r.rejected;
    h *= field_ok && std::isfinite(err) ? std::clamp(opt_.safety * std::pow(err, -1.0 / 8), 0.1, 0.9) : 0.25;
    if (!(h >= opt_.h_min)) {  // also a NaN h: never loop on it
      r.ok = false;
      r.h_next = h;
      have_fsal_ = false;
      return r;
    }
  }
}

bool DormandPrince853::denseOutput(double x, VecX& q, VecX& v) {
  if (!dense_) return false;
  const double h = h_last_;
  if (!extra_) {  // stages 13–15, once per step
    for (int s = dop853::kStages + 1; s < 16; ++s) {
      stageState(s, h, q_start_, v_start_);
      if (!(*field_)(t_start_ + dop853::C[s] * h, qs_, vs_, kv_[s]) || !kv_[s].allFinite() ||
          !qs_.allFinite())
        return false;
    }
    extra_ = true;
  }
  // One component set: y₀, y₁ and the stages k (θ about q₀ with θ₀ = 0, or v).
  auto interpolate = [&](const VecX& y0, const VecX& y1, const std::array<VecX, 16>& k, VecX& out) {
    for (int i = 0; i < 4; ++i) {
      dsum_[i].setZero();
      for (int j = 0; j < 16; ++j)
        if (dop853::D[i][j] != 0) dsum_[i] += (h * dop853::D[i][j]) * k[j];
    }
    for (int c = 0; c < y1.size(); ++c) {
      const double delta = y1[c] - y0[c];
      const double F[7] = {delta, h * k[0][c] - delta, 2 * delta - h * (k[0][c] + k[dop853::kStages][c]),
                           dsum_[0][c], dsum_[1][c], dsum_[2][c], dsum_[3][c]};
      double y = 0;
      for (int m = 6; m >= 0; --m) y = (y + F[m]) * (m % 2 == 0 ? x : 1 - x);
      out[c] = y0[c] + y;
    }
  };
  theta_.setZero();  // θ₀ = 0
  interpolate(theta_, theta1_, kth_, dth_);
  interpolate(v_start_, v1_, kv_, dv_);
  v = dv_;
  retract(model_, q_start_, dth_, q);
  return true;
}

void DormandPrince853::stateMoved(const VecX& dtheta, const VecX& dv) {
  if (!have_fsal_) return;
  const double moved = scaledMove(opt_, scale_q_, v1_, dtheta, dv);
  if (!(moved <= 1.0)) have_fsal_ = false;
}

}  // namespace appell::detail
