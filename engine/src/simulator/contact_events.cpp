// Unilateral constraints in the simulator: event detection and location, and
// the mode decision at an event (impact, then contact forces). The
// mathematics and the references are in contact_events.hpp.
#include <appell/dynamics.hpp>
#include <appell/kinematics.hpp>
#include <appell/simulator.hpp>

#include "simulator/simulator_internal.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace appell {

std::span<const NamedValue<ContactEventKind>> contactEventKindTable() {
  static const NamedValue<ContactEventKind> table[] = {
      {ContactEventKind::Touchdown, "touchdown", {}, "an open contact's gap reached 0: it closed"},
      {ContactEventKind::Bounce, "bounce", {}, "it touched down and rebounded (restitution)"},
      {ContactEventKind::LiftOff, "lift_off", {"liftoff"}, "a closed contact's normal force reached 0: it opened"},
      {ContactEventKind::Slip, "slip", {}, "a sticking contact's friction demand reached μ: it slides"},
      {ContactEventKind::Stick, "stick", {}, "a sliding contact stopped slipping and sticking holds"},
      {ContactEventKind::Feature, "feature", {}, "a closed contact moved onto another face, edge or vertex of a terrain"},
      {ContactEventKind::TimeStepping, "timestepping", {"window"}, "the automatic scheme switched to time-stepping (a mode decision failed, events piled up or the step collapsed)"},
      {ContactEventKind::Events, "events", {}, "the time-stepping window ended: the event scheme decided the modes again"},
  };
  return table;
}

const char* toString(ContactEventKind kind) {
  for (const auto& e : contactEventKindTable())
    if (e.value == kind) return e.name;
  return "?";
}


using detail::UnilateralRow;

void Simulator::setUpUnilateral() {
  for (int c = 0; c < static_cast<int>(constraints_.size()); ++c) {
    const Constraint& con = *constraints_[c];
    if (!con.unilateral()) continue;
    if (!uni_) uni_ = std::make_unique<detail::UnilateralState>();
    UnilateralRow r;
    r.c = c;
    r.row = con.unilateralRow();
    if (r.row >= con.rows())
      throw std::invalid_argument("Simulator: constraint '" + con.name() +
                                  "' names unilateral row " + std::to_string(r.row) + " of " +
                                  std::to_string(con.rows()));
    const double e = con.restitution();
    if (!(e >= 0 && e <= 1))
      throw std::invalid_argument("Simulator: constraint '" + con.name() +
                                  "' has restitution " + std::to_string(e) + " outside [0, 1]");
    r.global = cdata_->offset[c] + r.row;
    r.joint = con.jointSpace();
    r.a = con.bodyA();
    r.b = con.bodyB();
    if (r.joint) {
      r.cols = cdata_->blocks[c].joint_cols;
      r.a_joint = VecX::Zero(static_cast<int>(r.cols.size()));
    }
    const double mu = con.friction();
    if (!(mu >= 0))
      throw std::invalid_argument("Simulator: constraint '" + con.name() + "' has friction μ = " +
                                  std::to_string(mu) + " (must be ≥ 0)");
    const double mu_k = con.kineticFriction();
    if (!(mu_k >= 0 && mu_k <= mu))
      throw std::invalid_argument("Simulator: constraint '" + con.name() +
                                  "' has kinetic friction μₖ = " + std::to_string(mu_k) +
                                  " outside [0, μ = " + std::to_string(mu) + "]");
    const double creep = con.creepSpeed();
    if (!(creep >= 0 && std::isfinite(creep)))
      throw std::invalid_argument("Simulator: constraint '" + con.name() + "' has creep speed " +
                                  std::to_string(creep) + " (must be ≥ 0 and finite)");
    if (std::isfinite(mu) && cdata_->slide[c].n > 0) {
      r.mu = mu;
      r.mu_k = mu_k;
      r.nf = cdata_->slide[c].n;
      r.creep = creep;
    }
    r.slot = con.pointSlot();
    uni_->rows.push_back(r);
  }
  if (!uni_) return;
  auto& u = *uni_;
  for (const auto& r : u.rows)  // regularized friction: closed means sliding
    if (cdata_->regularized[r.c] && cdata_->isActive(r.c)) cdata_->setSliding(r.c, true);
  for (int i = 0; i < static_cast<int>(u.rows.size()); ++i) {
    const void* group = constraints_[u.rows[i].c]->pointGroup();
    if (!group) continue;
    for (int j = 0; j < static_cast<int>(u.rows.size()); ++j)
      if (j != i && constraints_[u.rows[j].c]->pointGroup() == group) {
        if (u.rows[j].slot == u.rows[i].slot)
          throw std::invalid_argument("Simulator: contacts '" +
                                      constraints_[u.rows[i].c]->name() + "' and '" +
                                      constraints_[u.rows[j].c]->name() +
                                      "' are the same point of one pair");
        u.rows[i].siblings.push_back(j);
      }
    if (u.rows[i].siblings.size() > cdata_->blocks[u.rows[i].c].excluded_features.size())
      throw std::invalid_argument("Simulator: contact '" + constraints_[u.rows[i].c]->name() +
                                  "' has more than 4 points");
  }
  u.q0 = q_;
  u.v0 = v_;
  u.vplus = v_;
  u.vminus = v_;
  u.vdot = VecX::Zero(model_.nv);
  u.impulse = VecX::Zero(cdata_->m);
  u.res.vdot = VecX::Zero(model_.nv);
  u.res.lambda = VecX::Zero(cdata_->m);
  u.res.reaction = VecX::Zero(model_.nv);
  events_.reserve(64);
  int kf = 0;
  for (const auto& r : u.rows) kf += r.nf > 0 ? 1 : 0;
  u.sliding.reserve(u.rows.size());
  u.G = MatX::Zero(model_.nv, kf);
  u.J = MatX::Zero(6, model_.nv);
  u.R = MatX::Zero(kf, kf);
  u.lam0 = VecX::Zero(kf);
  u.s = VecX::Zero(kf);
  u.tau_f = VecX::Zero(model_.nv);
  u.unit = u.res;
  int nf = 0;
  for (const auto& r : u.rows) nf += r.nf;
  u.onset.reserve(u.rows.size());
  u.was_sliding.assign(u.rows.size(), 0);
  u.onset_problem.size(model_.nv, nf, kf, u.res);
  u.settle.reserve(u.rows.size());
  u.settle_problem.size(model_.nv, nf, kf, u.res);
  u.swmax = VecX::Zero(kf);
  u.vstick = VecX::Zero(model_.nv);
  u.over_W = MatX::Zero(nf, nf);
  u.over_g = VecX::Zero(nf);
  u.over_eig = Eigen::SelfAdjointEigenSolver<MatX>(nf);
  u.feature_ahead.assign(u.rows.size(), -1);
}

