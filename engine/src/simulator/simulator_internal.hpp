// The simulator's private parts, shared by simulator.cpp (the step) and
// contact_events.cpp (unilateral constraints): the acceleration field the
// integrator calls, and the per-contact workspace of the event handling.
#pragma once

#include <appell/configuration.hpp>
#include <appell/simulator.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include <algorithm>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace appell {

namespace detail {

/// A sliding contact is a candidate for its settled direction when its slip
/// is at most this fraction of the state's largest speed (a screen only: the
/// settling time decides, friction_settled.cpp).
inline constexpr double kSettleScreen = 1e-2;

/// Per unilateral constraint: where its row is, and a copy of that row as
/// evaluated with the contact closed (an open contact's block holds zero
/// rows), to measure its normal velocity and acceleration while it is open.
struct UnilateralRow {
  int c = -1, row = -1, global = -1;
  bool joint = false;
  int a = -1, b = -1;
  Vec6 wa = Vec6::Zero(), wb = Vec6::Zero();
  double bval = 0, kappa = 0, abias = 0;
  VecX a_joint;            // joint-space row over cols (RowBlock::joint_cols)
  std::vector<int> cols;
  double gap = 0;         // at the decision's state
  double gamma = 0;       // normal velocity before the impact
  double target = 0;      // e γ⁻: the impact shifts the row to γ⁺ = −e γ⁻
  double impulse = 0, tangential = 0;
  bool touching = false, in_set = false, was_closed = false, lifting = false, touching_down = false;
  bool bounced = false;   // rebounded at this event: open, not a force candidate
  bool separated = false; // left the impact's set: its friction impulses would pull it
  double gap_start = 0;   // gap at the start of the step (open contacts)
  // Coulomb friction (friction.cpp): μ, and while sliding the slip direction
  // in the friction rows' coordinates (unit; kept when the slip is ~0).
  double mu = std::numeric_limits<double>::infinity();  // static: the sticking cone
  double mu_k = std::numeric_limits<double>::infinity();  // kinetic: the sliding force
  int nf = 0;             // friction rows (0: frictionless or bilateral)
  // Regularized friction (Constraint::creepSpeed): > 0, the contact slides
  // whenever closed, dir = s / max(|s|, creep) (|dir| ≤ 1); no stick or
  // slip events, no onset or settling decisions.
  double creep = 0;
  Vec3 dir = Vec3::Zero();
  Vec3 dir_start = Vec3::Zero();  // at the step's start: the slip-reversal event's reference
  // Friction released for frictionOnset: sliding without a friction force
  // (its force is an unknown of the onset problem, not superposed).
  bool released = false;
  int first_force = 0;    // onset: index of its first friction row's unknown
  // At a slip-reversal event: it was sliding and its mode and direction are
  // decided afresh; sliding on (in a new direction) is not a new slip event.
  bool redeciding = false;
  // Sliding on its settled direction (friction_settled.cpp): its friction
  // force is an unknown of this solve, `settle_force` its first index.
  bool settling = false;
  int settle_force = 0;
  // Piecewise supports (contact_features.cpp): the piece a closed contact's
  // rows use between events (RowBlock::latched_feature), the nearest piece at
  // the step's start, and the nearest one at the state last searched.
  int feature = -1, feature_start = -1, feature_free = -1;
  // Points of one pair (Constraint::pointGroup): the other points' rows,
  // this one's slot, and whether it idles — open while a point of lower slot
  // is open too, which is the one watching for the next touchdown.
  std::vector<int> siblings;
  int slot = 0;
  bool dormant = false;
};

/// The friction forces of a set of contacts as the unknowns of one problem
/// (friction_onset.cpp, friction_settled.cpp), sized for every friction row:
/// their generalized forces per unit row force U (nv × F), the slip
/// accelerations' and normal loads' responses W (F × F) and N (K × F), the
/// free terms a0 and ln0, the forces f, and the solves' workspace.
struct FrictionProblem {
  MatX U, W, N;
  MatX V;  // with_velocities: the generalized velocities' (v̇'s) response (nv × F)
  VecX a0, ln0, acc, load, f, f_old, tau;
  ConstrainedResult res;
  /// Block Gauss–Seidel's view of the contact whose n rows start at o0
  /// (the others' forces fixed): min ½ f_jᵀH f_j + cᵀf_j, H its W block
  /// (symmetrized), c = a0_j + Σ_{i≠j} W_ji f_i.
  void disk(int o0, int n, int F, Mat3& H, Vec3& c) const {
    H.setZero();
    H.topLeftCorner(n, n) = W.block(o0, o0, n, n);
    H = 0.5 * (H + H.transpose()).eval();
    c.setZero();
    c.head(n) = a0.segment(o0, n);  // (products one by one: no temporaries)
    c.head(n).noalias() += W.block(o0, 0, n, F) * f.head(F);
    c.head(n).noalias() -= H.topLeftCorner(n, n) * f.segment(o0, n);
  }
  /// Block Gauss–Seidel from f = 0 over K contacts until f stops changing
  /// (to 1e-14 of the largest radius): block(j) sets contact j's forces in
  /// f (the loads read the others' as they are) and returns its disk's
  /// radius. false when `sweeps` sweeps did not settle it.
  template <class Block>
  bool gaussSeidel(int K, int F, int sweeps, Block&& block) {
    f.head(F).setZero();
    for (int sweep = 0; sweep < sweeps; ++sweep) {
      f_old.head(F) = f.head(F);
      double fmax = 0;
      for (int j = 0; j < K; ++j) fmax = std::max(fmax, block(j));
      if (sweep > 0 && (f.head(F) - f_old.head(F)).lpNorm<Eigen::Infinity>() <=
                           1e-14 * std::max(fmax, 1e-300))
        return true;
    }
    return false;
  }
  /// Contact j's load (normal force or impulse) at the current forces.
  double loadAt(int j, int F) const { return ln0[j] + N.row(j).head(F).dot(f.head(F)); }
  void size(int nv, int nf, int kf, const ConstrainedResult& like) {
    U = MatX::Zero(nv, nf);
    V = MatX::Zero(nv, nf);
    W = MatX::Zero(nf, nf);
    N = MatX::Zero(kf, nf);
    a0 = acc = f = f_old = VecX::Zero(nf);
    ln0 = load = VecX::Zero(kf);
    tau = VecX::Zero(nv);
    res = like;
  }
};

/// What a unilateral constraint's crossing is (the event function located).
enum class Crossing { None, Gap, Normal, Cone, Slip, Feature };

struct UnilateralState {
  std::vector<UnilateralRow> rows;
  VecX q0, v0, vplus, vminus, vdot, impulse;
  double t0 = 0;
  ConstrainedResult res;
  int zero_events = 0;    // consecutive events at the very start of a step
  // Sliding friction by superposition (friction.cpp), sized for every
  // contact with friction rows and finite μ.
  std::vector<int> sliding;   // rows (indices into `rows`) sliding in this solve
  MatX G, J, R;               // nv × k friction forces per unit normal load; 6 × nv; k × k
  VecX lam0, s, tau_f;
  double friction_power = 0;  // −vᵀ Σ sⱼ Gⱼ of the last solve: the power friction takes
  ConstrainedResult unit;
  Eigen::PartialPivLU<MatX> lu;
  // The onset problem (friction_onset.cpp), sized for every friction row:
  // candidates, their generalized forces per unit row force (nv × F), the
  // slip accelerations' and normal loads' responses W (F × F), N (K × F),
  // the free terms, the forces and the modes before.
  std::vector<int> onset;
  FrictionProblem onset_problem;
  std::vector<char> was_sliding;
  // Sliding contacts on their settled directions (friction_settled.cpp): the
  // same unknowns, their own storage (an onset's solves may need it).
  std::vector<int> settle;
  bool settle_off = false;    // this solve slides every contact along its slip
  FrictionProblem settle_problem;
  VecX swmax;                 // per candidate: the largest eigenvalue of its W block
  VecX vstick;                // an impact's post-impact velocity with every contact sticking
  // Over-constrained sticking contacts (friction_overconstrained.cpp), sized
  // for every friction row: W padded, its eigen-solver, the part g of the
  // free slip acceleration in W's null space.
  MatX over_W;
  VecX over_g;
  std::vector<int> feature_ahead;  // per row: its nearest piece feature_window after an event
  Eigen::SelfAdjointEigenSolver<MatX> over_eig;
};

/// r.dir from the slip of sliding contact r, or the step's starting
/// direction while the slip is below `floor` or reversed (friction.cpp).
void slipDirection(const ConstraintData& cd, UnilateralRow& r, double floor);

/// argmin ½ fᵀH f + cᵀf over |f| ≤ r in the first n (≤ 3) components, H
/// symmetric positive semidefinite (friction_onset.cpp).
Vec3 diskMinimizer(const Mat3& H, const Vec3& c, int n, double r);

}  // namespace detail

