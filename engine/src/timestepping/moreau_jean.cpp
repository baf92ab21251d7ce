// One Moreau–Jean step (moreau_jean.hpp states the scheme).
#include "timestepping/moreau_jean.hpp"

#include <appell/configuration.hpp>
#include <appell/dynamics.hpp>

#include <algorithm>
#include <cmath>

namespace appell::timestepping {

namespace {

// The rows a candidate uses: normal, friction, equality (its row list).
int rowList(const Candidate& k, int* out) {
  int n = 0;
  out[n++] = k.normal;
  for (int i = 0; i < k.nf; ++i) out[n++] = k.f[i];
  for (int i = 0; i < k.ne; ++i) out[n++] = k.e[i];
  return n;
}

}  // namespace

MoreauJean::MoreauJean(const Model& model, const ConstraintList& constraints,
                       std::vector<Actuator> servos, const TimeSteppingOptions& options,
                       double gap_tol)
    : options_(options), gap_tol_(gap_tol) {
  int rows = 0;
  for (int c = 0; c < static_cast<int>(constraints.size()); ++c) {
    const Constraint& con = *constraints[c];
    if (!con.unilateral()) continue;
    Candidate k;
    k.c = c;
    k.normal = con.unilateralRow();
    k.mu = con.friction();
    k.mu_kinetic = std::isfinite(con.kineticFriction()) ? con.kineticFriction() : k.mu;
    k.restitution = con.restitution();
    k.stiffness = con.contactLaw().normal_stiffness;
    k.damping = con.contactLaw().normal_damping;
    const bool coulomb = std::isfinite(k.mu);
    for (int r = 0; r < con.rows(); ++r) {
      if (r == k.normal) continue;
      // Finite μ: tangent and lateral rows in the cone, spin rows free
      // (torsional friction is the event scheme's). μ = ∞: every other row
      // holds while the contact pushes (ideal rolling).
      if (coulomb && isTangential(con.rowKind(r)) && k.nf < 3) k.f[k.nf++] = r;
      else if (!coulomb && k.ne < 5) k.e[k.ne++] = r;
    }
    first_.push_back(rows);
    rows += k.rows();
    all_.push_back(k);
  }
  active_.reserve(all_.size());
  modes_.assign(constraints.size(), Mode::Open);
  rebound_.assign(constraints.size(), 0);
  warm_.assign(6 * all_.size(), 0.0);
  slid_.assign(all_.size(), 0);
  compliance_.assign(all_.size(), 0.0);
  restituted_.assign(all_.size(), 0);
  problem_.reserve(rows, static_cast<int>(all_.size()));
  carry_modes_.reserve(all_.size());
  carry_ids_.reserve(all_.size());
  ids_.reserve(all_.size());
  servos_ = ImplicitServos(model, std::move(servos), rows);
  const int ns = servos_.size();
  // The servo rows follow the contacts' in J: the coordinate itself, u = v_d.
  delassus_.reserve(model, rows + ns);
  for (int i = 0; i < ns; ++i) delassus_.J(rows + i, servos_.dof(i)) = 1;
  map_.reserve(rows + ns);
  if (ns > 0) W_all_ = MatX::Zero(rows + ns, rows + ns);
  Rs_ = MatX::Zero(model.nv, ns);
  mobility_ = VecX::Zero(ns);
  Wss_ = MatX::Zero(ns, ns);
  u_servo_ = VecX::Zero(ns);
  vfree0_ = VecX::Zero(model.nv);
  rows_ = rows;
  qnext_ = qmid_ = VecX::Zero(model.nq);
  uminus_ = ufree_ = VecX::Zero(std::max(rows, 1));
  tau_ = vfree_ = vdot_ = v0_ = VecX::Zero(model.nv);
  ConstraintData cd(model, constraints, DenseRows::None);
  lambda_ = impulse_ = VecX::Zero(cd.m);
  res_.vdot = res2_.vdot = VecX::Zero(model.nv);
  res_.lambda = res2_.lambda = VecX::Zero(cd.m);
  res_.reaction = res2_.reaction = VecX::Zero(model.nv);
}

// v_free: the step's velocity without contact impulses, on the bilateral rows.
bool MoreauJean::freeVelocity(const Model& model, Data& data, const ConstraintList& constraints,
                              ConstraintData& cdata, ConstrainedSolver& solver,
                              const Simulator::JointForces& tau_fn, double t, const VecX& q,
                              const VecX& v, double h) {
  for (const Candidate& k : all_) cdata.setActive(k.c, false);
  evaluateConstraintRows(model, data, constraints, cdata, t, q, v);
  tau_.setZero();
  if (tau_fn) {
    tau_fn(t, q, v, tau_);
    if (tau_.size() != model.nv || !tau_.allFinite()) {
      error_ = "the joint-force callback returned a non-finite or wrongly sized tau";
      return false;
    }
  }
  servos_.addExplicit(model, t, q, v, tau_);
  solver.solve(model, data, constraints, cdata, q, v, tau_, res_, SolveOutputs::All);
  if (!res_.ok || !res_.vdot.allFinite()) {
    error_ = "the free motion's solve failed: " + (res_.ok ? std::string("non-finite v̇") : res_.error);
    return false;
  }
  vdot_ = res_.vdot;
  vfree_ = v;
  vfree_.noalias() += h * vdot_;
  work_.support -= h * res_.lambda.dot(cdata.b);
  lambda_ = res_.lambda;
  if (cdata.m_active > 0 &&
      !solver.projectVelocity(model, data, constraints, cdata, q, vfree_, impulse_)) {
    error_ = "the free velocity's projection onto the bilateral rows failed: " + solver.lastError();
    return false;
  }
  return true;
}

// Candidates: contacts whose gap closes within the step at the free velocity.
void MoreauJean::selectCandidates(const ConstraintData& cdata, double h, double rest_speed) {
  active_.clear();
  problem_.clear();
  map_.clear();
  for (int k = 0; k < static_cast<int>(all_.size()); ++k) {
    const Candidate& cand = all_[k];
    const int at = first_[k];
    // The gap at q̃, predicted for the step's end.
    const double gap = cdata.gap[cdata.offset[cand.c] + cand.normal];
    if (!(gap <= gap_tol_)) continue;
    active_.push_back(k);
    // Static and kinetic friction (Coulomb's two coefficients) in a scheme
    // whose step solves one cone per contact: the kinetic cone for a contact
    // that slid at the last step, the static one otherwise — so a slip
    // starts once the demand exceeds μ, and a sliding contact's force is
    // μₖλₙ, as between events (a sliding skid-steer's turn is set by μₖ).
    const int o = problem_.add(cand.nf, cand.ne, slid_[k] ? cand.mu_kinetic : cand.mu);
    for (int i = 0; i < cand.rows(); ++i) {
      map_.push_back(at + i);
      problem_.u_free[o + i] = ufree_[at + i];
      problem_.target[o + i] = 0;
      problem_.P[o + i] = warm_[6 * k + i];
    }
    // Newton's restitution on an approach faster than the rest speed; an
    // open gap may close within the step, to land on g = 0 at its end
    // (q⁺ = q + h v⁺ at θ = 1), and a gap at round-off below 0 reopens.
    const double approach = -uminus_[at];
    compliance_[k] = 0;
    restituted_[k] = 0;
    if (cand.stiffness > 0) continue;  // (its target once the step's θ is known: below)
    problem_.target[o] = ufree_[at] - gap / h;  // g⁺ ≈ g̃ + h (u⁺ − u_free) ≥ 0
    restituted_[k] = approach > rest_speed && cand.restitution * approach > problem_.target[o];
    if (restituted_[k]) problem_.target[o] = cand.restitution * approach;
  }
  // The step's θ: ½ — the trapezoidal rule's position, exact in free fall
  // and for the work of gravity on a body — when no rigid contact lands by
  // its gap target (which needs θ = 1) and no joint force acts; else the
  // options' θ. (With a force that grows with the displacement — a servo, a
  // spring in the caller's forces — θ = ½ on an explicit force amplifies
  // each step by 1 + (ω h)²/4; θ = 1 keeps it bounded, symplectic Euler.)
  bool rigid = false;
  for (int k : active_) rigid = rigid || !(all_[k].stiffness > 0);
  theta_ = rigid || joint_forces_ ? options_.theta : 0.5;
  for (int j = 0; j < static_cast<int>(active_.size()); ++j) {
    const int k = active_[j];
    const Candidate& cand = all_[k];
    if (!(cand.stiffness > 0)) continue;
    // A compliant normal (Kelvin–Voigt at the step's end): with the gap at
    // q, g = g̃ − h u_free, and g⁺ = g + h (θ u⁺ + (1 − θ) u⁻),
    // Pₙ = max(0, h (−k g⁺ − c u⁺)) = max(0, h a − D u⁺),
    //   a = k (h u_free − g̃ − h (1 − θ) u⁻),   D = h (h θ k + c):
    // u⁺ + Pₙ/D ≥ h a/D ⊥ Pₙ ≥ 0, the rigid row's law with 1/D added to
    // W's diagonal (addCompliance) — a regularized row, as MuJoCo's soft
    // constraints and Drake's SAP compliant contact.
    const int at = first_[k], o = problem_.blocks[j].first;
    const double gap = cdata.gap[cdata.offset[cand.c] + cand.normal];
    const double D = h * (h * theta_ * cand.stiffness + cand.damping);
    compliance_[k] = 1 / D;
    problem_.target[o] =
        h * cand.stiffness * (h * ufree_[at] - gap - h * (1 - theta_) * uminus_[at]) / D;
  }
}

// W's diagonal on the compliant normals: + 1/D (selectCandidates), so the
// problem's u on such a row is the velocity plus Pₙ/D.
void MoreauJean::addCompliance() {
  for (int j = 0; j < static_cast<int>(active_.size()); ++j) {
    const double r = compliance_[active_[j]];
    if (r > 0) problem_.W(problem_.blocks[j].first, problem_.blocks[j].first) += r;
  }
}

bool MoreauJean::step(const Model& model, Data& data, const ConstraintList& constraints,
                      ConstraintData& cdata, ConstrainedSolver& solver,
                      const Simulator::JointForces& tau_fn, double t, VecX& q, VecX& v, double h,
                      double rest_speed) {
  error_.clear();
  work_ = {};
  servos_settled_ = true;
  joint_forces_ = static_cast<bool>(tau_fn) || !servos_.empty();
  for (int k = 0; k < static_cast<int>(all_.size()); ++k)
    slid_[k] = cdata.isSliding(all_[k].c) ? 1 : 0;  // (the last step's mode, either scheme's)
  if (!servos_.empty()) {
    servos_.law(model, t, q, v, h, options_.theta);
    if (servos_.gateDue() && !gateServos(model, data, constraints, cdata, solver, t, q, v))
      return false;
    servos_.age();
  }
  if (!freeVelocity(model, data, constraints, cdata, solver, tau_fn, t, q, v, h)) return false;
  if (servos_.anyImplicit() && !servosAlone(model, data, constraints, cdata, solver, q, v))
    return false;
  // The contacts at the predicted end q̃ = q ⊕ h v_free (θ = 1): a floating
  // body's body-frame velocity is measured in its frame at the step's end
  // (at q, the frame's turn h ω would enter the normal velocity as a
  // spurious h ω × v — a ball rolling at 2 m/s lost a third of its load).
  integrate(model, q, vfree_, h, qnext_);
  int list[6];
  for (const Candidate& k : all_) {
    cdata.setActive(k.c, true);
    cdata.setSliding(k.c, false);
    // Each contact on its nearest piece of a terrain (no latches: the
    // event scheme's way of keeping a piece between events).
    cdata.blocks[k.c].piece.latched = -1;
    cdata.blocks[k.c].piece.excluded_count = 0;
  }
  evaluateConstraintRows(model, data, constraints, cdata, t + h, qnext_, vfree_);
  for (int k = 0; k < static_cast<int>(all_.size()); ++k)
    delassus_.assemble(model, data, constraints, cdata, all_[k].c, list, rowList(all_[k], list),
                       first_[k]);
  const int rows = rows_;
  if (rows > 0) {
    uminus_.head(rows) = delassus_.b.head(rows);
    uminus_.head(rows).noalias() += delassus_.J.topRows(rows) * v;
    ufree_.head(rows) = delassus_.b.head(rows);
    ufree_.head(rows).noalias() += delassus_.J.topRows(rows) * vfree_;
  }
  selectCandidates(cdata, h, rest_speed);
  for (int k : active_)
    if (cdata.blocks[all_[k].c].singular) {
      error_ = constraints[all_[k].c]->name() + ": " + cdata.blocks[all_[k].c].singular_reason +
               " (a singular contact geometry: its rows are unusable)";
      return false;
    }
  const int n = problem_.n;
  if (!solveContacts(model, data, constraints, cdata, solver, t + h, n)) return false;
  v0_ = v;  // (v at the step's start, for the work and the positions)
  endVelocity(n, v);
  finish(cdata, v0_, v, h);
  for (int i = 0; i < servos_.size(); ++i) {
    if (!servos_.isImplicit(i)) continue;  // (an explicit servo's work is in τ's)
    const int d = servos_.dof(i);
    work_.joint += 0.5 * servos_.P()[i] * (v0_[d] + v[d]);
  }
  // q⁺ = q ⊕ h (θ v⁺ + (1 − θ) v), the step's θ (selectCandidates): ½ in
  // flight, where θ = 1 (the landing's rule) lost half the potential
  // energy a first step exchanged — a drop started in time-stepping was
  // stopped as diverging at its first step.
  vfree_ = theta_ * v + (1 - theta_) * v0_;
  integrate(model, q, vfree_, h, qnext_);
  if (theta_ != 0.5) {
    vfree_ = 0.5 * (v + v0_);
    integrate(model, q, vfree_, h, qmid_);
    work_.scheme = potentialEnergy(model, data, qmid_) - potentialEnergy(model, data, qnext_);
  }
  q.swap(qnext_);
  return true;
}

// The contact problem of the step's n candidate rows at q̃ (with the
// servos when there are any); none: nothing to solve.
bool MoreauJean::solveContacts(const Model& model, Data& data, const ConstraintList& constraints,
                               ConstraintData& cdata, ConstrainedSolver& solver, double t_end,
                               int n) {
  if (n == 0) {
    problem_.sweeps = 0;
    problem_.residual = 0;
    problem_.converged = true;
    return true;
  }
  // The Delassus operator at q̃, over the bilateral rows there.
  for (const Candidate& k : all_) cdata.setActive(k.c, false);
  evaluateConstraintRows(model, data, constraints, cdata, t_end, qnext_, vfree_);
  solver.solve(model, data, constraints, cdata, qnext_, vfree_, tau_, res2_,
               SolveOutputs::Accelerations);
  if (!res2_.ok) {
    error_ = "the Delassus operator's solve failed: " + res2_.error;
    return false;
  }
  vdot_ = res2_.vdot;
  if (servos_.anyImplicit()) return solveWithServos(model, data, constraints, cdata, solver, n);
  if (!delassus_.respond(model, data, constraints, cdata, solver, qnext_, vfree_, tau_, vdot_,
                         map_, n, res2_, problem_.W, error_))
    return false;
  addCompliance();
  solveProblem();
  return true;
}

// v⁺ = v_free + R P over the n problem rows; with servos and contacts,
// v_free without the servos + R_c P_c + R_s P_s (R_c at q̃, R_s at q); with servos and
// no contact, v_free already holds the servos' impulses (servosAlone).
void MoreauJean::endVelocity(int n, VecX& v) const {
  if (n > 0 && servos_.anyImplicit()) {
    v = vfree0_;
    v.noalias() += delassus_.R.leftCols(n) * problem_.P.head(n);
    v.noalias() += Rs_ * servos_.P();
  } else {
    v = vfree_;
    if (n > 0) v.noalias() += delassus_.R.leftCols(n) * problem_.P.head(n);
  }
}

// The gate (implicit_servos.hpp): every servo's mobility (M⁻¹)_dd under the
// bilateral rows at (t, q, v), one solve each — its response to a unit force
// on its own coordinate — and the choice of the implicit ones.
bool MoreauJean::gateServos(const Model& model, Data& data, const ConstraintList& constraints,
                            ConstraintData& cdata, ConstrainedSolver& solver, double t,
                            const VecX& q, const VecX& v) {
  for (const Candidate& k : all_) cdata.setActive(k.c, false);
  evaluateConstraintRows(model, data, constraints, cdata, t, q, v);
  tau_.setZero();  // (any τ: the response is affine in it)
  solver.solve(model, data, constraints, cdata, q, v, tau_, res2_, SolveOutputs::Accelerations);
  if (!res2_.ok) {
    error_ = "the servos' mobility solve failed: " + res2_.error;
    return false;
  }
  vdot_ = res2_.vdot;
  const int ns = servos_.size();
  map_.clear();
  for (int i = 0; i < ns; ++i) map_.push_back(rows_ + i);
  if (!delassus_.respond(model, data, constraints, cdata, solver, q, v, tau_, vdot_, map_, ns,
                         res2_, W_all_, error_, false))
    return false;
  for (int i = 0; i < ns; ++i) mobility_[i] = delassus_.R(servos_.dof(i), i);
  servos_.gate(mobility_);
  return true;
}

// The servos over the step without contacts, at q: their responses R_s
// (Delassus::respond on the servo rows), their impulses, and v_free with
// them — the velocity that predicts q̃ (and the step's end in flight).
bool MoreauJean::servosAlone(const Model& model, Data& data, const ConstraintList& constraints,
                             ConstraintData& cdata, ConstrainedSolver& solver, const VecX& q,
                             const VecX& v) {
  const int ns = servos_.size();
  map_.clear();
  for (int i = 0; i < ns; ++i)
    if (servos_.isImplicit(i)) map_.push_back(rows_ + i);
  if (!delassus_.respond(model, data, constraints, cdata, solver, q, v, tau_, vdot_, map_,
                         static_cast<int>(map_.size()), res2_, W_all_, error_, false))
    return false;
  for (int i = 0, j = 0; i < ns; ++i) {
    if (servos_.isImplicit(i)) Rs_.col(i) = delassus_.R.col(j++);
    else Rs_.col(i).setZero();  // (explicit: its force is in τ)
  }
  // Wₛₛ = e_dᵀ Rₛ, symmetric up to round-off.
  for (int i = 0; i < ns; ++i)
    for (int j = 0; j <= i; ++j)
      Wss_(i, j) = Wss_(j, i) = 0.5 * (Rs_(servos_.dof(i), j) + Rs_(servos_.dof(j), i));
  vfree0_ = vfree_;
  for (int i = 0; i < ns; ++i) u_servo_[i] = vfree_[servos_.dof(i)];
  servos_settled_ = servos_.solveAlone(Wss_, u_servo_);
  vfree_.noalias() += Rs_ * servos_.P();
  return true;
}

// The contact problem with the servos eliminated (implicit_servos.hpp): the
// responses of the n problem rows at q̃, the servos' from servosAlone, the
// contacts' Schur complement, solved again while the set of servos at their effort
// limits changes (each pass warm-started from the last).
bool MoreauJean::solveWithServos(const Model& model, Data& data, const ConstraintList& constraints,
                                 ConstraintData& cdata, ConstrainedSolver& solver, int n) {
  const int ns = servos_.size();
  if (!delassus_.respond(model, data, constraints, cdata, solver, qnext_, vfree_, tau_, vdot_,
                         map_, n, res2_, W_all_, error_))
    return false;
  // The servos' columns from their responses at q (servosAlone): W_cs = J_c Rₛ
  // and its transpose, W_ss as there — one solve per servo a step, not two;
  // the operator at q instead of q̃ is a first-order difference, as the
  // scheme's own.
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < ns; ++j)
      W_all_(i, n + j) = W_all_(n + j, i) = delassus_.J.row(map_[i]).dot(Rs_.col(j));
  W_all_.block(n, n, ns, ns) = Wss_;
  for (int i = 0; i < ns; ++i) u_servo_[i] = vfree0_[servos_.dof(i)];
  bool settled = false;
  for (int pass = 0; pass <= 2 * ns + 4 && !settled; ++pass) {
    for (int i = 0; i < n; ++i)
      problem_.u_free[i] = delassus_.J.row(map_[i]).dot(vfree0_) + delassus_.b[map_[i]];
    servos_.eliminate(W_all_, n, u_servo_, problem_.W, problem_.u_free);
    addCompliance();
    solveProblem();
    settled = servos_.impulses(W_all_, n, problem_.P);
  }
  servos_settled_ = servos_settled_ && settled;
  return true;
}

