// Tree solver: set-up, and the two solves (dynamics, velocity projection)
// built from the passes in tree_solver/{backward,forward,multipliers,loops}.cpp.
#include <appell/kinematics.hpp>
#include <appell/tree_solver.hpp>

#include "tree_solver/workspace.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace appell {

using detail::Segment;

namespace {

/// Where constraint c's rows go: a joint limit on a one-DoF joint to that
/// joint's node (tree_solver/locked.cpp), a row between two bodies or in
/// joint space to the loops, a row on one body to that body's stack.
void placeConstraintRows(const Model& model, const Constraint& con, int c, int global,
                         detail::TreeWorkspace& ws) {
  const int rows = con.rows();
  const int A = con.bodyA(), B = con.bodyB();
  auto fail = [&](const std::string& why) {
    throw std::invalid_argument("TreeSolver: constraint '" + con.name() + "' " + why);
  };
  if (rows < 0) fail("has a negative row count");
  if (!con.jointSpace()) {
    if (A >= model.nbodies || B >= model.nbodies)
      fail("acts on a body index outside the model (" + std::to_string(model.nbodies) + " bodies)");
    if (A < 0 && B < 0) fail("acts on no moving body (both bodies are the world)");
    if (rows > 6) fail("writes " + std::to_string(rows) + " body rows (at most 6)");
  }
  int own_joint = -1;
  if (con.jointSpace()) {
    const std::vector<int> cols = con.jointColumns(model);
    if (cols.size() == 1 && cols[0] >= 0 && cols[0] < model.nv) {
      const int b = model.body_of_v[cols[0]];
      if (model.joints[b].nv == 1) own_joint = b;
    }
  }
  if (own_joint >= 0) {
    auto& jr = ws.nodes[own_joint].jrows;
    if (jr.empty()) ws.jrow_nodes.push_back(own_joint);
    for (int r = 0; r < rows; ++r) {
      detail::JointRow row;
      row.constraint = c;
      row.row = r;
      row.global = global + r;
      jr.push_back(row);
    }
  } else if (con.jointSpace() || (A >= 0 && B >= 0)) {
    for (int r = 0; r < rows; ++r) ws.loops.push_back({c, r, global + r, con.jointSpace(), A, B});
  } else if (rows > 0) {
    detail::TreeBlock tb;
    tb.constraint = c;
    tb.body = A >= 0 ? A : B;
    tb.sign = A >= 0 ? 1.0 : -1.0;
    tb.rows = rows;
    tb.declared = rows;
    tb.global = global;
    tb.rhs.setZero(rows);
    ws.nodes[tb.body].groups.push_back({Segment::Block, static_cast<int>(ws.blocks.size()), rows});
    ws.blocks.push_back(tb);
  }
}

/// The factor's record (workspace.hpp, FactorRecord) at its largest.
void sizeFactorRecord(const Model& model, detail::TreeWorkspace& ws) {
  int length = 0;
  for (const auto& tb : ws.blocks) length += 1 + 6 * tb.declared;
  for (int b : ws.jrow_nodes) length += 2 * static_cast<int>(ws.nodes[b].jrows.size());
  for (const auto& lr : ws.loops) length += lr.joint_space ? 1 + model.nv : 12;
  ws.factor_record.rows.assign(length, 0.0);
  ws.factor_record.next.assign(length, 0.0);
  ws.factor_record.q = VecX::Zero(model.nq);
}

/// One free body (tree_solver/free_body.cpp) with a positive definite
/// inertia: L⁻¹ of its constant factor I = L Lᵀ, formed once.
void setUpFreeBody(const Model& model, const SolverOptions& options, detail::TreeWorkspace& ws) {
  ws.free_body = options.free_body_closed_form && model.nbodies == 1 &&
                 model.joints[0].type == JointType::Floating && ws.loops.empty() &&
                 ws.jrow_nodes.empty() && model.spatial_inertia_factor[0](0, 0) > 0;
  if (!ws.free_body) return;
  ws.free_body_linv =
      model.spatial_inertia_factor[0].triangularView<Eigen::Lower>().solve(Mat6::Identity());
  // λ_min(I) = σ_min(L)²: the closed form's acceptance bound (free_body.cpp).
  const Mat6& L = model.spatial_inertia_factor[0];
  const Mat6 I = L * L.transpose();
  ws.free_body_lambda_min = std::max(0.0, Eigen::SelfAdjointEigenSolver<Mat6>(I).eigenvalues()[0]);
}

/// The loop closure's workspace (tree_solver/loops.cpp), for k loop rows.
void sizeLoopWorkspace(const Model& model, int k, detail::TreeWorkspace& ws) {
  ws.W = MatX::Zero(model.nv, k);
  ws.L = MatX::Zero(ws.m, k);
  ws.Z = MatX::Zero(6 * model.nbodies, k);
  ws.z_svd = decltype(ws.z_svd)(6 * model.nbodies, k, Eigen::ComputeThinV);
  // R_i = Λ^½ Vᵀ from I_i = V Λ Vᵀ: also for a body whose inertia is only
  // semidefinite (a massless frame, a point mass).
  ws.inertia_root.resize(model.nbodies);
  for (int i = 0; i < model.nbodies; ++i) {
    const Eigen::SelfAdjointEigenSolver<Mat6> es(model.spatial_inertia[i]);
    ws.inertia_root[i] =
        es.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal() * es.eigenvectors().transpose();
  }
  ws.loop_null = MatX::Zero(ws.m, k);
  ws.vdot0 = VecX::Zero(model.nv);
  ws.lambda0 = VecX::Zero(ws.m);
  for (VecX* x : {&ws.loop_target, &ws.loop_rhs, &ws.loop_res, &ws.loop_scale, &ws.loop_lambda,
                  &ws.loop_tmp, &ws.loop_resid, &ws.loop_share, &ws.loop_fnorm})
    *x = VecX::Zero(k);
}

}  // namespace

