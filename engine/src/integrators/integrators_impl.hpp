// The three integrators. Each keeps its stage vectors, sized at construction.
#pragma once

#include <appell/configuration.hpp>
#include <appell/integrators.hpp>

#include <Eigen/Cholesky>

#include <array>
#include <cmath>

namespace appell::detail {

/// The field's rates at one stage (AccelerationField::rate).
using StageRates = std::array<double, AccelerationField::kMaxRates>;

/// Reads the rates the field evaluated with its last call.
inline void readRates(const AccelerationField& f, StageRates& out) {
  const int n = f.rateCount();
  for (int i = 0; i < AccelerationField::kMaxRates; ++i) out[i] = i < n ? f.rate(i) : 0.0;
}

/// The step's work integrals, h Σₖ bₖ ρₖ over its first `stages` stages: the
/// rates ρ (powers) integrated with the weights b that advance the state.
template <size_t N>
void integrateRates(double h, const double* b, int stages, const std::array<StageRates, N>& rates,
                    StepResult& r) {
  for (int i = 0; i < AccelerationField::kMaxRates; ++i) {
    double sum = 0;
    for (int k = 0; k < stages; ++k) sum += b[k] * rates[k][i];
    r.integrals[i] = h * sum;
  }
}

/// The magnitudes the adaptive methods measure local coordinates against:
/// the coordinate itself for Euclidean joints, 1 rad for rotations.
inline void coordinateScales(const Model& model, const VecX& q, VecX& scale) {
  for (const Joint& j : model.joints) {
    const bool rot = j.type == JointType::Floating || j.type == JointType::Ball;
    for (int k = 0; k < j.nv; ++k) {
      const bool euclid = !rot || (j.type == JointType::Floating && k >= 3);
      scale[j.idx_v + k] = euclid ? std::abs(q[j.idx_q + k - (j.type == JointType::Floating ? 3 : 0)]) : 1.0;
    }
  }
}

/// The scaled RMS size of a move (Δθ, Δv) of the accepted state (θ about
/// `scale`'s q, v): ≤ 1 is within the error tolerance. The adaptive methods'
/// stateMoved() keeps the FSAL stage below that.
inline double scaledMove(const IntegratorOptions& o, const VecX& scale, const VecX& v,
                         const VecX& dtheta, const VecX& dv) {
  const int n = static_cast<int>(v.size());
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    const double sq = o.atol + o.rtol * scale[i];
    const double sv = o.atol + o.rtol * std::abs(v[i]);
    sum += std::pow(dtheta[i] / sq, 2) + std::pow(dv[i] / sv, 2);
  }
  return n > 0 ? std::sqrt(sum / (2.0 * n)) : 0.0;
}

/// An RKMK step's first stage at (t, q, v): kθ = localRate at θ = 0, and
/// kv = f(t, q, v) unless carried over from the last step (FSAL). false when
/// the field refuses the state.
inline bool firstStage(const Model& model, AccelerationField& f, double t, const VecX& q,
                       const VecX& v, bool have_fsal, VecX& theta, VecX& kth, VecX& kv,
                       StageRates& rates, StepResult& r) {
  theta.setZero();
  localRate(model, q, theta, v, kth);
  if (have_fsal) return true;
  ++r.evaluations;
  if (!f(t, q, v, kv) || !kv.allFinite()) return false;
  readRates(f, rates);
  return true;
}

class SymplecticEuler final : public Integrator {
 public:
  explicit SymplecticEuler(const Model& model);
  IntegratorType type() const override { return IntegratorType::SymplecticEuler; }
  StepResult step(AccelerationField& f, double& t, VecX& q, VecX& v, double h) override;

 private:
  const Model& model_;
  VecX a_, v1_, theta_, q1_;
};

class Leapfrog final : public Integrator {
 public:
  Leapfrog(const Model& model, const IntegratorOptions& options);
  IntegratorType type() const override { return IntegratorType::Leapfrog; }
  StepResult step(AccelerationField& f, double& t, VecX& q, VecX& v, double h) override;

