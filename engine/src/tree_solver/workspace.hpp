// Private workspace of the tree solver (tree_solver.hpp): every per-body and
// per-row quantity of the passes, sized once by the constructor. All small
// matrices have compile-time maximum sizes, so the passes never allocate.
#pragma once

#include <appell/tree_solver.hpp>

#include "solvers/pivoted_qr.hpp"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <Eigen/SVD>

#include <algorithm>
#include <array>
#include <string>
#include <vector>

namespace appell::detail {

// Row stacks: at most 6 rows after compression, at most 12 while stacking
// (stacked in PivotedQR's own storage).
using KRows = Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor, 6, 6>;
using KVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;
using BufVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 12, 1>;
using SmallMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;
using StackMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 12, 12>;
/// Rows of a stack's triangularised least-squares system that fix its free
/// multipliers (tree_solver/min_norm.cpp): ≤ 12 × (≤ 12 unknowns + right side).
using AugMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 12, 13>;

/// A least-squares system ‖F [x; 1]‖ of at most 13 rows and 12 unknowns
/// (tree_solver/min_norm.cpp), column-major: col[k][r] = F(r, k).
struct LsSystem {
  int rows = 0, cols = 0;
  alignas(16) double col[13][13];  ///< 12 stacked rows, and a locked joint's force
};

/// A kept singular value of K S below this (rows equilibrated, S unit) is a
/// joint that can barely move its rows: the rows are not resolved there but
/// handed up with their compliance (tree_solver/soft.cpp).
constexpr double kWeakPivot = 5e-2;

/// One piece of a node's row stack: the output of the previous compression,
/// one constraint's own rows, or one child's unresolved rows.
struct Segment {
  enum Kind { Previous, Block, Child } kind = Previous;
  int id = -1;    ///< block index (into TreeWorkspace::blocks) or child body
  int rows = 0;
};

/// One rank-revealing compression  Qᵀ E [stacked rows] Π = [R₁; ≈0], K = R₁ Πᵀ.
/// The rows are stacked straight into the factorization's storage and
/// Q = H₀ H₁ ⋯ H_{rank−1} stays there as its Householder reflectors
/// (pivoted_qr.hpp); applying them costs O(nrows · rank) per vector where
/// forming Q costs O(nrows² · 6).
struct Compression {
  int nrows = 0;               ///< rows stacked
  int rank = 0;                ///< rows kept (= f.rank reflectors, or none: Q = 1)
  PivotedQR f;                 ///< R, reflectors, scalars τ and column pivots Π
  BufVec E;                    ///< row equilibration scales
  int nseg = 0;
  std::array<Segment, 13> seg;
  KVec rhs;                    ///< kept right sides (bias pass)
  KVec mu;                     ///< multipliers of the kept rows (forward pass)

  // Compliant rows (tree_solver/soft.cpp): a stacked segment carried a
  // compliance Φ = F Fᵀ (kept as its square-root factor F), so the dropped
  // combinations (K part ≈ 0) may still involve multipliers:
  // Φ_dk μ_k + Φ_dd μ_d = r_d,  F_d = U_d Σ_d W_dᵀ.
  bool soft = false;
  int nelim = 0;               ///< dropped directions with compliance (eliminated here)
  SmallMat F;                  ///< rank × rank factor of the kept rows' compliance
  StackMat Ud;                 ///< left singular vectors of F_d: eliminated, then redundant
  BufVec sInv;                 ///< 1/Σ_e of the eliminated directions
  StackMat FkWe;               ///< F_k W_e (rank × nelim)
  BufVec rd;                   ///< dropped right sides Q₂ᵀ E r of the last bias pass