namespace {

/// A pivoting's two-cycle: contact `flip` was flipped straight back — in the
/// set its multiplier pulls, out of it it moves into its support. The set
/// around it is wrong (a rigid body on more contacts than its surface
/// allows: a car on uneven ground): keep it and unload the other set
/// members in turn, from `next_unload`. False when none is left.
bool breakTwoCycle(std::vector<UnilateralRow>& rows, int flip, int& last_flip, int& next_unload) {
  int other = -1;
  for (int k = next_unload; k < static_cast<int>(rows.size()) && other < 0; ++k)
    if (k != flip && rows[k].touching && rows[k].in_set) other = k;
  if (other < 0) return false;
  rows[other].in_set = false;
  rows[flip].in_set = true;
  next_unload = other + 1;
  last_flip = -1;
  return true;
}

}  // namespace

// ---------------------------------------------------------------- detection

/// The first unilateral constraint whose event function changed sign over
/// the step just taken (end state in cdata_ and result_), or −1, and which
/// function: an open gap (touchdown), a closed normal force (lift-off), a
/// sticking friction demand beyond μ (slip), a sliding slip reversed (stick).
int Simulator::crossedConstraint(detail::Crossing& type) const {
  using detail::Crossing;
  const double ftol = options_.contacts.force_tol;
  for (int k = 0; k < static_cast<int>(uni_->rows.size()); ++k) {
    const UnilateralRow& r = uni_->rows[k];
    type = Crossing::None;
    if (!cdata_->isActive(r.c)) {
      if (!r.dormant && cdata_->gap[r.global] < 0) type = Crossing::Gap;
    } else if (options_.evaluate_end_state) {
      const double fn = result_.lambda[r.global];
      if (fn < -ftol) type = Crossing::Normal;
      else if (r.nf > 0 && !cdata_->isSliding(r.c) &&
               frictionForce(k, result_.lambda).norm() > r.mu * fn + ftol)
        type = Crossing::Cone;
      else if (r.nf > 0 && r.creep == 0 && cdata_->isSliding(r.c) &&
               cdata_->slide[r.c].slip.dot(r.dir_start) <
                   -options_.contacts.speed_tol)
        type = Crossing::Slip;
    }
    if (type != Crossing::None) return k;
  }
  return -1;
}

/// The friction rows' multipliers of unilateral row k (up to 3).
Vec3 Simulator::frictionForce(int k, const VecX& lambda) const {
  const UnilateralRow& r = uni_->rows[k];
  const auto& sr = cdata_->slide[r.c];
  Vec3 f = Vec3::Zero();
  for (int i = 0; i < sr.n; ++i) f[i] = lambda[cdata_->offset[r.c] + sr.row[i]] / sr.scale[i];
  return f;
}

/// Integrates from the step's start by τ (no projection): the state the
/// event functions are evaluated on. τ = 0 is the start itself.
bool Simulator::restepTo(double tau, StepStatus& st) {
  auto& u = *uni_;
  t_ = u.t0;
  q_ = u.q0;
  v_ = u.v0;
  work_ = work_prev_;
  if (tau <= 0) return true;
  integrator_->reset();
  field_->clear();
  const StepResult r = integrator_->step(*field_, t_, q_, v_, tau);
  takeStepWork(r);
  st.evaluations += r.evaluations;
  counters_.evaluations += r.evaluations;
  ++counters_.event_steps;
  return r.ok && q_.allFinite() && v_.allFinite();
}

/// Event function of unilateral row k at the current (t_, q_, v_): the gap
/// while open; while closed λᵤ, or μλₙ − |λₜ| (sticking), or the slip along
/// its direction at the step's start (sliding) — one solve when it needs λ.
double Simulator::eventFunction(int k, detail::Crossing type) {
  using detail::Crossing;
  const UnilateralRow& r = uni_->rows[k];
  if (type == Crossing::Feature) return searchFeatures() >= 0 ? -1.0 : 1.0;  // any switched
  evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
  if (type == Crossing::Gap) return cdata_->gap[r.global];
  if (type == Crossing::Slip) return cdata_->slide[r.c].slip.dot(r.dir_start);
  tau_.setZero();
  if (tau_fn_) tau_fn_(t_, q_, v_, tau_);
  if (!solveDynamics(t_, q_, v_, tau_, uni_->res)) return std::numeric_limits<double>::quiet_NaN();
  const double fn = uni_->res.lambda[r.global];
  if (type == Crossing::Normal) return fn;
  return r.mu * fn - frictionForce(k, uni_->res.lambda).norm();
}

