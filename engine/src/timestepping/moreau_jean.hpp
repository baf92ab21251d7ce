// The time-stepping stage of the simulator: Moreau–Jean steps for frictional
// unilateral contacts (Jean, "The non-smooth contact dynamics method", CMAME
// 177, 1999; Acary & Brogliato, "Numerical Methods for Nonsmooth Dynamical
// Systems", Springer 2008, ch. 10). One step from (t, q, v) over h:
//
//   v_free = v + h v̇₀            v̇₀: the solver's acceleration with only the
//                                 bilateral rows G closed (then projected
//                                 onto G v + b = 0 at q)
//   u      = J v + b             the candidate contacts' rows (normal,
//                                 friction, ideal), u⁻ at v, u_free at v_free
//   v⁺     = v_free + R P        R = (M⁻¹ − M⁻¹Gᵀ(GM⁻¹Gᵀ)⁺GM⁻¹) Jᵀ
//   u⁺     = u_free + W P        W = J R, the Delassus operator
//   q⁺     = q ⊕ h (θ v⁺ + (1 − θ) v)
//
// R's columns are the responses of the scene's own O(n) solver to unit
// forces along the rows (delassus.cpp: m solves, each O(n)); P, the
// impulses over the step, solve the contact problem (contact_problem.cpp):
// per contact, Newton's restitution u⁺ₙ + e u⁻ₙ ≥ 0 ⊥ Pₙ ≥ 0 and Coulomb's
// cone in De Saxcé's form; rows of μ = ∞ (ideal rolling) and custom rows
// hold as equalities while the contact pushes. A contact is a candidate when
// its gap closes within the step at the free velocity, g + h u_free,ₙ ≤ gap_tol.
// Spin friction and regularized creep are the event scheme's: here spin rows
// of a finite-μ contact are free and a creep contact is plain Coulomb.
//
// A stage in MuJoCo's sense: a function over (model, data, state) whose
// workspace is sized once at construction; step() allocates nothing.
#pragma once

#include "timestepping/contact_problem.hpp"
#include "timestepping/implicit_servos.hpp"

#include <appell/contact_problem.hpp>
#include <appell/simulator.hpp>

#include <string>
#include <vector>

namespace appell::timestepping {

/// Throws std::invalid_argument naming the first option out of range.
void checkOptions(const TimeSteppingOptions& options);

/// What a contact did over the step: its impulse pushed (closed) or not,
/// inside its cone (sticking) or on it (sliding).
enum class Mode : signed char { Open, Stick, Slide };

/// One unilateral constraint in the problem: where its rows are.
struct Candidate {
  int c = -1;             ///< constraint index
  int normal = -1;        ///< the normal row in the constraint
  int nf = 0, ne = 0;     ///< friction rows (finite μ) and equality rows
  int f[3] = {-1, -1, -1};
  int e[6] = {-1, -1, -1, -1, -1, -1};
  double mu = 0, restitution = 0;
  double mu_kinetic = 0;  ///< the cone's μ for a contact that slid at the last step
  double stiffness = 0, damping = 0;  ///< a compliant normal (ContactLaw); 0: rigid
  int rows() const { return 1 + nf + ne; }
};

/// The energy terms of one step (J), for the simulator's balance.
struct StepWork {
  double impact = 0;    ///< −Pₙ (u⁻ₙ + u⁺ₙ)/2 and the equality rows' part
  double friction = 0;  ///< −Pₜ·(u⁻ₜ + u⁺ₜ)/2
  double joint = 0;     ///< h τ·(v + v⁺)/2
  double support = 0;   ///< −Pᵀb − h λᵀb: rows that move in time
  /// The θ-method's own loss, V(q_½) − V(q⁺): the potential energy of the
  /// step's end against the trapezoidal position q_½ = q ⊕ h (v + v⁺)/2,
  /// which the work terms above are consistent with. (θ − ½) h Q_gᵀ Δv to
  /// first order — ½ m g² h² a step of a free fall at θ = 1, zero at θ = ½
  /// (Acary, "Energy conservation and dissipation properties of time-
  /// integration methods for nonsmooth elastodynamics with contact", ZAMM
  /// 96, 2016: the scheme dissipates for θ > ½).
  double scheme = 0;
};

class MoreauJean {
 public:
  /// `servos` are taken implicitly (implicit_servos.hpp); the joint forces
  /// given to step() exclude them.
  MoreauJean(const Model& model, const ConstraintList& constraints,
             std::vector<Actuator> servos, const TimeSteppingOptions& options, double gap_tol);