  // Minimum-norm λ (tree_solver/min_norm.cpp): the dropped combinations with
  // no compliance are null vectors of Aᵀ, their multipliers t are free.
  int nfree = 0;               ///< free multipliers t (dropped rows, less the eliminated ones)
  AugMat mnTop;                ///< nfree rows fixing t from δμ: R_tt t + R_tμ δμ + r_t = 0
  SmallMat mnR;                ///< cost-to-go of the kept rows' δμ: ½‖R δμ + ρ‖²
  KVec mnRho;
  KVec dmu;                    ///< δμ of the replay
};

/// A constraint whose rows act on one body of the tree.
struct TreeBlock {
  int constraint = -1;         ///< index in the ConstraintList / ConstraintData
  int body = -1;
  double sign = 1;             ///< +1: rows Wₐ on bodyA; −1: rows −W_b on bodyB
  int rows = 0;                ///< rows in this solve: the declared ones, 0 while open
  int declared = 0;            ///< the constraint's rows
  int global = -1;             ///< first row in ConstraintData
  KVec rhs;                    ///< right side on the gravity-shifted acceleration
};

/// A joint-space row on the one velocity of a one-DoF joint, c q̇ + b = 0
/// (a joint limit). It is not a loop: while closed it locks its joint —
/// q̈ = ρ is fixed, the joint's motion subspace is empty for this solve, and
/// the row's force ℓ = Σ c λ is read off the joint's force balance
///     sᵀ(IA a + pA) = τ + (K s)ᵀ μ + ℓ.
/// Several closed rows on one joint are one row: ρ = Σ c r / Σ c², λ = c ℓ / Σ c²
/// (their minimum-norm split; the rest of their right sides must vanish).
struct JointRow {
  int constraint = -1;
  int row = -1;                ///< row within the constraint
  int global = -1;             ///< row in ConstraintData
  double c = 0;                ///< coefficient on q̇ (this solve)
  double rhs = 0;              ///< right side on q̈ (or on Δq̇ for the impulse)
  bool active = false;
};

/// A row closing a loop: two moving bodies, or given over v (joint space).
struct LoopRow {
  int constraint = -1;
  int row = -1;                ///< row within the constraint
  int global = -1;             ///< row in ConstraintData
  bool joint_space = false;
  int bodyA = -1, bodyB = -1;
};

/// x ← H_k x, H_k = 1 − τ v vᵀ with v = [0…0, 1, essential] (reflector k of
/// the compression's QR, Eigen's storage). Written out: Eigen's generic
/// applyHouseholderOnTheLeft costs several times more on these short vectors.
inline void applyReflector(const Compression& cp, int k, BufVec& x) {
  const double tau = cp.f.tau[k];
  const int pk = cp.f.perm[k];
  double t = x[k];
  for (int r = k + 1; r < cp.nrows; ++r) t += cp.f.a[r][pk] * x[r];
  t *= tau;
  x[k] -= t;
  for (int r = k + 1; r < cp.nrows; ++r) x[r] -= t * cp.f.a[r][pk];
}

/// x ← Qᵀ x (x has cp.nrows entries): H₀ first. A stack certified
/// independent has no reflector (Q = 1, cp.f.rank = 0).
inline void applyQt(const Compression& cp, BufVec& x) {
  for (int k = 0; k < cp.f.rank; ++k) applyReflector(cp, k, x);
}

/// x ← Q x (x has cp.nrows entries): the last reflector first.
inline void applyQ(const Compression& cp, BufVec& x) {
  for (int k = cp.f.rank - 1; k >= 0; --k) applyReflector(cp, k, x);
}

/// How U₂, the left null space of K S (rows handed to the parent), is held.
enum class U2Form {
  Identity,   ///< the joint resolves no row: U₂ = 1 (or nothing is left)
  Reflector,  ///< one-DoF joint: columns 1… of H = 1 − β u uᵀ
  Explicit,   ///< the SVD's columns, in U2
};

struct Node {
  // Ordered by use, not by pass: what every body touches in every solve
  // first and together (fewer cache lines per body), what only multi-DoF or
  // unresolved joints use last.
  int ncomp = 0;
  int nK = 0;                             ///< compressed rows at this body
  int rankG = 0;                          ///< rows the joint resolves
  int npass = 0, nf = 0;                  ///< rows handed up; free joint directions
  U2Form u2form = U2Form::Identity;
  double hbeta = 0;                       ///< reflector scalar β (U2Form::Reflector)
  Vec6 Hc;                                ///< H c, H = Pᵀ Ia P what the parent sees
  Vec6 bias0;                             ///< initial bias force (v ×* I v, or unit forces)
  Vec6 pA;                                ///< articulated bias before the joint
  Vec6 c;                                 ///< velocity-product acceleration v × S q̇
  Vec6 a;                                 ///< acceleration (gravity-shifted)
  // One-DoF joint with its row resolved (the common case), kept compact:
  KVec gp;                                ///< G⁺ᵀ = g/σ² (nK), g = K s
  Vec6 gk;                                ///< GKᵀ = Kᵀ G⁺ᵀ (not at the root)
  Vec6 ias;                               ///< IA s (not at the root)
  KVec hu;                                ///< reflector vector (U2Form::Reflector)
  KVec k;                                 ///< right sides of K
  KVec kpass;                             ///< right sides of the handed-up rows (on a_parent)
  KVec kpc;                               ///< Kpass c, their velocity-product part
  KVec nu;                                ///< multipliers of the handed-up rows