// v̇ = f(t, q, v): joint forces, constraint rows, the solver. Failures are
// remembered (with the reason) and reported as "not admissible" to the
// integrator, which then rejects the step.
class Simulator::Field final : public AccelerationField {
 public:
  explicit Field(Simulator& s)
      : s_(s),
        tau_(VecX::Zero(s.model_.nv)),
        residual_(VecX::Zero(s.cdata_->m)),
        residual_c_(VecX::Zero(s.cdata_->m)),
        impulse_(VecX::Zero(s.cdata_->m)),
        q_kick_(s.model_.nq),
        q_fail_(s.model_.nq),
        v_fail_(s.model_.nv) {}

  bool operator()(double t, const VecX& q, const VecX& v, VecX& vdot) override {
    Simulator& s = s_;
    tau_.setZero();
    if (s.tau_fn_) {
      s.tau_fn_(t, q, v, tau_);
      if (tau_.size() != s.model_.nv || !tau_.allFinite()) {
        record("the joint-force callback returned a non-finite or wrongly sized tau", t);
        return false;
      }
    }
    // Only the closed rows act on the motion: contacts in flight are
    // evaluated at the step's end, where touchdown is detected.
    s.cdata_->closed_only = true;
    evaluateConstraintRows(s.model_, *s.data_, s.constraints_, *s.cdata_, t, q, v);
    s.cdata_->closed_only = false;
    if (s.options_.baumgarte.enabled)
      applyBaumgarte(*s.data_, s.constraints_, *s.cdata_, v, s.options_.baumgarte.alpha,
                     s.options_.baumgarte.beta);
    // Rows that move in time (b ≠ 0) do work −λᵀb: only then are the
    // multipliers needed at a stage.
    const bool moving = (s.cdata_->b.array() != 0).any();
    s.solveDynamics(t, q, v, tau_, stage_, moving ? SolveOutputs::All : SolveOutputs::Accelerations);
    if (!stage_.ok) {
      if (!failed_) noteFailure(t, q, v);
      record(stage_.error, t);
      return false;
    }
    if (!stage_.vdot.allFinite()) {
      record("the solver returned a non-finite acceleration", t);
      return false;
    }
    vdot = stage_.vdot;
    // The powers of the work balance at this stage (Simulator::frictionWork).
    rates_[kFrictionWork] = s.uni_ ? s.uni_->friction_power : 0.0;
    rates_[kJointWork] = tau_.dot(v);
    rates_[kSupportWork] = moving ? -stage_.lambda.dot(s.cdata_->b) : 0.0;
    return true;
  }
  bool constrained() const override { return !s_.constraints_.empty(); }
  bool projectVelocity(double t, const VecX& q, VecX& v) override {
    Simulator& s = s_;
    evaluateConstraintRows(s.model_, *s.data_, s.constraints_, *s.cdata_, t, q, v);
    if (!s.solver_->projectVelocity(s.model_, *s.data_, s.constraints_, *s.cdata_, q, v, impulse_)) {
      record("the leapfrog's velocity projection failed: " + s.solver_->lastError(), t);
      return false;
    }
    return true;
  }
  // The leapfrog's discrete constraints (integrators.hpp): the residuals at
  // the half-step point (velocity rows) and the gaps at the step's end over h
  // (holonomic rows), removed by impulses along the rows at (t, q) — the rows
  // at q with their offsets shifted by (those residuals − the residual at q),
  // then the solver's own M-orthogonal projection.
  bool constrainKick(double t, const VecX& q, double h, VecX& w) override {
    Simulator& s = s_;
    ConstraintData& cd = *s.cdata_;
    integrate(s.model_, q, w, 0.5 * h, q_kick_);
    evaluateConstraintRows(s.model_, *s.data_, s.constraints_, cd, t + 0.5 * h, q_kick_, w);
    velocityResiduals(*s.data_, s.constraints_, cd, w, residual_c_);
    integrate(s.model_, q, w, h, q_kick_);
    evaluateConstraintRows(s.model_, *s.data_, s.constraints_, cd, t + h, q_kick_, w);
    // A gap at the round-off of its own evaluation (ε·|q|) is zero: divided
    // by an event's shortened step (h ~ 1e-12 s) it would be a velocity
    // correction of ~1e-5 m/s that changes with each evaluation's round-off,
    // and the implicit kick's fixed point could not settle.
    const double gap_floor = 8 * std::numeric_limits<double>::epsilon() *
                             (1 + q_kick_.lpNorm<Eigen::Infinity>());
    for (int i = 0; i < cd.m; ++i)
      if (cd.holonomic[i] && cd.isActive(cd.row_constraint[i]))
        residual_c_[i] = std::abs(cd.gap[i]) > gap_floor ? cd.gap[i] / h : 0.0;
    evaluateConstraintRows(s.model_, *s.data_, s.constraints_, cd, t, q, w);
    velocityResiduals(*s.data_, s.constraints_, cd, w, residual_);
    residual_c_ -= residual_;
    shiftRowOffsets(s.constraints_, cd, residual_c_);
    if (!s.solver_->projectVelocity(s.model_, *s.data_, s.constraints_, cd, q, w, impulse_)) {
      record("the leapfrog's constrained half-kick failed: " + s.solver_->lastError(), t);
      return false;
    }
    return true;
  }
  int rateCount() const override { return kWorkTerms; }
  double rate(int i) const override { return rates_[i]; }