StepStatus Simulator::locateAndHandleEvent(StepStatus st, double h, int k,
                                           detail::Crossing type) {
  auto& u = *uni_;
  const ContactEventOptions& o = options_.contacts;
  // The step's start: the last good state (t_prev_ …), saved by step().
  u.t0 = t_prev_;
  u.q0 = q_prev_;
  u.v0 = v_prev_;
  if (k < 0) k = crossedConstraint(type);
  bool feature = type == detail::Crossing::Feature;  // a piece switch among the events
  double hi = h;
  // The event functions along the step: on the integrator's dense output
  // when it has one (Dormand–Prince: no new evaluations), else on steps from
  // the start shortened to τ. The step to the located event is always a
  // proper step of the method.
  const bool dense = integrator_->denseOutput(1.0, q_, v_);
  auto stateAt = [&](double tau) {
    if (!dense) return restepTo(tau, st);
    t_ = u.t0 + tau;
    if (tau <= 0) {
      q_ = u.q0;
      v_ = u.v0;
      return true;
    }
    return integrator_->denseOutput(tau / h, q_, v_);
  };
  for (int round = 0; k >= 0 && round < static_cast<int>(u.rows.size()) + 1; ++round) {
    // Illinois (modified regula falsi) on φ_k(τ) over [0, hi]: φ(0) ≥ 0 > φ(hi).
    double a = 0, b = hi;
    if (!stateAt(a)) return fail(st, "event location: the step from the last state failed");
    double fa = eventFunction(k, type);
    if (!stateAt(b)) return fail(st, "event location: the step from the last state failed");
    b = t_ - u.t0;
    double fb = eventFunction(k, type);
    if (!std::isfinite(fa) || !std::isfinite(fb))
      return fail(st, "event location: the event function of '" +
                          constraints_[u.rows[k].c]->name() + "' is not finite");
    if (fa <= 0 && (type == detail::Crossing::Gap || type == detail::Crossing::Slip)) {
      // A contact that opened at the step's start (a bounce, a lift-off) has
      // g(0) ≈ 0 but is separating: its gap is positive just after; one that
      // started sliding there has zero slip, positive just after. Bracket
      // the root from there.
      for (double s = 0.5; s > 1e-9 && fa <= 0; s *= 0.25) {
        if (!stateAt(s * b)) return fail(st, "event location: a shortened step failed");
        const double f = eventFunction(k, type);
        if (f > 0) {
          a = t_ - u.t0;
          fa = f;
        }
      }
    }
    if (fa <= 0) {
      b = 0;  // already at (or past) the event at the start: decide there
    } else {
      int side = 0;
      for (int it = 0; it < o.max_locate_iterations && b - a > o.time_tol; ++it) {
        // (A switch of piece is a step function: bisection.)
        double c = type == detail::Crossing::Feature ? 0.5 * (a + b) : (a * fb - b * fa) / (fb - fa);
        if (!(c > a && c < b)) c = 0.5 * (a + b);
        if (!stateAt(c)) return fail(st, "event location: a shortened step failed");
        c = t_ - u.t0;  // an adaptive method may have taken less than asked
        const double fc = eventFunction(k, type);
        if (!std::isfinite(fc)) return fail(st, "event location: non-finite event function");
        if (fc > 0) {
          a = c;
          fa = fc;
          if (side == 1) fb *= 0.5;
          side = 1;
        } else {
          b = c;
          fb = fc;
          if (side == -1) fa *= 0.5;
          side = -1;
        }
        if (fc == 0) break;
      }
    }
    // Did another contact cross before τ = b? Then that one is first.
    if (!stateAt(b)) return fail(st, "event location: a shortened step failed");
    hi = t_ - u.t0;
    int earlier = -1;
    detail::Crossing earlier_type = detail::Crossing::None;
    if (type != detail::Crossing::Feature) {
      earlier = searchFeatures();
      if (earlier >= 0) earlier_type = detail::Crossing::Feature;
    }
    evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
    for (int j = 0; j < static_cast<int>(u.rows.size()) && earlier < 0; ++j) {
      if (j == k && type != detail::Crossing::Feature) continue;
      const UnilateralRow& r = u.rows[j];
      if (!cdata_->isActive(r.c)) {
        if (!r.dormant && cdata_->gap[r.global] < -o.gap_tol)
          earlier = j, earlier_type = detail::Crossing::Gap;
      } else if (cdata_->isSliding(r.c) && r.creep == 0) {
        if (eventFunction(j, detail::Crossing::Slip) < -o.speed_tol)
          earlier = j, earlier_type = detail::Crossing::Slip;
      } else if (cdata_->isSliding(r.c)) {  // regularized: only its load can cross
        if (options_.evaluate_end_state && eventFunction(j, detail::Crossing::Normal) < -o.force_tol)
          earlier = j, earlier_type = detail::Crossing::Normal;
      } else if (options_.evaluate_end_state) {
        if (eventFunction(j, detail::Crossing::Normal) < -o.force_tol)
          earlier = j, earlier_type = detail::Crossing::Normal;
        else if (r.nf > 0 && eventFunction(j, detail::Crossing::Cone) < -o.force_tol)
          earlier = j, earlier_type = detail::Crossing::Cone;
      }
    }
    if (earlier < 0) break;
    k = earlier;
    type = earlier_type;
    feature = feature || type == detail::Crossing::Feature;
  }
  if (feature) {
    // The pieces feature_window later: contacts switching that soon after
    // the first switch with it (contact_features.cpp).
    if (!stateAt(std::min(hi + o.feature_window, h)))
      return fail(st, "event location: a shortened step failed");
    searchFeatures();
    for (int j = 0; j < static_cast<int>(u.rows.size()); ++j) u.feature_ahead[j] = u.rows[j].feature_free;
    if (!dense && !stateAt(hi)) return fail(st, "event location: a shortened step failed");
  }
  if (dense && !restepTo(hi, st))  // the step itself, to the event
    return fail(st, "event location: the step to the event failed");
  if (hi <= 0) {
    if (++u.zero_events > 2)
      return fail(st, "contact '" + constraints_[u.rows[k].c]->name() +
                          "' switches at every step start: no consistent contact mode" +
                          rigidRollingHint());
  } else {
    u.zero_events = 0;
  }
  // The step to the event: q_, v_ hold the integrated state at t0 + hi.
  for (auto& r : u.rows) {
    r.lifting = false;
    r.touching_down = false;
  }
  UnilateralRow& ev = u.rows[k];
  if (type == detail::Crossing::Normal) ev.lifting = true;
  if (type == detail::Crossing::Gap) ev.touching_down = true;
  st.h_taken = hi;
  // Drift control on the old set and pieces (the closed rows' velocity drift
  // is not slip, the open ones' approach speed stays); the new pieces (a
  // contact may now approach its new one: an impact), the modes, then drift
  // control on the new set.
  std::string error;
  if (!projectAfterModes(error)) return fail(st, error);
  switchFeatures(feature);
  const double T_before = appell::kineticEnergy(model_, *data_, q_, v_);
  if (type == detail::Crossing::Cone || type == detail::Crossing::Slip) {
    // Friction: the contact starts sliding against its sticking force, or
    // its slip stopped and it sticks if the cone allows (frictionPhase).
    if (type == detail::Crossing::Slip) {
      cdata_->setSliding(ev.c, false);
      ev.redeciding = true;
    } else {  // at the cone's edge: slide against the sticking force
      evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
      tau_.setZero();
      if (tau_fn_) tau_fn_(t_, q_, v_, tau_);
      if (!solveDynamics(t_, q_, v_, tau_, u.res)) return fail(st, u.res.error);
      const Vec3 ft = frictionForce(k, u.res.lambda);
      if (ft.norm() > 0) ev.dir = -ft / ft.norm();
      ev.dir_start = ev.dir;
      cdata_->setSliding(ev.c, true);
      logEvent(ContactEventKind::Slip, k, 0, 0, 0);
    }
    const bool phase_ok = frictionPhase(error, type == detail::Crossing::Cone ? k : -1);
    ev.redeciding = false;
    if (!phase_ok) return fail(st, "at t = " + std::to_string(t_) + ": " + error);
    if (type == detail::Crossing::Slip && !cdata_->isSliding(ev.c))
      logEvent(ContactEventKind::Stick, k, 0, 0, 0);
  } else if (!decideModes(error) || !frictionPhase(error)) {
    return fail(st, "at t = " + std::to_string(t_) + ": " + error + rigidRollingHint());
  }
  if (!projectAfterModes(error)) return fail(st, error);
  dissipated_ += T_before - appell::kineticEnergy(model_, *data_, q_, v_);
  for (auto& r : u.rows) r.dir_start = r.dir;  // the next step's slip reference
  applyLatches();  // contacts that closed keep the piece they touched down on
  integrator_->reset();
  if (!evaluateEndState(error)) return fail(st, error);
  st.events = static_cast<int>(events_.size());
  counters_.events += st.events;
  return st;
}