TreeSolver::TreeSolver(const Model& model, const ConstraintList& constraints,
                       const SolverOptions& options)
    : ws_(std::make_unique<detail::TreeWorkspace>()) {
  auto& ws = *ws_;
  ws.options = options;
  ws.nbodies = model.nbodies;
  ws.nv = model.nv;
  ws.nodes.resize(model.nbodies);
  int global = 0;
  for (size_t c = 0; c < constraints.size(); ++c) {
    const Constraint& con = *constraints[c];
    ws.names.push_back(con.name());
    ws.unilateral_row.push_back(con.unilateralRow());
    placeConstraintRows(model, con, static_cast<int>(c), global, ws);
    global += con.rows();
  }
  ws.m = global;
  sizeFactorRecord(model, ws);
  std::sort(ws.jrow_nodes.begin(), ws.jrow_nodes.end());
  setUpFreeBody(model, options, ws);
  for (int i = 0; i < model.nbodies; ++i)
    for (int ch : model.children[i]) ws.nodes[i].groups.push_back({Segment::Child, ch, 0});
  for (auto& nd : ws.nodes) {
    // A stack is compressed when the next group would overflow it (never
    // before the first group) and once at the end: at most one compression
    // per group, and one slot for a body with none.
    nd.comp.resize(std::max<size_t>(1, nd.groups.size()));
    nd.K.resize(0, 6);
    nd.k.resize(0);
    nd.nu.resize(0);
    nd.bias0.setZero();
    nd.c.setZero();
    nd.a.setZero();
  }
  ws.tau = VecX::Zero(model.nv);
  ws.a_world.setZero();
  ws.vdot = VecX::Zero(model.nv);
  ws.lambda = VecX::Zero(ws.m);
  ws.seeds.assign(model.nbodies, -1);
  ws.region.assign(model.nbodies, -1);
  ws.fsub.assign(model.nbodies, Vec6::Zero());
  ws.floop.assign(model.nbodies, Vec6::Zero());
  ws.a0.assign(model.nbodies, Vec6::Zero());
  if (!ws.loops.empty()) sizeLoopWorkspace(model, static_cast<int>(ws.loops.size()), ws);
}

TreeSolver::~TreeSolver() = default;

int TreeSolver::loopRows() const { return static_cast<int>(ws_->loops.size()); }
int TreeSolver::redundantRows() const { return ws_->last_redundant; }
bool TreeSolver::lastSolveClosedForm() const { return ws_->last_closed_form; }
bool TreeSolver::lastFactorReused() const { return ws_->last_factor_reused; }
int TreeSolver::certifiedStacks() const { return ws_->certified_stacks; }
void TreeSolver::forgetFactor() {
  ws_->factor_record.valid = false;
  ws_->loop_closure_valid = false;
}
const std::string& TreeSolver::lastError() const { return ws_->last_error; }