  // Factors (depend on q and the rows only).
  KRows K;                                ///< compressed rows, body frame
  KRows Kpass;                            ///< U2ᵀ K, this body's frame
  SmallMat Gpinv;                         ///< (K S)⁺ truncated at the rank, nv × nK (nv > 1)
  Eigen::Matrix<double, Eigen::Dynamic, 6, 0, 6, 6> GK;  ///< G⁺ K (nv × 6): P = 1 − S GK (nv > 1)
  Mat6X IaS;                              ///< Ia S, Ia = IA − U D⁻¹ Uᵀ (ρ > 0, nv > 1, not the root)
  Mat6 IA;                                ///< articulated inertia before the joint

  // Free directions and general splits.
  SmallMat U2;                            ///< nK × npass (U2Form::Explicit)
  SmallMat V2;                            ///< nv × nf, right null space of K S
  Mat6X S2, U;                            ///< S V2 and IA S V2
  SmallMat Dinv;                          ///< (S2ᵀ IA S2)⁻¹, or its lower Cholesky factor (dinv_factor)
  /// Dinv holds the Cholesky factor L of D (a root's general split: nothing
  /// passes to a parent, so D⁻¹ is only applied to the forward pass's one
  /// vector — two triangular solves instead of forming the inverse).
  bool dinv_factor = false;
  KVec u;                                 ///< V2ᵀ τ − S2ᵀ pA

  // Compliant elimination (tree_solver/soft.cpp): the joint is eliminated as
  // in ABA with the rows carried, K' a − Φ' λ = k'; directions of Φ' large
  // enough are resolved here, the rest handed up with their compliance.
  bool soft = false;
  bool softpass = false;                  ///< some handed-up row has compliance > 0
  KVec fpass;                             ///< √compliance of the handed-up rows (diagonal)
  SmallMat GD;                            ///< G D⁻¹ (nK × nv), G = K S
  SmallMat Vphi;                          ///< eigenvectors of Φ': handed up, then resolved
  KRows Kel;                              ///< resolved rows V₁ᵀ K'
  KVec lamInv;                            ///< 1/Λ₁
  KVec kv;                                ///< Vphiᵀ k' (bias pass)

  // Minimum-norm λ (tree_solver/min_norm.cpp).
  int nfree = 0;                          ///< free multipliers here (dropped rows, rows to the world)
  bool mn_active = false;                 ///< λ of this body's rows depends on free multipliers
  SmallMat mnR;                           ///< cost-to-go of the handed-up rows' δν: ½‖R δν + ρ‖²
  KVec mnRho;
  KVec dnu;                               ///< δν of the replay

  // Locked joint (JointRow): closed rows on this one-DoF joint's velocity.
  bool locked = false;
  double c2 = 0;                          ///< Σ c² of the closed rows
  double rho = 0;                         ///< q̈ they fix (bias pass)
  double ell = 0;                         ///< their force on q̈ (forward pass)
  KVec gl;                                ///< K s: how the rows of K see q̈
  KVec kps;                               ///< Kpass s
  Vec6 Hs;                                ///< H s: the parent's share of s ρ
  std::vector<JointRow> jrows;            ///< declared rows on this joint