 private:
  void dropOldestPair();
  void mixAnderson(int k, double change, double previous, double scale);
  bool projectedField(AccelerationField& f, double t, const VecX& q, const VecX& x, VecX& out);
  bool endKick(AccelerationField& f, double& t, VecX& q, VecX& v, double h, StepResult& r);
  const Model& model_;
  IntegratorOptions opt_;
  static constexpr int kAndersonDepth = 4;
  using SmallMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kAndersonDepth, kAndersonDepth>;
  using SmallVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kAndersonDepth, 1>;
  VecX a_, a_end_, a_shift_, vh_, w_, y_, xp_;
  VecX z_, g_, res_, g_prev_, res_prev_;  // the fixed point's (x, Δ), 2 nv
  MatX dF_, dG_;  // Anderson's residual and image differences, 2 nv × depth
  VecX q1_;       // q⁺
  int depth_ = 0;  // columns of dF_, dG_ in use (the newest last); kept across steps
  static constexpr double kPairFloor = 1e-11;  // residuals below this (× scale) are round-off
  static constexpr double kRoundOffFloor = 1e-11;
  bool have_end_ = false;  // a_end_ = f(q⁺, v½) of the last step: the next predictor
};

class RungeKutta4 final : public Integrator {
 public:
  explicit RungeKutta4(const Model& model);
  IntegratorType type() const override { return IntegratorType::RK4; }
  StepResult step(AccelerationField& f, double& t, VecX& q, VecX& v, double h) override;

 private:
  const Model& model_;
  std::array<VecX, 4> kth_, kv_;
  std::array<StageRates, 4> rates_{};
  VecX theta_, vs_, qs_;
};

class DormandPrince54 final : public Integrator {
 public:
  DormandPrince54(const Model& model, const IntegratorOptions& options);
  IntegratorType type() const override { return IntegratorType::DormandPrince54; }
  bool adaptive() const override { return true; }
  StepResult step(AccelerationField& f, double& t, VecX& q, VecX& v, double h) override;
  void reset() override { have_fsal_ = false; }
  void stateMoved(const VecX& dtheta, const VecX& dv) override;
  bool denseOutput(double s, VecX& q, VecX& v) override;

 private:
  const Model& model_;
  IntegratorOptions opt_;
  std::array<VecX, 7> kth_, kv_;
  std::array<StageRates, 7> rates_{};  // rates_[0] follows kv_'s FSAL swap
  VecX theta_, vs_, qs_, err_th_, err_v_, scale_q_;
  VecX q_start_, v_start_, dth_, dv_;  // the last accepted step, for dense output
  double h_last_ = 0;
  bool have_fsal_ = false;
  bool dense_ = false;                 // the last call accepted a step: dense output valid
};

class DormandPrince853 final : public Integrator {
 public:
  DormandPrince853(const Model& model, const IntegratorOptions& options);
  IntegratorType type() const override { return IntegratorType::DormandPrince853; }
  bool adaptive() const override { return true; }
  StepResult step(AccelerationField& f, double& t, VecX& q, VecX& v, double h) override;
  void reset() override { have_fsal_ = false; }
  void stateMoved(const VecX& dtheta, const VecX& dv) override;
  /// Evaluates the field three more times (stages 13–15) on the first call
  /// after a step, with the field that step used.
  bool denseOutput(double s, VecX& q, VecX& v) override;

 private:
  double errorNorm(double h, const VecX& v);
  void stageState(int s, double h, const VecX& q, const VecX& v);
  const Model& model_;
  IntegratorOptions opt_;
  std::array<VecX, 16> kth_, kv_;       // 12 stages, f(y₁), 3 dense-output stages
  std::array<StageRates, 13> rates_{};
  VecX theta_, vs_, qs_, theta1_, v1_, q1_, err5_th_, err5_v_, err3_th_, err3_v_, scale_q_;
  VecX q_start_, v_start_, dth_, dv_;   // the last accepted step, for dense output
  std::array<VecX, 4> dsum_;
  AccelerationField* field_ = nullptr;  // the last accepted step's field
  double t_start_ = 0, h_last_ = 0;
  bool have_fsal_ = false;
  bool fsal_pending_ = false;           // kv_[12] is the next step's k₁, not yet moved
  bool dense_ = false;                  // the last call accepted a step
  bool extra_ = false;                  // stages 13–15 of that step evaluated
};

}  // namespace appell::detail
