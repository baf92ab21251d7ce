// The unilateral stages' workspace, shared by the simulator's stage files:
// each unilateral constraint's state (UnilateralRow, split into the states
// it mixes), the kinds of crossing an event function can have, a located
// event, and the buffers sized once at construction (UnilateralState).
#pragma once

#include <appell/configuration.hpp>
#include <appell/simulator.hpp>

#include "simulator/friction_problem.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include <algorithm>
#include <limits>
#include <span>
#include <sstream>
#include <string>
#include <vector>

namespace appell {

namespace detail {

/// A sliding contact is a candidate for its settled direction when its slip
/// is at most this fraction of the state's largest speed (a screen only: the
/// settling time decides, friction_settled.cpp).
inline constexpr double kSettleScreen = 1e-2;

/// A unilateral row's geometry: where its row is, and a copy of that row as
/// evaluated with the contact closed (an open contact's block holds zero
/// rows), to measure its normal velocity and acceleration while it is open
/// (contact_modes.cpp: saveCandidateRows, rowVelocity, rowAcceleration).
struct RowGeometry {
  int c = -1, row = -1, global = -1;
  bool joint = false;
  int a = -1, b = -1;
  Vec6 wa = Vec6::Zero(), wb = Vec6::Zero();
  double bval = 0, kappa = 0, abias = 0;
  VecX a_joint;            // joint-space row over cols (RowBlock::joint_cols)
  std::vector<int> cols;
  double gap = 0;          // at the decision's state
};

/// A unilateral row's state in a mode decision (impact.cpp, contact_modes.cpp).
struct ImpactState {
  double gamma = 0;       // normal velocity before the impact
  double target = 0;      // e γ⁻: the impact shifts the row to γ⁺ = −e γ⁻
  double impulse = 0, tangential = 0;
  bool touching = false, in_set = false, was_closed = false, lifting = false, touching_down = false;
  bool bounced = false;   // rebounded at this event: open, not a force candidate
  bool separated = false; // left the impact's set: its friction impulses would pull it
  // An impact's friction solution (friction_impact.cpp), kept per row until
  // every island's is found: friction impulse, slip after, normal impulse.
  Vec3 friction_impulse = Vec3::Zero(), slip_after = Vec3::Zero();
  double load_after = 0;
};

/// A unilateral row's Coulomb friction (friction.cpp and the friction_*
/// stages): μ, and while sliding the slip direction in the friction rows'
/// coordinates (unit; kept when the slip is ~0).
struct FrictionState {
  double mu = std::numeric_limits<double>::infinity();  // static: the sticking cone
  double mu_k = std::numeric_limits<double>::infinity();  // kinetic: the sliding force
  int nf = 0;             // friction rows (0: frictionless or bilateral)
  // Regularized friction (ContactLaw::creep_speed): > 0, the contact slides
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
};

/// Sliding on its settled direction (friction_settled.cpp): its friction
/// force is an unknown of this solve, `settle_force` its first index.
struct SettlingState {
  bool settling = false;
  int settle_force = 0;
  Vec3 settled = Vec3::Zero();  // its force, kept until the last solve reports it
};

/// A contact's piece of a piecewise support and its pair (contact_features.cpp).
struct FeatureState {
  // The piece a closed contact's rows use between events
  // (TerrainPiece::latched), the nearest piece at the step's start, and
  // the nearest one at the state last searched.
  int feature = -1, feature_start = -1, feature_free = -1;
  // Points of one pair (ContactLaw::group): the other points' rows, this
  // one's slot, and whether it idles — open while a point of lower slot is
  // open too, which is the one watching for the next touchdown.
  std::vector<int> siblings;
  int slot = 0;
  bool dormant = false;
};

/// Per unilateral constraint, the states its stages keep: each stage reads
/// and writes its own part (a function that needs only one takes it alone).
struct UnilateralRow : RowGeometry, ImpactState, FrictionState, SettlingState, FeatureState {};

/// A settling candidate's W block, eigen-decomposed (friction_settled.cpp):
/// its m (= its friction rows) eigenvalues, ascending and clamped at 0, and
/// their eigenvectors in E's first m columns.
struct SettleFactor {
  Vec3 lam = Vec3::Zero();
  Mat3 E = Mat3::Zero();
  int m = 0;
};
SettleFactor settleFactor(const Mat3& H, int n);

/// What a unilateral constraint's crossing is (the event function located).
enum class Crossing { None, Gap, Normal, Cone, Slip, Feature };

/// A located event: the row whose function crossed first, which function,
/// whether a change of piece is among the events, and its time after the
/// step's start (event_location.cpp).
struct LocatedEvent {
  int k = -1;
  Crossing type = Crossing::None;
  bool feature = false;
  double hi = 0;
};

/// The unilateral rows grouped by the bodies their forces can move
/// (islands.cpp): island i's rows are rows[start[i] .. start[i + 1]), in
/// their order; each friction problem is solved island by island, on
/// storage sized for the largest island.
struct Islands {
  std::vector<int> start, rows, of_row;
  int max_friction_contacts = 0, max_friction_rows = 0;
  int count() const { return static_cast<int>(start.size()) - 1; }
};

Islands findIslands(const Model& model, const ConstraintList& constraints,
                    const ConstraintData& cd, const std::vector<UnilateralRow>& rows);

/// A problem's candidates island by island: `list` gets the rows `pick`
/// selects (pick sees every row once, island by island), `runs` the start of
/// each island that has some (runs.back() == list.size()). Capacities
/// reserved at construction: no allocation.
template <class Pick>
void gatherByIsland(const Islands& is, std::vector<int>& list, std::vector<int>& runs, Pick&& pick) {
  list.clear();
  runs.clear();
  runs.push_back(0);
  for (int i = 0; i < is.count(); ++i) {
    for (int j = is.start[i]; j < is.start[i + 1]; ++j)
      if (pick(is.rows[j])) list.push_back(is.rows[j]);
    if (static_cast<int>(list.size()) > runs.back()) runs.push_back(static_cast<int>(list.size()));
  }
}

/// Run i of a gathered list.
inline std::span<const int> runOf(const std::vector<int>& list, const std::vector<int>& runs, int i) {
  return std::span<const int>(list.data() + runs[i], runs[i + 1] - runs[i]);
}

/// Numbers one run's friction unknowns from 0 (each row's first at r.*first);
/// returns their count.
inline int numberUnknowns(std::vector<UnilateralRow>& rows, std::span<const int> run,
                          int UnilateralRow::*first) {
  int F = 0;
  for (int k : run) {
    rows[k].*first = F;
    F += rows[k].nf;
  }
  return F;
}

struct UnilateralState {
  std::vector<UnilateralRow> rows;
  Islands islands;
  VecX q0, v0, vplus, vminus, vdot, impulse;
  double t0 = 0;
  ConstrainedResult res;
  int zero_events = 0;    // consecutive events at the very start of a step
  // Sliding friction by superposition (friction.cpp), sized for every
  // contact with friction rows and finite μ.
  std::vector<int> sliding, sliding_runs;  // rows sliding in this solve, island by island
  MatX G, J, R;               // nv × k friction forces per unit normal load; 6 × nv; k × k (one island)
  VecX lam0, s, tau_f, tau_unit;
  double friction_power = 0;  // −vᵀ Σ sⱼ Gⱼ of the last solve: the power friction takes
  ConstrainedResult unit;
  Eigen::PartialPivLU<MatX> lu;
  // The onset problem (friction_onset.cpp), sized for every friction row:
  // candidates, their generalized forces per unit row force (nv × F), the
  // slip accelerations' and normal loads' responses W (F × F), N (K × F),
  // the free terms, the forces and the modes before.
  std::vector<int> onset, onset_runs;
  FrictionProblem onset_problem;
  std::vector<char> was_sliding;
  // Sliding contacts on their settled directions (friction_settled.cpp): the
  // same unknowns, their own storage (an onset's solves may need it).
  std::vector<int> settle, settle_runs;
  VecX settle_tau;            // τ with every island's settled forces
  bool settle_off = false;    // this solve slides every contact along its slip
  FrictionProblem settle_problem;
  VecX swmax;                 // per candidate: the largest eigenvalue of its W block
  std::vector<SettleFactor> settle_factor;  // per candidate: its W block's eigenpairs,
  std::vector<char> settle_factored;        // once it needs them (friction_settled.cpp)
  VecX vstick;                // an impact's post-impact velocity with every contact sticking
  VecX vsum;                  // an impact's v⁰ + Σ V P over the islands (friction_impact.cpp)
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


/// A pivoting's two-cycle: contact `flip` was flipped straight back — in the
/// set its multiplier pulls, out of it it moves into its support. The set
/// around it is wrong (a rigid body on more contacts than its surface
/// allows: a car on uneven ground): keep it and unload the other set
/// members in turn, from `next_unload`. False when none is left.
/// (contact_modes.cpp; the impact and force stages both pivot.)
bool breakTwoCycle(std::vector<UnilateralRow>& rows, int flip, int& last_flip, int& next_unload);

}  // namespace detail

}  // namespace appell