namespace {

void checkSizes(const Model& model, const ConstraintData& cdata, const detail::TreeWorkspace& ws) {
  if (model.nbodies != ws.nbodies || model.nv != ws.nv || cdata.m != ws.m)
    throw std::invalid_argument(
        "TreeSolver: the model or constraint set differs from the one the solver was built for");
}

/// The active set of this solve: an open constraint's block writes no rows
/// (its λ stays 0); an open loop row is a zero row of the Schur complement.
/// A sliding constraint keeps its block, whose friction rows are zero rows
/// (dropped by the compression, λ = 0). Zero rows are not redundancy:
/// returns how many the loops hold and sets `zero_block_rows`.
int applyActiveSet(const ConstraintData& cdata, detail::TreeWorkspace& ws, int& zero_block_rows) {
  zero_block_rows = 0;
  for (auto& tb : ws.blocks) {
    tb.rows = cdata.isActive(tb.constraint) ? tb.declared : 0;
    if (tb.rows > 0 && cdata.isSliding(tb.constraint)) zero_block_rows += tb.rows - 1;
  }
  int open = 0;
  for (const auto& lr : ws.loops) {
    const bool zero = !cdata.isActive(lr.constraint) ||
                      (cdata.isSliding(lr.constraint) &&
                       lr.row != ws.unilateral_row[lr.constraint]);
    open += zero ? 1 : 0;
  }
  return open;
}

/// Velocity products and bias forces of the current state (ABA's first pass).
void velocityTerms(const Model& model, const Data& data, const VecX& v, detail::TreeWorkspace& ws) {
  for (int i = 0; i < model.nbodies; ++i) {
    const Joint& j = model.joints[i];
    auto& nd = ws.nodes[i];
    nd.c = crossMotion(data.v[i], j.S * v.segment(j.idx_v, j.nv));
    nd.bias0 = crossForce(data.v[i], model.spatial_inertia[i] * data.v[i]);
  }
}

/// The outputs of a dynamics solve from the workspace: v̇, the rank, and
/// (unless only v̇ is asked for) the minimum-norm λ and the reaction Aᵀλ.
void finish(const Model& model, const Data& data, const ConstraintData& cdata,
            detail::TreeWorkspace& ws, int zero_rows, ConstrainedResult& out,
            SolveOutputs outputs) {
  out.vdot = ws.vdot;
  out.redundant = ws.redundant - zero_rows;
  ws.last_redundant = out.redundant;
  out.rank = cdata.m_active - out.redundant;
  if (outputs == SolveOutputs::Accelerations) return;  // an integrator stage: v̇ is all it reads
  if (ws.redundant > 0) detail::minimumNorm(model, ws, ws.lambda);  // zero rows too: their λ = 0
  out.lambda = ws.lambda;
  detail::reactionForces(model, data, cdata, ws, ws.lambda, out.reaction);
}

}  // namespace

void TreeSolver::solve(const Model& model, Data& data, const ConstraintList& constraints,
                       ConstraintData& cdata, const VecX& q, const VecX& v, const VecX& tau,
                       ConstrainedResult& out,
                       SolveOutputs outputs) {
  (void)constraints;
  auto& ws = *ws_;
  checkSizes(model, cdata, ws);
  int zero_rows = 0;
  const int open_loops = applyActiveSet(cdata, ws, zero_rows);
  if (out.vdot.size() != model.nv) out.vdot.resize(model.nv);
  if (out.lambda.size() != ws.m) out.lambda.resize(ws.m);
  if (out.reaction.size() != model.nv) out.reaction.resize(model.nv);
  out.ok = true;
  out.error.clear();
  ws.last_error.clear();
  ws.last_closed_form = false;
  ws.last_factor_reused = false;
  if (cdata.singular) {
    out.ok = false;
    out.error = "singular constraint geometry: " + cdata.singular_reason;
    ws.last_error = out.error;
    return;
  }

  forwardKinematicsIfStale(model, data, q, v);  // done once with the rows
  // Right sides on the gravity-shifted accelerations a' = a − g (ABA's trick):
  // w·a + κ = 0  ⇔  w·a' = −κ − w_lin·g.
  for (auto& tb : ws.blocks) {
    const RowBlock& blk = cdata.blocks[tb.constraint];
    const RowMatrix6& W = tb.sign > 0 ? blk.Wa : blk.Wb;
    for (int r = 0; r < tb.rows; ++r)
      tb.rhs[r] = -blk.kappa[r] - tb.sign * W.row(r).tail<3>().dot(model.gravity);
  }
  for (int b : ws.jrow_nodes)  // c q̈ + (Ȧv + ḃ) = 0; gravity does not enter
    for (auto& jr : ws.nodes[b].jrows) jr.rhs = -cdata.blocks[jr.constraint].abias_joint[jr.row];
  ws.tau = tau;
  ws.a_world = spatial(Vec3::Zero(), -model.gravity);
  ws.last_closed_form = ws.free_body && detail::freeBodySolve(model, data, cdata, ws, false);
  if (ws.last_closed_form) {
    finish(model, data, cdata, ws, zero_rows, out, outputs);
    return;
  }
  velocityTerms(model, data, v, ws);
  detail::factorPassIfChanged(model, data, cdata, q, ws);
  detail::velocityCouplings(model, ws);
  ws.use_c = true;
  ws.multipliers = outputs != SolveOutputs::Accelerations || ws.any_soft;
  ws.lambda.setZero();
  detail::loopTargets(model, data, cdata, ws, v, false);
  if (!detail::biasPass(model, data, ws, true) || !detail::forwardPass(model, data, ws, true) ||
      !detail::solveLoops(model, data, cdata, ws)) {
    out.ok = false;
    out.error = detail::describeFailure(model, data, ws);
    ws.last_error = out.error;
    return;
  }
  ws.redundant += static_cast<int>(ws.loops.size()) - open_loops - ws.loop_rank;
  finish(model, data, cdata, ws, zero_rows, out, outputs);
}