  std::vector<Segment> groups;            ///< own blocks, then children
  std::vector<Compression> comp;          ///< sized groups.size() + 1
  Mat6 H;                                 ///< Pᵀ Ia P, what the parent sees (velocityCouplings)
};

/// y = U₂ᵀ x: right sides of the rows handed to the parent.
inline void applyU2t(const Node& nd, const KVec& x, KVec& y) {
  switch (nd.u2form) {
    case U2Form::Identity: y = x.head(nd.npass); break;
    case U2Form::Reflector: {
      const double t = nd.hbeta * nd.hu.dot(x);
      y = x.tail(nd.npass);
      y.noalias() -= t * nd.hu.tail(nd.npass);
      break;
    }
    case U2Form::Explicit: y.noalias() = nd.U2.transpose() * x; break;
  }
}

/// y += U₂ ν: multipliers of the handed-up rows back on K.
inline void addU2(const Node& nd, const KVec& nu, KVec& y) {
  switch (nd.u2form) {
    case U2Form::Identity: y.head(nd.npass) += nu; break;
    case U2Form::Reflector: {
      const double t = nd.hbeta * nd.hu.tail(nd.npass).dot(nu);
      y.tail(nd.npass) += nu;
      y.noalias() -= t * nd.hu;
      break;
    }
    case U2Form::Explicit: y.noalias() += nd.U2 * nu; break;
  }
}

struct Failure {
  bool failed = false;
  int node = -1;                          ///< body where rows turned out inconsistent
  int comp = -1;                          ///< compression index, −1: at the world
  double residual = 0;
};

/// What the passes' factor (factorPass) was formed from, by value: the
/// configuration (the kinematics are forwardKinematics(q)'s) and, after the
/// active set, each block's row count and covectors and each joint row's
/// state — then the loop rows' coefficients, on which the loop closure's
/// unit responses and their SVD depend as well. The model is the one the
/// solver was built for (immutable, as for the constructor's own
/// precomputations). Sized by the constructor.
struct FactorRecord {
  bool valid = false;
  VecX q;
  std::vector<double> rows, next;  ///< the record, and this call's (swapped in)
  int tree_length = 0;             ///< entries of the tree part (factorPass's inputs)
  int length = 0;                  ///< with the loop rows
  int redundant = 0;               ///< factorPass's redundancy count
};

struct TreeWorkspace {
  std::vector<int> unilateral_row;          ///< per constraint: Constraint::unilateralRow()
  SolverOptions options;
  int nbodies = 0, nv = 0, m = 0;
  std::vector<Node> nodes;
  std::vector<TreeBlock> blocks;
  std::vector<LoopRow> loops;
  std::vector<int> jrow_nodes;            ///< bodies with JointRows, ascending
  std::vector<std::string> names;         ///< constraint names, for messages
  bool free_body = false;                 ///< one body on a floating joint, no loop or joint rows (free_body.cpp)
  bool last_closed_form = false;          ///< the last solve took free_body.cpp's closed form
  Mat6 free_body_linv;                    ///< L⁻¹, I = L Lᵀ the free body's inertia (body frame)
  double free_body_lambda_min = 0;        ///< λ_min(I) = σ_min(L)²
  FactorRecord factor_record;             ///< factorPassIfChanged
  bool last_factor_reused = false;        ///< the last solve / projection skipped factorPass
  int certified_stacks = 0;               ///< stacks of the factor with no QR (backward.cpp, compress)
  bool loop_closure_valid = false;        ///< W, L, Z and its SVD are for the recorded rows (loops.cpp)

  // Solver scratch with compile-time maximum sizes.
  Eigen::JacobiSVD<SmallMat, Eigen::ColPivHouseholderQRPreconditioner> svd;

  // Right sides of one pass.
  VecX tau;                               ///< generalized force of the pass
  Vec6 a_world;                           ///< world acceleration (world frame)
  bool use_c = true;
  /// The forward pass unrolls the multipliers (ws.lambda). An integrator
  /// stage asks for v̇ only, which does not depend on them (forward.cpp) —
  /// unless a body hands rows up with their compliance: its accelerations
  /// read the multipliers its parent unrolls (soft.cpp, softForward).
  bool multipliers = true;
  bool any_soft = false;                  ///< a body of the factor is soft (factorPass)

  // Outputs of one pass.
  VecX vdot, lambda;
  int redundant = 0;
  int last_redundant = 0;                 ///< of the last solve / projection (redundantRows())
  Failure failure;
  /// Compliance factors (tree_solver/soft.cpp): F' of a joint, F_d, F_k of a stack.
  Eigen::JacobiSVD<StackMat, Eigen::ColPivHouseholderQRPreconditioner> svd12;