/// The step's drift control with the new active set.
bool Simulator::projectAfterModes(std::string& error) {
  if (options_.project_positions) {
    projection_ = projector_->project(model_, *data_, constraints_, *cdata_, t_, q_);
    if (!projection_.ok) {
      error = "position projection failed: " + projection_.error;
      return false;
    }
  }
  if (options_.project_velocities && cdata_->m_active > 0) {
    if (!options_.project_positions)
      evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
    if (!solver_->projectVelocity(model_, *data_, constraints_, *cdata_, q_, v_, impulse_)) {
      error = "velocity projection failed: " + solver_->lastError();
      return false;
    }
  }
  return true;
}

// ------------------------------------------------------------ mode decision

namespace {

/// A saved joint-space row (over its columns) applied to x.
double sparseDot(const UnilateralRow& r, const VecX& x) {
  double s = 0;
  for (size_t k = 0; k < r.cols.size(); ++k) s += r.a_joint[static_cast<int>(k)] * x[r.cols[k]];
  return s;
}

}  // namespace

/// γ = ġ of unilateral row k from its saved row, at data_'s velocities.
double Simulator::rowVelocity(int k) const {
  const UnilateralRow& r = uni_->rows[k];
  if (r.joint) return sparseDot(r, v_) + r.bval;
  double g = r.bval;
  if (r.a >= 0) g += r.wa.dot(data_->oMi[r.a].act(data_->v[r.a]));
  if (r.b >= 0) g -= r.wb.dot(data_->oMi[r.b].act(data_->v[r.b]));
  return g;
}