bool TreeSolver::projectVelocity(const Model& model, Data& data, const ConstraintList& constraints,
                                 ConstraintData& cdata, const VecX& q, VecX& v, VecX& impulse) {
  (void)constraints;
  auto& ws = *ws_;
  checkSizes(model, cdata, ws);
  int zero_rows = 0;
  const int open_loops = applyActiveSet(cdata, ws, zero_rows);
  ws.last_error.clear();
  ws.last_closed_form = false;
  ws.last_factor_reused = false;
  if (cdata.singular) {
    ws.last_error = "singular constraint geometry: " + cdata.singular_reason;
    return false;
  }
  if (impulse.size() != ws.m) impulse.resize(ws.m);

  // min ½‖Δ‖²_M  s.t.  A Δ = −(A v + b): the dynamics problem with no forces,
  // no velocity products, no gravity, and the velocity residual as right side.
  forwardKinematicsIfStale(model, data, q, v);
  for (auto& tb : ws.blocks) {
    const RowBlock& blk = cdata.blocks[tb.constraint];
    const RowMatrix6& W = tb.sign > 0 ? blk.Wa : blk.Wb;
    const Vec6 V = data.oMi[tb.body].act(data.v[tb.body]);
    for (int r = 0; r < tb.rows; ++r) tb.rhs[r] = -(tb.sign * W.row(r).dot(V) + blk.b[r]);
  }
  for (int b : ws.jrow_nodes)
    for (auto& jr : ws.nodes[b].jrows) {
      const RowBlock& blk = cdata.blocks[jr.constraint];
      jr.rhs = -(jointRowDot(blk, jr.row, v) + blk.b_joint[jr.row]);
    }
  ws.tau.setZero();
  ws.a_world.setZero();
  ws.last_closed_form = ws.free_body && detail::freeBodySolve(model, data, cdata, ws, true);
  if (!ws.last_closed_form) {
    detail::factorPassIfChanged(model, data, cdata, q, ws);
    for (auto& nd : ws.nodes) nd.bias0.setZero();
    ws.use_c = false;
    ws.multipliers = true;  // μ is the impulse
    ws.lambda.setZero();
    detail::loopTargets(model, data, cdata, ws, v, true);
    if (!detail::biasPass(model, data, ws, true) || !detail::forwardPass(model, data, ws, true) ||
        !detail::solveLoops(model, data, cdata, ws)) {
      ws.last_error = detail::describeFailure(model, data, ws);
      return false;
    }
    ws.redundant += static_cast<int>(ws.loops.size()) - open_loops - ws.loop_rank;
  }
  ws.last_redundant = ws.redundant - zero_rows;
  if (ws.redundant > 0) detail::minimumNorm(model, ws, ws.lambda);
  v += ws.vdot;
  impulse = -ws.lambda;  // the shared convention: v⁺ = v − M⁻¹Aᵀμ
  return true;
}

std::unique_ptr<ConstrainedSolver> makeTreeSolver(const Model& model,
                                                  const ConstraintList& constraints,
                                                  const SolverOptions& options) {
  return std::make_unique<TreeSolver>(model, constraints, options);
}

}  // namespace appell