  // Loop closure: k unit solves and the square root of the Schur complement.
  MatX W;                                 ///< nv × k, response to each loop row's force
  MatX L;                                 ///< m × k, tree multipliers of each response
  MatX Z;                                 ///< 6n × k, [R_i a_i] per response: S = Zᵀ Z
  std::vector<Mat6> inertia_root;         ///< R_i with I_i = R_iᵀ R_i (body frame, constant)
  Eigen::JacobiSVD<MatX, Eigen::ColPivHouseholderQRPreconditioner> z_svd;
  VecX vdot0, lambda0, loop_target, loop_rhs, loop_res, loop_scale, loop_lambda, loop_tmp, loop_resid;
  VecX loop_share, loop_fnorm;             ///< free share and norm of each loop row's force
  std::vector<Vec6> a0;                   ///< body accelerations of the main pass
  std::vector<Vec6> fsub;                 ///< subtree constraint forces (world frame)
  std::vector<Vec6> floop;                ///< subtree loop-row force (body frame, freeShare)
  int loop_rank = 0;

  // Minimum-norm λ (tree_solver/min_norm.cpp): bodies with free multipliers
  // (recorded by the factor pass, leaves first), the bodies whose λ they move
  // (parents first), and the loop closure's null vectors of Aᵀ.
  std::vector<int> seeds, region;
  int nseeds = 0, nregion = 0;
  LsSystem mnF;                           ///< one stack's least-squares system
  MatX loop_null;                         ///< m × k

