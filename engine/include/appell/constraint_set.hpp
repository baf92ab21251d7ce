// All declared constraints of a system, in two forms.
//
// Rows. Each constraint writes its block at (q, v, t) (constraint.hpp): world-
// frame spatial covectors on one or two bodies' spatial velocities,
//     wₐ·Vₐ − w_b·V_b + b = 0,      wₐ·aₐ − w_b·a_b + κ = 0,
// or, for jointSpace() constraints, rows over v. Evaluating the rows costs
// O(n) kinematics plus O(m); it is all the tree solver reads, and the
// velocity residual ‖A v + b‖∞ follows from the rows and the body velocities
// (Vₐ = ᵒXₐ Vₐ^body) without ever forming A.
//
// Dense form. The reference solvers (KKT, Appell/Maggi), equilibria and
// linearization read the Pfaffian form over the generalized velocities,
//     A(q, t) v + b(q, t) = 0,      A v̇ + abias = 0,   abias = Ȧ v + ḃ,
// assembled from the rows with the world-frame body Jacobians, V = J v:
//     A = Wₐ Jₐ − W_b J_b,      abias = κ + Wₐ J̇ₐv − W_b J̇_b v
// (J̇v is the body's spatial acceleration at v̇ = 0). That is O(m·nv) per
// evaluation, so it is a separate step, done only by those who need it.
#pragma once

#include <appell/constraint.hpp>

#include <memory>
#include <vector>

namespace appell {

using ConstraintList = std::vector<std::shared_ptr<const Constraint>>;

/// Whether a ConstraintData carries storage for the dense form (m × nv A).
enum class DenseRows { Sized, None };

struct ConstraintData {
  /// Sizes every buffer once; the dense part only with DenseRows::Sized.
  ConstraintData(const Model& model, const ConstraintList& constraints,
                 DenseRows dense = DenseRows::Sized);

  // Rows (evaluateConstraintRows).
  int m = 0;                       ///< total rows
  std::vector<int> offset;         ///< first row of each constraint
  std::vector<RowBlock> blocks;    ///< per constraint, as evaluated
  VecX b;                          ///< m, velocity offsets of the rows
  VecX gap;                        ///< m, holonomic gaps (0 for other rows)
  std::vector<char> holonomic;     ///< m, row is ġ of a gap
  std::vector<int> row_constraint; ///< m, owning constraint
  /// Per constraint: closed (1) or open (0). Every constraint is evaluated
  /// (an open contact still reports its gap and frame), but the rows of an
  /// open one are not constraints: solvers give them λ = 0, the dense form
  /// holds zero rows for them, projections and residuals skip them. Only
  /// unilateral constraints open (the simulator's active set, contact_events).
  std::vector<char> active;
  /// Set by a caller that needs only the closed rows (the dynamics at an
  /// integrator's stage): open constraints are not evaluated at all — a
  /// contact in flight costs nothing inside a step; its block keeps the gap
  /// and frame of its last evaluation (the simulator's step end, where
  /// touchdown is detected).
  bool closed_only = false;
  int m_active = 0;                ///< rows of the closed constraints (sliding: the normal row)
  bool isActive(int constraint) const { return active[constraint] != 0; }
  /// Opens or closes a constraint (keeps m_active); no allocation.
  void setActive(int constraint, bool closed);