  /// One step from (t, q, v) over h: q, v become the end state (t + h is the
  /// caller's). `cdata`'s active flags are overwritten (the caller sets them
  /// from modes()). false with error() when a solve fails.
  /// Approaches slower than `rest_speed` are plastic (as in the event scheme).
  bool step(const Model& model, Data& data, const ConstraintList& constraints,
            ConstraintData& cdata, ConstrainedSolver& solver,
            const Simulator::JointForces& tau_fn, double t, VecX& q, VecX& v, double h,
            double rest_speed);

  const std::string& error() const { return error_; }
  /// Per constraint: what it did over the last step (Open for bilateral ones).
  const std::vector<Mode>& modes() const { return modes_; }
  /// Per constraint: whether its normal velocity after the step separates
  /// (a rebound): it is then not held by the drift projection.
  bool rebounds(int c) const { return rebound_[c] != 0; }
  const StepWork& work() const { return work_; }
  /// Multipliers of the step as forces (m): the impulses over h on the
  /// contact rows, the bilateral λ of the free solve on the others.
  const VecX& lambda() const { return lambda_; }
  const VecX& vdot() const { return vdot_; }
  int sweeps() const { return problem_.sweeps; }
  double residual() const { return problem_.residual; }
  bool converged() const { return problem_.converged && servos_settled_; }
  bool polished() const { return problem_.polished; }
  /// Copies the last step's contact problem (its blocks named by constraint)
  /// into `out` (allocates; not for the step loop).
  void record(ContactProblemData& out) const;
  /// Candidate contacts of the last step.
  int candidates() const { return static_cast<int>(active_.size()); }

 private:
  bool freeVelocity(const Model& model, Data& data, const ConstraintList& constraints,
                    ConstraintData& cdata, ConstrainedSolver& solver,
                    const Simulator::JointForces& tau_fn, double t, const VecX& q,
                    const VecX& v, double h);
  void selectCandidates(const ConstraintData& cdata, double h, double rest_speed);
  void addCompliance();
  bool solveContacts(const Model& model, Data& data, const ConstraintList& constraints,
                     ConstraintData& cdata, ConstrainedSolver& solver, double t_end, int n);
  void endVelocity(int n, VecX& v) const;
  bool gateServos(const Model& model, Data& data, const ConstraintList& constraints,
                  ConstraintData& cdata, ConstrainedSolver& solver, double t, const VecX& q,
                  const VecX& v);
  bool servosAlone(const Model& model, Data& data, const ConstraintList& constraints,
                   ConstraintData& cdata, ConstrainedSolver& solver, const VecX& q, const VecX& v);
  bool solveWithServos(const Model& model, Data& data, const ConstraintList& constraints,
                       ConstraintData& cdata, ConstrainedSolver& solver, int n);
  void finish(const ConstraintData& cdata, const VecX& v0, const VecX& v1, double h);
  void solveProblem();

  TimeSteppingOptions options_;
  double gap_tol_;
  std::vector<Candidate> all_;     ///< every unilateral constraint
  std::vector<int> active_;        ///< indices into all_ of this step's candidates
  std::vector<int> first_;         ///< per all_: first local row (−1: not a candidate)
  std::vector<Mode> modes_;
  std::vector<char> rebound_;
  std::vector<char> slid_;         ///< per all_: sliding at the step's start (μₖ)
  std::vector<char> restituted_;   ///< per all_: its normal target is Newton's restitution
  std::vector<double> warm_;       ///< per all_ (6 each): the last step's impulses
  std::vector<double> compliance_; ///< per all_: this step's 1/D of a compliant normal (0: rigid)
  std::vector<int> map_;           ///< per problem row: its row in the Delassus J
  int rows_ = 0;                   ///< rows of every candidate (J's layout)
  ContactProblem problem_;
  // The last failed active-set finish, carried from solve to solve over the
  // same blocks (solveProblem): its modes, the blocks' constraints, and the
  // solves since it was last tried.
  std::vector<signed char> carry_modes_;
  std::vector<int> carry_ids_, ids_;
  int carry_age_ = 0;
  ImplicitServos servos_;
  MatX W_all_;                     ///< the Delassus operator over problem and servo rows
  MatX Rs_, Wss_;                  ///< the servos' responses and their block, at the step's q
  VecX mobility_;                  ///< per servo: (M⁻¹)_dd under the bilateral rows, for the gate
  VecX u_servo_, vfree0_;          ///< servo rows' and v's free velocity without the servos
  bool servos_settled_ = true;     ///< the servos' limited set settled this step
  double theta_ = 1;               ///< this step's θ (selectCandidates)
  bool joint_forces_ = false;      ///< joint forces act (the caller's or servos): θ stays the options'
  Delassus delassus_;
  VecX uminus_, ufree_;            ///< every candidate row at v and at v_free
  VecX tau_, vfree_, vdot_, lambda_, impulse_, v0_, qnext_, qmid_;
  ConstrainedResult res_, res2_;
  StepWork work_;
  std::string error_;
};

}  // namespace appell::timestepping