/// γ̇ of unilateral row k, data_ holding forwardKinematics(q, v, v̇).
double Simulator::rowAcceleration(int k) const {
  const UnilateralRow& r = uni_->rows[k];
  if (r.joint) return sparseDot(r, uni_->vdot) + r.abias;
  double g = r.kappa;
  if (r.a >= 0) g += r.wa.dot(spatialAccelerationWorld(*data_, r.a));
  if (r.b >= 0) g -= r.wb.dot(spatialAccelerationWorld(*data_, r.b));
  return g;
}

/// What a failed mode decision may mean when several closed contacts roll
/// without slip or by Coulomb's law (sticking, or switching between stick
/// and slip): a vehicle on uneven ground, over-constrained by its own tyres
/// (docs/contacts.md §4). Empty when fewer than two such contacts are closed.
std::string Simulator::rigidRollingHint() const {
  int rigid = 0;
  for (const auto& r : uni_->rows)
    if (cdata_->isActive(r.c) && cdata_->slide[r.c].n > 0 && r.creep == 0) ++rigid;
  if (rigid < 2) return "";
  return " (" + std::to_string(rigid) +
         " closed contacts roll without slip or stick by Coulomb's law, which can "
         "over-constrain a vehicle on uneven ground; tyres with a finite 'mu' and a "
         "'creep_speed' slip a little instead: docs/contacts.md §4, §8)";
}

/// Closes every touching contact, evaluates the rows at (t_, q_, v_) and keeps
/// a copy of each unilateral row; the active set is left all-touching-closed.
void Simulator::saveCandidateRows() {
  auto& u = *uni_;
  evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
  for (auto& r : u.rows) {
    r.gap = cdata_->gap[r.global];
    r.touching = !r.bounced && (cdata_->isActive(r.c) ||
                                (!r.dormant && std::abs(r.gap) <= options_.contacts.gap_tol) ||
                                r.touching_down);
    if (r.touching) cdata_->setActive(r.c, true);
  }
  evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
  for (auto& r : u.rows) {
    if (!r.touching) continue;
    const RowBlock& blk = cdata_->blocks[r.c];
    if (r.joint) {
      r.a_joint = blk.A_joint.row(r.row).transpose();
      r.bval = blk.b_joint[r.row];
      r.abias = blk.abias_joint[r.row];
    } else {
      r.wa = blk.Wa.row(r.row).transpose();
      r.wb = blk.Wb.row(r.row).transpose();
      r.bval = blk.b[r.row];
      r.kappa = blk.kappa[r.row];
    }
  }
}

void Simulator::logEvent(ContactEventKind kind, int k, double before, double after,
                         double impulse) {
  const UnilateralRow& r = uni_->rows[k];
  ContactEvent e;
  e.t = t_;
  e.constraint = r.c;
  e.kind = kind;
  e.speed_before = before;
  e.speed_after = after;
  e.normal_impulse = impulse;
  // The friction impulse of this event's impact (none for a lift-off, a
  // stick or a change of piece, whatever impact came before).
  const bool impact = kind == ContactEventKind::Touchdown || kind == ContactEventKind::Bounce ||
                      kind == ContactEventKind::Slip;
  e.tangential_impulse = impact ? r.tangential : 0;
  events_.push_back(e);
}

/// Shifts the closed impact rows so that the projection makes γ⁺ = −e γ⁻.
void Simulator::shiftImpactTargets() {
  for (auto& r : uni_->rows) {
    if (!r.touching || !r.in_set) continue;
    cdata_->b[r.global] += r.target;
    RowBlock& blk = cdata_->blocks[r.c];
    if (r.joint) blk.b_joint[r.row] += r.target;
    else blk.b[r.row] += r.target;
  }
}