  std::string last_error;
};

/// Right sides of the rows stacked in compression e of body i, before
/// equilibration: the previous compression's kept rows, constraint blocks and
/// children's handed-up rows, in stacking order.
inline void gatherRhs(const TreeWorkspace& ws, int i, int e, BufVec& r) {
  const Node& nd = ws.nodes[i];
  const Compression& cp = nd.comp[e];
  r.resize(cp.nrows);
  double* out = r.data();
  for (int s = 0; s < cp.nseg; ++s) {
    const Segment& g = cp.seg[s];
    const double* in = g.kind == Segment::Previous ? nd.comp[e - 1].rhs.data()
                       : g.kind == Segment::Block  ? ws.blocks[g.id].rhs.data()
                                                   : ws.nodes[g.id].kpass.data();
    for (int k = 0; k < g.rows; ++k) *out++ = in[k];
  }
}

// Passes (tree_solver/backward.cpp, tree_solver/forward.cpp, tree_solver/loops.cpp).
void factorPass(const Model& model, const Data& data, const ConstraintData& cdata,
                TreeWorkspace& ws);
/// factorPass, unless ws already holds the factor of this q and these rows
/// (FactorRecord): a projection at a stage's pose, or the end-of-step solve
/// after it, reuses that stage's factor. The result is bit for bit the same.
/// `data` must hold the kinematics of q.
void factorPassIfChanged(const Model& model, const Data& data, const ConstraintData& cdata,
                         const VecX& q, TreeWorkspace& ws);
/// The velocity-product terms of the bias pass, H c and Kpass c, from the
/// factor and the nodes' c (velocityTerms): a dynamics solve needs them, a
/// projection (no velocity products) does not.
void velocityCouplings(const Model& model, TreeWorkspace& ws);
/// Right-side pass; with `check`, returns false (ws.failure) on inconsistent rows.
bool biasPass(const Model& model, const Data& data, TreeWorkspace& ws, bool check);
/// Accelerations and multipliers (ws.vdot, ws.lambda for tree rows); with
/// `check`, tests the rows handed to the world and returns false on a mismatch.
bool forwardPass(const Model& model, const Data& data, TreeWorkspace& ws, bool check);
/// Multipliers of the stacked rows of compressions `from` … 0 of `body`
/// (comp[from].mu set): λ_stack = E Q₁ μ, the adjoint of the compression,
/// written to the body's own rows in `lambda` and to its children's `nu`.
void unrollNode(TreeWorkspace& ws, int body, int from, VecX& lambda);
/// Aᵀλ in O(n + m): row forces summed as world spatial forces over each
/// subtree, projected on each joint's motion subspace.
void reactionForces(const Model& model, const Data& data, const ConstraintData& cdata,
                    TreeWorkspace& ws, const VecX& lambda, VecX& reaction);
/// Solves the loop rows (right sides ws.loop_target) on top of the main pass
/// (ws.vdot, ws.lambda, body accelerations). Returns false (ws.failure,
/// ws.last_error) when inconsistent.
bool solveLoops(const Model& model, const Data& data, const ConstraintData& cdata,
                TreeWorkspace& ws);
/// Right sides of the loop rows (ws.loop_target) for the dynamics or, with
/// `impulse`, the velocity projection.
void loopTargets(const Model& model, const Data& data, const ConstraintData& cdata,
                 TreeWorkspace& ws, const VecX& v, bool impulse);

// Locked joints (tree_solver/locked.cpp).
/// A joint with no free direction, for splitSoft/softBias/softForward of a
/// locked node.
const Joint& lockedJoint();
/// Factor pass of a locked node (after its rows are compressed): all rows go
/// up (hard) or as splitSoft decides (compliant); H for the parent.
void splitLocked(TreeWorkspace& ws, const Joint& j, bool root, Node& nd, Mat6& H);
/// ρ of a locked node's closed rows; false (ws.failure, ws.last_error) when
/// their right sides disagree.
bool lockedRhs(TreeWorkspace& ws, int body, bool check);
/// ℓ of a locked node, from its joint's force balance (mu: the last
/// compression's multipliers, on K), written as λ of its rows into `lambda`.
void lockedForce(const Joint& j, Node& nd, double tau, VecX& lambda);
/// Certificate share of a locked node's rows: ℓ = −(K s)ᵀ μ.
void lockedCertificate(Node& nd, VecX& cert);

// Compliant rows (tree_solver/soft.cpp).
/// After compress(): the stack's compliance factor carried through Q, the
/// dropped combinations with compliance eliminated. Returns the truly
/// redundant count.
int softCompress(TreeWorkspace& ws, int body, int e);
/// Whether a segment of a stack carries compliance.
bool softSegment(const TreeWorkspace& ws, const Node& nd, int e, const Segment& g);
/// Joint split with rows carried (ABA elimination, then Φ' split); H for the parent.
void splitSoft(TreeWorkspace& ws, const Joint& j, bool root, Node& nd, Mat6& H);
/// Right sides through a compliant compression; false if the redundant part
/// is inconsistent (residual in `res`).
bool softCompressionRhs(Compression& cp, const BufVec& t, double tol, double& res);
/// Multipliers of a compliant compression's dropped rows, into lam[rank…];
/// `homogeneous`: with zero right sides (their change when lam[0…rank) changes).
void softDroppedMultipliers(const Compression& cp, BufVec& lam, bool homogeneous = false);
/// Bias pass of a compliant node: its gradient contribution g for the parent
/// (without H c) and its handed-up right sides.
void softBias(const Joint& j, Node& nd, const VecX& tau, Vec6& pa);
/// Forward pass of a compliant node: q̈, a, and the multipliers of its rows.
void softForward(const Joint& j, Node& nd, const Vec6& abar, VecX& vdot);
/// λ ← the minimum-norm solution of Aᵀλ = Aᵀλ_given (tree_solver/min_norm.cpp):
/// λ minus its projection on null(Aᵀ), spanned by the free multipliers of the
/// tree rows and the loop closure's redundant directions. Nothing to do when
/// no row is redundant.
void minimumNorm(const Model& model, TreeWorkspace& ws, VecX& lambda);

/// The one-free-body solve in closed form (tree_solver/free_body.cpp):
/// v̇ (or the velocity change, `impulse`) into ws.vdot and λ into ws.lambda,
/// from the blocks' right sides, ws.tau and ws.a_world. False, having
/// changed nothing the passes read, when the rows are not resolved whole
/// (redundant, weak, zero or more than 6 rows): then the passes solve.
bool freeBodySolve(const Model& model, const Data& data, const ConstraintData& cdata,
                   TreeWorkspace& ws, bool impulse);
/// "…" message naming the constraints involved in the inconsistency of ws.failure.
std::string describeFailure(const Model& model, const Data& data, TreeWorkspace& ws);

}  // namespace appell::detail