  void clear() {
    failed_ = false;
    solve_failed_ = false;
    message_.clear();
  }
  bool failed() const { return failed_; }
  /// A solve failed at (t, q, v) — a stage's, or the step's end state or
  /// projection (Simulator::attemptStep): an over-constrained sticking set
  /// is decided there (Simulator::step, friction_overconstrained.cpp).
  void noteFailure(double t, const VecX& q, const VecX& v) {
    solve_failed_ = true;
    t_fail_ = t;
    q_fail_ = q;
    v_fail_ = v;
  }
  /// Whether a solve failed (then failedT/Q/V are its state).
  bool solveFailed() const { return solve_failed_; }
  double failedT() const { return t_fail_; }
  const VecX& failedQ() const { return q_fail_; }
  const VecX& failedV() const { return v_fail_; }
  const std::string& message() const { return message_; }

 private:
  void record(const std::string& why, double t) {
    if (failed_) return;  // keep the first reason
    failed_ = true;
    std::ostringstream os;
    os << why << " (at t = " << t << ")";
    message_ = os.str();
  }

  Simulator& s_;
  VecX tau_;
  VecX residual_, residual_c_, impulse_;  // constrainKick's (size m)
  VecX q_kick_;                           // its half-step and end points
  ConstrainedResult stage_;
  std::array<double, kWorkTerms> rates_{};
  bool failed_ = false;
  bool solve_failed_ = false;
  double t_fail_ = 0;
  VecX q_fail_, v_fail_;
  std::string message_;
};

}  // namespace appell