/// Impact: Newton's law on the touching contacts that approach, with the
/// velocity projection as the impulse solve, by principal pivoting; then
/// Coulomb's law on their friction impulses (friction_impact.cpp). A set
/// member at rest that those impulses would pull separates: it leaves the
/// set for good and the impact is solved again (at most once per contact).
bool Simulator::impactPhase(std::string& error) {
  auto& u = *uni_;
  const ContactEventOptions& o = options_.contacts;
  forwardKinematics(model_, *data_, q_, v_);
  bool any = false;
  for (int k = 0; k < static_cast<int>(u.rows.size()); ++k) {
    auto& r = u.rows[k];
    r.impulse = r.tangential = 0;
    r.target = 0;
    r.separated = false;
    if (!r.touching) continue;
    r.gamma = rowVelocity(k);
    if (r.gamma < -o.speed_tol) {
      any = true;
      const double e = constraints_[r.c]->restitution();
      r.target = r.gamma < -o.rest_speed ? e * r.gamma : 0.0;
    }
    r.in_set = r.was_closed || r.gamma < -o.speed_tol;
  }
  if (!any) return true;
  for (int round = 0;; ++round) {
    int last_flip = -1, next_unload = 0;
    for (int it = 0;; ++it) {
      if (it == o.max_mode_iterations) {
        error = "impact: no consistent set of contacts after " + std::to_string(it) + " pivots";
        return false;
      }
      for (auto& r : u.rows)
        if (r.touching) cdata_->setActive(r.c, r.in_set);
      evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
      shiftImpactTargets();
      u.vplus = v_;
      if (!solver_->projectVelocity(model_, *data_, constraints_, *cdata_, q_, u.vplus, u.impulse)) {
        // Restitution targets on redundant rows can contradict each other: a
        // ball resting on one slope of a valley that strikes the other with
        // e > 0 cannot both rebound there and keep rolling on the first (two
        // points of one rigid body keep their distance). A set member at rest
        // (no target) is then the one that gives way: it leaves the set, and
        // the pivoting goes on (it rejoins if it would approach).
        int resting = -1;
        for (int k = 0; k < static_cast<int>(u.rows.size()) && resting < 0; ++k) {
          const auto& r = u.rows[k];
          if (r.touching && r.in_set && r.target == 0 && r.gamma >= -o.speed_tol) resting = k;
        }
        if (resting < 0) {
          error = "impact: the impulse solve failed: " + solver_->lastError();
          return false;
        }
        u.rows[resting].in_set = false;
        last_flip = resting;
        continue;
      }
      std::swap(v_, u.vplus);  // rowVelocity reads v_ and data_ at v⁺
      forwardKinematics(model_, *data_, q_, v_);
      double scale = 0;
      for (const auto& r : u.rows)
        if (r.touching && r.in_set) scale = std::max(scale, std::abs(u.impulse[r.global]));
      int flip = -1;
      for (int k = 0; k < static_cast<int>(u.rows.size()) && flip < 0; ++k) {
        auto& r = u.rows[k];
        if (!r.touching) continue;
        if (r.in_set) {
          r.impulse = -u.impulse[r.global];  // v⁺ = v − M⁻¹Aᵀμ: the push along the row is −μ
          if (r.impulse < -1e-10 * (1 + scale)) flip = k;
        } else if (!r.separated && rowVelocity(k) + r.target < -o.speed_tol) {
          flip = k;
        }
      }
      if (flip < 0) break;
      std::swap(v_, u.vplus);  // back to the pre-impact velocity
      if (flip == last_flip) {  // it would pull, and out of the set it approaches
        if (!breakTwoCycle(u.rows, flip, last_flip, next_unload)) {
          error = "impact: no consistent set of contacts: '" + constraints_[u.rows[flip].c]->name() +
                  "' would pull and cannot stay out";
          return false;
        }
        continue;
      }
      u.rows[flip].in_set = !u.rows[flip].in_set;
      last_flip = flip;
    }
    // (u.vplus holds v⁻.)
    int separating = -1;
    if (frictionImpact(error, separating)) break;
    // The friction impulses would pull a set member that was at rest: it
    // separates — out of the set, and the impact is solved again from v⁻.
    if (separating < 0 || round == static_cast<int>(u.rows.size())) return false;
    u.rows[separating].in_set = false;
    u.rows[separating].separated = true;
    v_ = u.vminus;
    forwardKinematics(model_, *data_, q_, v_);
  }
  // v_ is v⁺. Contacts that took an impulse with restitution rebound: open.
  for (int k = 0; k < static_cast<int>(u.rows.size()); ++k) {
    auto& r = u.rows[k];
    if (!r.touching || !r.in_set) continue;
    const Constraint& con = *constraints_[r.c];
    double t2 = 0;
    for (int i = 0; i < con.rows(); ++i)
      if (isTangential(con.rowKind(i))) t2 += std::pow(u.impulse[cdata_->offset[r.c] + i], 2);
    r.tangential = std::sqrt(t2);
    const double after = rowVelocity(k);
    if (r.target < 0) {
      logEvent(ContactEventKind::Bounce, k, r.gamma, after, r.impulse);
      r.touching = false;  // separating: not a candidate of the force problem
      r.bounced = true;
      cdata_->setActive(r.c, false);
    } else if (r.gamma < -o.speed_tol) {
      logEvent(ContactEventKind::Touchdown, k, r.gamma, after, r.impulse);
      r.touching_down = false;  // logged
      r.was_closed = true;      // closed plastically: the force problem starts from it
    }
  }
  return true;
}