// Work terms, modes, the reported forces, the next step's warm start.
void MoreauJean::finish(const ConstraintData& cdata, const VecX& v0, const VecX& v1, double h) {
  work_.joint = 0.5 * h * tau_.dot(v0 + v1);
  std::fill(modes_.begin(), modes_.end(), Mode::Open);
  std::fill(rebound_.begin(), rebound_.end(), 0);
  std::fill(warm_.begin(), warm_.end(), 0.0);
  const ContactProblem& p = problem_;
  // A contact slides when its slip is well above what the solve's residual
  // leaves on a sticking one (redundant corners of a box creep at the
  // residual, 1e-8 m/s: taken for slides, they took the kinetic cone at the
  // next step and the box slipped at 0.4 m g instead of μₛ m g = 0.5 m g).
  const double slide_floor =
      100 * std::max(p.residual, options_.residual_tol *
                                     std::max(1.0, p.u_free.head(p.n).lpNorm<Eigen::Infinity>()));
  for (int j = 0; j < static_cast<int>(active_.size()); ++j) {
    const int k = active_[j];
    const Candidate& cand = all_[k];
    const ProblemBlock& b = p.blocks[j];
    const int o = b.first, at = first_[k];
    for (int i = 0; i < b.rows(); ++i) {
      // (A compliant normal's problem velocity holds Pₙ/D beside the motion's.)
      const double P = p.P[o + i], u_end = p.u[o + i] - (i == 0 ? compliance_[k] * P : 0.0);
      const double umid = 0.5 * (uminus_[at + i] + u_end);
      (i >= 1 && i <= b.nf ? work_.friction : work_.impact) -= P * umid;
      work_.support -= P * delassus_.b[at + i];
      warm_[6 * k + i] = P;
      const int row = i == 0 ? cand.normal : i <= b.nf ? cand.f[i - 1] : cand.e[i - 1 - b.nf];
      lambda_[cdata.offset[cand.c] + row] = P / h;
    }
    if (!(p.P[o] > 0)) continue;
    Mode mode = Mode::Stick;
    if (b.nf > 0) {
      const double pf = p.P.segment(o + 1, b.nf).norm();
      const double slip = p.u.segment(o + 1, b.nf).norm();
      if (pf >= (1 - 1e-6) * b.mu * p.P[o] && slip > slide_floor) mode = Mode::Slide;
    }
    modes_[cand.c] = mode;
    // A rebound separates at its restitution target; a contact pushed out
    // of an O(h) overlap at gap/h stays closed (and keeps its mode: a
    // sliding tyre on a gap correction of 7e-7 m/s was reported open, and
    // took the static cone at the next step).
    rebound_[cand.c] = restituted_[k] && p.u[o] > std::max(1e-9, 0.5 * p.target[o]) ? 1 : 0;
  }
}