  /// Per constraint: closed and sliding (docs/contacts.md §8). Only its
  /// unilateral (normal) row holds; its friction rows are kept in `slide`
  /// (directions and slip velocities) and zeroed in the block, like an open
  /// contact's; its other rows (spin) are dropped.
  std::vector<char> sliding;
  struct SlidingRows {
    int n = 0;                               ///< friction rows (tangent1/2, lateral)
    int row[3] = {-1, -1, -1};               ///< their indices in the constraint
    /// Row i's unit in the friction law: 1, or ℓ/μ for a spin row (its
    /// covectors, slip and κ below are scaled by it, its multiplier — the
    /// torque — divided by it: Constraint::spinFriction()).
    double scale[3] = {1, 1, 1};
    Eigen::Matrix<double, 3, 6> Wa = Eigen::Matrix<double, 3, 6>::Zero();  ///< covectors on body A
    Eigen::Matrix<double, 3, 6> Wb = Eigen::Matrix<double, 3, 6>::Zero();  ///< and on body B
    Vec3 slip = Vec3::Zero();                ///< row values: the slip velocity along each
    Vec3 kappa = Vec3::Zero();               ///< their κ: slip acceleration = Wa·aₐ − Wb·a_b + κ
  };
  std::vector<SlidingRows> slide;            ///< per constraint (n = 0: no friction rows)
  bool isSliding(int constraint) const { return sliding[constraint] != 0; }
  /// Per constraint: its friction is regularized (Constraint::creepSpeed > 0,
  /// a finite μ and friction rows): it has no sticking mode, so setActive
  /// closes it sliding.
  std::vector<char> regularized;
  /// Makes a closed constraint slide or stick (keeps m_active); no allocation.
  void setSliding(int constraint, bool slides);
  bool singular = false;           ///< some constraint reported singular geometry
  std::string singular_reason;     ///< "<constraint>: <reason>" of the first one

  // Dense form (assembleDenseRows), empty unless sized.
  bool has_dense = false;          ///< the dense storage below is sized
  MatX A;                          ///< m × nv
  VecX abias;                      ///< m, Ȧv + ḃ
  MatX J;                          ///< 6 × nv scratch (body Jacobian)
};

/// Evaluates every constraint's rows at (q, v, t): blocks, b, gaps, singular
/// flags. Leaves `data` holding forwardKinematics(q, v, 0) (data.a = J̇v).
void evaluateConstraintRows(const Model& model, Data& data, const ConstraintList& constraints,
                            ConstraintData& cdata, double t, const VecX& q, const VecX& v);

/// Assembles A and abias from the rows in `cdata`. `data` must hold
/// forwardKinematics(q, v, 0) at the rows' (q, v), as evaluateConstraintRows
/// leaves it. Throws std::logic_error when `cdata` has no dense storage.
void assembleDenseRows(const Model& model, const Data& data, const ConstraintList& constraints,
                       ConstraintData& cdata);

/// A and abias of one constraint's rows (rows × nv, rows), from its evaluated
/// block; `J` is 6 × nv scratch. `data` as for assembleDenseRows.
void assembleConstraintRows(const Model& model, const Data& data, const Constraint& constraint,
                            const RowBlock& block, MatX& J, Eigen::Ref<MatX> A,
                            Eigen::Ref<VecX> abias);

/// Rows and dense form together: evaluateConstraintRows, then assembleDenseRows.
void evaluateConstraints(const Model& model, Data& data, const ConstraintList& constraints,
                         ConstraintData& cdata, double t, const VecX& q, const VecX& v);

/// ‖A v + b‖∞ from the rows and the body velocities: `data` must hold
/// forwardKinematics(q, v) at the rows' q and this v (as evaluateConstraintRows
/// at (q, v) leaves it). O(m); A is not needed.
double velocityResidual(const Data& data, const ConstraintList& constraints,
                        const ConstraintData& cdata, const VecX& v);
/// Row by row, A v + b (size m; an open constraint's rows are its zero rows,
/// so their b): the same O(m) reading of the rows, `data` as above.
void velocityResiduals(const Data& data, const ConstraintList& constraints,
                       const ConstraintData& cdata, const VecX& v, VecX& residual);
/// The same at any v: recomputes forwardKinematics(q, v) into `data` first.
double velocityResidual(const Model& model, Data& data, const ConstraintList& constraints,
                        const ConstraintData& cdata, const VecX& q, const VecX& v);
/// Adds `delta` (size m) to the evaluated rows' velocity offsets b — in
/// cdata.b and in each closed constraint's block — so that a solve or a
/// projection over these rows sees A v + b + delta.
void shiftRowOffsets(const ConstraintList& constraints, ConstraintData& cdata, const VecX& delta);
/// max |gap| of the last evaluation.
double gapResidual(const ConstraintData& cdata);

}  // namespace appell