/// Contact forces: λᵤ ≥ 0 for the closed, γ̇ ≥ 0 for the open touching
/// contacts, by principal pivoting with one dynamics solve per pivot.
bool Simulator::forcePhase(std::string& error) {
  auto& u = *uni_;
  const ContactEventOptions& o = options_.contacts;
  const double acc_tol = o.force_tol * (1 + model_.gravity.norm());
  saveCandidateRows();  // rows at the post-impact velocity (κ depends on v)
  // Only contacts at rest take part: one that separates (γ > 0, the trailing
  // foot an impact unloaded) is open, and lifts off if it was closed. One
  // that separates slower than rest_speed is held (its velocity projected to
  // zero): a body rocking between contacts with ever smaller plastic impacts
  // (an accumulation of impacts in finite time) comes to rest.
  bool any = false, held = false;
  for (int k = 0; k < static_cast<int>(u.rows.size()); ++k) {
    auto& r = u.rows[k];
    if (!r.touching) continue;
    const double gamma = rowVelocity(k);
    if (gamma > std::max(o.speed_tol, r.was_closed || r.touching_down ? o.rest_speed : 0.0)) {
      r.touching = false;
      cdata_->setActive(r.c, false);
      if (r.was_closed) logEvent(ContactEventKind::LiftOff, k, 0, gamma, 0);
      continue;
    }
    held = held || gamma > o.speed_tol;
    any = true;
    r.in_set = !r.lifting && (r.was_closed || r.touching_down);
  }
  if (!any) return true;
  u.vminus = v_;
  int last_flip = -1, next_unload = 0;
  for (int it = 0;; ++it) {
    if (it == o.max_mode_iterations) {
      error = "contact modes: no consistent set of contacts after " + std::to_string(it) +
              " pivots (a Painlevé-type configuration?)";
      return false;
    }
    for (auto& r : u.rows)
      if (r.touching) cdata_->setActive(r.c, r.in_set);
    // The velocity the trial set holds: a held contact still separates at up
    // to rest_speed, and redundant rows (two sticking corners on one edge)
    // give consistent accelerations only at a velocity that satisfies them
    // all — so with a held contact, project onto the trial set (plastic)
    // before solving. (Not otherwise: a contact that slips keeps its slip for
    // the friction phase.)
    v_ = u.vminus;
    evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
    if (held && cdata_->m_active > 0) {
      u.vplus = v_;
      if (!solver_->projectVelocity(model_, *data_, constraints_, *cdata_, q_, u.vplus,
                                    u.impulse)) {
        error = "contact modes: the velocity projection failed: " + solver_->lastError();
        return false;
      }
      std::swap(v_, u.vplus);
      evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
    }
    tau_.setZero();
    if (tau_fn_) tau_fn_(t_, q_, v_, tau_);
    if (!solveDynamics(t_, q_, v_, tau_, u.res)) {
      // No acceleration holds every contact of the trial set: a rigid body
      // on more contacts than its surface allows — a car whose tyres meet a
      // ramp askew (the wobbly table). One of them unloads: the first whose
      // opening leaves a consistent set that it separates from (γ̇ ≥ 0) and
      // no contact pulls.
      const int drop = unloadingContact();
      if (drop < 0) {
        error = "contact modes: " + u.res.error;
        return false;
      }
      u.rows[drop].in_set = false;
      continue;
    }
    u.vdot = u.res.vdot;
    forwardKinematics(model_, *data_, q_, v_, u.vdot);
    // The tolerances scale with the forces at work: with 10⁹ N·m on a wheel,
    // round-off in λ and γ̈ is far above 1e-9 and an absolute test would
    // pivot on noise forever.
    const double fscale = std::max({1.0, u.res.lambda.lpNorm<Eigen::Infinity>(),
                                    tau_.lpNorm<Eigen::Infinity>()});
    const double ascale = std::max(1.0, u.vdot.lpNorm<Eigen::Infinity>());
    int flip = -1;
    for (int k = 0; k < static_cast<int>(u.rows.size()) && flip < 0; ++k) {
      const auto& r = u.rows[k];
      if (!r.touching) continue;
      if (r.in_set ? u.res.lambda[r.global] < -o.force_tol * fscale
                   : rowAcceleration(k) < -acc_tol * ascale)
        flip = k;
    }
    if (flip < 0) break;
    if (flip == last_flip) {  // it would pull, and out of the set it accelerates into its support
      if (!breakTwoCycle(u.rows, flip, last_flip, next_unload)) {
        error = "contact modes: no consistent set of contacts: '" +
                constraints_[u.rows[flip].c]->name() +
                "' would pull and cannot separate (a Painlevé-type configuration?)";
        return false;
      }
      continue;
    }
    u.rows[flip].in_set = !u.rows[flip].in_set;
    last_flip = flip;
  }
  for (int k = 0; k < static_cast<int>(u.rows.size()); ++k) {
    const auto& r = u.rows[k];
    if (!r.touching) continue;
    if (r.was_closed && !r.in_set) logEvent(ContactEventKind::LiftOff, k, 0, 0, 0);
    if (!r.was_closed && r.in_set) logEvent(ContactEventKind::Touchdown, k, r.gamma, 0, 0);
  }
  return true;
}

/// Friction modes at (t_, q_, v_), the normal modes decided. The contacts
/// that are not slipping are decided together first (frictionOnset), when
/// one of them needs a decision: a sticking one over its cone, a sliding one
/// whose slip stopped, or `forced` (at its slip event). Then, until nothing
/// changes (each change moves the others' loads): a closed contact that
/// slips (an initial state sliding, or one whose impact left the cone)
/// slides along its slip; a sticking one whose friction demand exceeds μ
/// slides against its sticking force (−λₜ/|λₜ|: the friction it already
/// exerts, at its limit).
bool Simulator::frictionPhase(std::string& error, int forced) {
  auto& u = *uni_;
  const ContactEventOptions& o = options_.contacts;
  bool onset_done = false;
  // Regularized contacts slide whenever closed (their force a function of
  // the slip); nothing below decides their mode.
  for (UnilateralRow& r : u.rows)
    if (r.creep > 0 && cdata_->isActive(r.c) && !cdata_->isSliding(r.c))
      cdata_->setSliding(r.c, true);
  for (int it = 0;; ++it) {
    if (it == o.max_mode_iterations) {
      error = "friction modes: no consistent stick/slip set after " + std::to_string(it) + " passes";
      return false;
    }
    evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
    tau_.setZero();
    if (tau_fn_) tau_fn_(t_, q_, v_, tau_);
    if (!solveDynamics(t_, q_, v_, tau_, u.res)) {
      error = "friction modes: " + u.res.error;
      return false;
    }
    if (!onset_done) {
      onset_done = true;
      bool needed = forced >= 0;
      for (int k = 0; k < static_cast<int>(u.rows.size()) && !needed; ++k) {
        const UnilateralRow& r = u.rows[k];
        if (r.nf == 0 || r.creep > 0 || !cdata_->isActive(r.c) ||
            contactSlip(k).norm() > o.speed_tol)
          continue;
        needed = cdata_->isSliding(r.c) ||
                 frictionForce(k, u.res.lambda).norm() > r.mu * u.res.lambda[r.global] + o.force_tol;
      }
      if (needed) {
        if (!frictionOnset(forced, error)) return false;
        continue;
      }
    }
    int change = -1;
    for (int k = 0; k < static_cast<int>(u.rows.size()) && change < 0; ++k) {
      UnilateralRow& r = u.rows[k];
      if (r.nf == 0 || !cdata_->isActive(r.c) || cdata_->isSliding(r.c)) continue;
      const double fn = u.res.lambda[r.global];
      // Sticking rows' residuals are the slip (before any projection).
      const Vec3 slip = contactSlip(k);
      const Vec3 ft = frictionForce(k, u.res.lambda);
      if (slip.norm() > o.speed_tol) {
        r.dir = slip / slip.norm();
      } else if (ft.norm() > r.mu * fn + o.force_tol && ft.norm() > 0) {
        r.dir = -ft / ft.norm();
      } else {
        continue;
      }
      r.dir_start = r.dir;
      cdata_->setSliding(r.c, true);
      if (!r.redeciding) logEvent(ContactEventKind::Slip, k, 0, slip.norm(), 0);
      change = k;
    }
    if (change < 0) return true;
  }
}