// The step's contact problem, solved — with the last failed active-set
// finish carried over: a finish that failed from some modes, in a problem
// that Gauss–Seidel then solved by itself, is not tried from them in the
// next solves over the same contacts either (the problem moves by O(h) a
// step and from the same modes it fails again), but tried again every
// kFinishRetry solves. Measured on cad_car's 10 s under `auto` (8 004 steps
// time-stepped): 5 768 finishes were tried from the modes of the last
// step's failed one and 6 succeeded, at 22 % of the run's time. Not carried
// from a problem left at the sweep limit: there the finish is the only way
// to converge (docs/contacts.md §10).
void MoreauJean::solveProblem() {
  constexpr int kFinishRetry = 8;
  ids_.clear();
  for (int k : active_) ids_.push_back(all_[k].c);
  const bool same = ids_ == carry_ids_;
  if (same && carry_age_ < kFinishRetry) problem_.skip_modes.assign(carry_modes_.begin(), carry_modes_.end());
  else problem_.skip_modes.clear();
  problem_.solve(options_.residual_tol, options_.max_sweeps);
  const std::vector<signed char>& failed = problem_.failedModes();
  if (failed.empty() || !problem_.converged) {
    carry_modes_.clear();
    carry_ids_.clear();
  } else if (problem_.failedFinishes() > 0) {  // (a failure of its own: carried afresh)
    carry_modes_.assign(failed.begin(), failed.end());
    carry_ids_.assign(ids_.begin(), ids_.end());
    carry_age_ = 0;
  } else {
    ++carry_age_;  // (only skipped: the carried modes stay)
  }
}

// The problem as the public record states it (contact_problem.hpp).
void MoreauJean::record(ContactProblemData& out) const {
  const ContactProblem& p = problem_;
  const int n = p.n;
  out.W = p.W.topLeftCorner(n, n);
  out.u_free = p.u_free.head(n);
  out.target = p.target.head(n);
  out.warm_start = p.start.head(n);
  out.skipped_finish_modes.assign(p.skip_modes.begin(), p.skip_modes.end());
  out.P = p.P.head(n);
  out.blocks.clear();
  for (int k = 0; k < static_cast<int>(p.blocks.size()); ++k) {
    const ProblemBlock& b = p.blocks[k];
    out.blocks.push_back({all_[active_[k]].c, b.first, b.nf, b.ne, b.mu});
  }
  out.sweeps = p.sweeps;
  out.residual = p.residual;
  out.converged = p.converged;
}

}  // namespace appell::timestepping