/// In the force phase, when the trial set is inconsistent: the in-set
/// contact whose opening gives a consistent set where it separates and every
/// other in-set contact pushes — of those, the one that separates fastest —
/// or −1. Only a real inconsistency unloads a contact: the separation must
/// exceed kUnloadAcceleration of the state's accelerations, or a residual
/// that drift leaves (a state projected to 1e-6) would open a loaded tyre;
/// that stays an error. One solve per candidate; the active set is left as
/// the trial set.
int Simulator::unloadingContact() {
  constexpr double kUnloadAcceleration = 1e-4;
  auto& u = *uni_;
  const double ftol = options_.contacts.force_tol;
  int found = -1;
  double fastest = 0;
  for (int j = 0; j < static_cast<int>(u.rows.size()); ++j) {
    UnilateralRow& cand = u.rows[j];
    if (!cand.touching || !cand.in_set) continue;
    cdata_->setActive(cand.c, false);
    evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
    if (solveDynamics(t_, q_, v_, tau_, u.res)) {
      u.vdot = u.res.vdot;
      forwardKinematics(model_, *data_, q_, v_, u.vdot);
      const double fscale = std::max(1.0, u.res.lambda.lpNorm<Eigen::Infinity>());
      const double ascale = std::max(1.0, u.res.vdot.lpNorm<Eigen::Infinity>());
      const double separation = rowAcceleration(j);
      bool ok = separation >= kUnloadAcceleration * ascale && separation > fastest;
      for (const UnilateralRow& r : u.rows)
        ok = ok && !(r.touching && r.in_set && r.c != cand.c && u.res.lambda[r.global] < -ftol * fscale);
      if (ok) {
        found = j;
        fastest = separation;
      }
    }
    cdata_->setActive(cand.c, true);
  }
  return found;
}

/// Decides the mode of every touching unilateral constraint at (t_, q_, v_):
/// open the ones with clearance, impact the approaching ones, then solve for
/// the contact forces. Leaves the active set in cdata_.
bool Simulator::decideModes(std::string& error) {
  auto& u = *uni_;
  for (auto& r : u.rows) {
    r.was_closed = cdata_->isActive(r.c);
    r.bounced = false;
  }
  saveCandidateRows();
  for (auto& r : u.rows)
    if (!r.touching) cdata_->setActive(r.c, false);
  return impactPhase(error) && forcePhase(error);
}

/// A closed contact whose contact point jumped inside the step — a disk
/// falling flat, whose lowest rim point runs round the rim — approaches the
/// support at the step's end faster than rest_speed. That is an impact:
/// resolved here, at the step's end, by the same impact and force problems as
/// a touchdown, its energy loss counted — instead of being absorbed unseen by
/// the drift projection. (A terrain's change of piece is located instead:
/// contact_features.cpp.) `rows_current` on entry: cdata_ and data_ hold the
/// rows at (t_, q_, v_); on return: they still do (no impact).
bool Simulator::pointJumpImpact(std::string& error, bool& rows_current) {
  auto& u = *uni_;
  // The rows at the step's end; their forward kinematics (q, v) leave the
  // bodies' velocities in data_ for the normal velocities below.
  if (!rows_current) evaluateConstraintRows(model_, *data_, constraints_, *cdata_, t_, q_, v_);
  rows_current = false;
  bool approaching = false;
  for (const auto& r : u.rows) {
    if (r.joint || !cdata_->isActive(r.c)) continue;
    const RowBlock& blk = cdata_->blocks[r.c];
    double gamma = blk.b[r.row];
    if (r.a >= 0) gamma += blk.Wa.row(r.row).dot(data_->oMi[r.a].act(data_->v[r.a]));
    if (r.b >= 0) gamma -= blk.Wb.row(r.row).dot(data_->oMi[r.b].act(data_->v[r.b]));
    approaching = approaching || gamma < -options_.contacts.rest_speed;
  }
  if (!approaching) {
    rows_current = true;
    return true;
  }
  if (options_.project_positions) {
    projection_ = projector_->project(model_, *data_, constraints_, *cdata_, t_, q_, true);
    if (!projection_.ok) {
      error = "position projection failed: " + projection_.error;
      return false;
    }
  }
  forwardKinematics(model_, *data_, q_, v_);
  const double T_before = appell::kineticEnergy(model_, *data_, q_, v_);
  for (auto& r : u.rows) r.lifting = r.touching_down = false;
  if (!decideModes(error) || !frictionPhase(error) || !projectAfterModes(error)) return false;
  dissipated_ += T_before - appell::kineticEnergy(model_, *data_, q_, v_);
  integrator_->reset();
  return true;
}

}  // namespace appell
