#include <appell/dynamics.hpp>
#include <appell/kinematics.hpp>
#include <appell/kkt.hpp>

#include "solvers/row_basis.hpp"

#include <stdexcept>

namespace appell {

namespace detail {

int totalRows(const ConstraintList& constraints) {
  int m = 0;
  for (const auto& c : constraints) {
    if (!c) throw std::invalid_argument("constraint list holds a null constraint");
    m += c->rows();
  }
  return m;
}

void checkSizes(const char* who, const Model& model, int m, const ConstraintData& cdata,
                const VecX& q, const VecX& v, const VecX* tau) {
  auto fail = [&](const std::string& what) {
    throw std::invalid_argument(std::string(who) + ": " + what);
  };
  if (cdata.m != m)
    fail("constraint data has " + std::to_string(cdata.m) + " rows, the solver was built for " +
         std::to_string(m));
  if (q.size() != model.nq) fail("q has size " + std::to_string(q.size()) + ", expected nq = " +
                                 std::to_string(model.nq));
  if (v.size() != model.nv) fail("v has size " + std::to_string(v.size()) + ", expected nv = " +
                                 std::to_string(model.nv));
  if (tau && tau->size() != model.nv)
    fail("tau has size " + std::to_string(tau->size()) + ", expected nv = " +
         std::to_string(model.nv));
}

void assembleDense(const Model& model, Data& data, const ConstraintList& constraints,
                   ConstraintData& cdata, const VecX& q, const VecX& v) {
  // J̇v at (q, v) for abias; the rows themselves were evaluated by the caller.
  data.ddq.setZero();
  forwardKinematics(model, data, q, v, data.ddq);
  assembleDenseRows(model, data, constraints, cdata);
}

void sizeResult(int nv, int m, ConstrainedResult& out) {
  out.vdot.resize(nv);
  out.lambda.resize(m);
  out.reaction.resize(nv);
  out.ok = true;
  out.error.clear();
  out.rank = 0;
  out.redundant = 0;
}

}  // namespace detail

// Mass-metric workspace: M = LLᵀ, B = L⁻¹Aᵀ and its row basis.
struct KktSolver::Impl {
  Impl(int n, int m)
      : llt(n), basis(n, m), B(MatX::Zero(n, m)), a(VecX::Zero(n)), d(VecX::Zero(m)),
        y(VecX::Zero(n)), lambda(VecX::Zero(m)) {}
  Eigen::LLT<MatX> llt;
  detail::RowBasis basis;
  MatX B;
  VecX a, d, y, lambda;

  bool factorMass(const MatX& M) {
    llt.compute(M);
    return llt.info() == Eigen::Success;
  }
  /// B = L⁻¹ Aᵀ and its rank-revealing factorization.
  void factorRows(const MatX& A, const SolverOptions& opt) {
    B = A.transpose();
    llt.matrixL().solveInPlace(B);
    basis.factor(B, opt, /*form_q=*/false);
  }
};

KktSolver::KktSolver(const Model& model, const ConstraintList& constraints,
                     const SolverOptions& options)
    : options_(options),
      impl_(std::make_unique<Impl>(model.nv, detail::totalRows(constraints))) {}

KktSolver::~KktSolver() = default;

void KktSolver::solve(const Model& model, Data& data, const ConstraintList& constraints,
                      ConstraintData& cdata, const VecX& q, const VecX& v, const VecX& tau,
                      ConstrainedResult& out,
                      SolveOutputs outputs) {
  (void)outputs;  // a dense reference always writes λ and Aᵀλ (they cost little next to its O(n³) factorisation)
  Impl& w = *impl_;
  const int m = w.basis.m();
  detail::checkSizes("KktSolver::solve", model, m, cdata, q, v, &tau);
  detail::sizeResult(model.nv, m, out);
  last_error_.clear();
  auto fail = [&](std::string why) {
    out.ok = false;
    out.error = std::move(why);
    last_error_ = out.error;
  };
  if (cdata.singular) return fail("singular contact geometry: " + cdata.singular_reason);
  detail::assembleDense(model, data, constraints, cdata, q, v);
  const MatX& M = crba(model, data, q);
  const VecX& h = nonLinearEffects(model, data, q, v);
  if (!w.factorMass(M)) return fail("mass matrix is not positive definite");
  // Unconstrained acceleration a = M⁻¹(τ − h).
  w.a = tau - h;
  w.llt.solveInPlace(w.a);
  if (m == 0) {
    out.vdot = w.a;
    out.reaction.setZero();
    return;
  }
  w.factorRows(cdata.A, options_);
  out.rank = w.basis.rank();
  out.redundant = cdata.m_active - out.rank;  // open contacts' zero rows are not redundancy
  // Constraint defect of the free motion: d = c − A a, c = −abias.
  w.d.noalias() = -cdata.A * w.a;
  w.d -= cdata.abias;
  if (!w.basis.solveRows(w.d, w.y)) return fail(w.basis.describeInconsistency(constraints, cdata));
  // v̇ = a + L⁻ᵀ y;  Aᵀλ = M(v̇ − a) = L y  ⇔  L⁻¹Aᵀλ = y.
  out.vdot = w.y;
  w.llt.matrixU().solveInPlace(out.vdot);
  out.vdot += w.a;
  w.basis.minNormOfSolution(out.lambda);
  out.reaction.noalias() = cdata.A.transpose() * out.lambda;
}

bool KktSolver::projectVelocity(const Model& model, Data& data, const ConstraintList& constraints,
                                ConstraintData& cdata, const VecX& q, VecX& v, VecX& impulse) {
  Impl& w = *impl_;
  const int m = w.basis.m();
  detail::checkSizes("KktSolver::projectVelocity", model, m, cdata, q, v, nullptr);
  impulse.resize(m);
  impulse.setZero();
  last_error_.clear();
  if (m == 0) return true;
  if (cdata.singular) {
    last_error_ = "singular contact geometry: " + cdata.singular_reason;
    return false;
  }
  detail::assembleDense(model, data, constraints, cdata, q, v);
  if (!w.factorMass(crba(model, data, q))) {
    last_error_ = "mass matrix is not positive definite";
    return false;
  }
  w.factorRows(cdata.A, options_);
  // min ½‖v⁺ − v‖²_M  s.t.  A v⁺ = −b:  y = Lᵀ(v⁺ − v) of least norm with
  // (A L⁻ᵀ) y = −b − A v.
  w.d.noalias() = -cdata.A * v;
  w.d -= cdata.b;
  if (!w.basis.solveRows(w.d, w.y)) {
    last_error_ = w.basis.describeInconsistency(constraints, cdata);
    return false;
  }
  w.basis.minNormOfSolution(w.lambda);  // M(v⁺ − v) = Aᵀλ
  impulse = -w.lambda;                  // v⁺ = v − M⁻¹Aᵀμ
  w.llt.matrixU().solveInPlace(w.y);
  v += w.y;
  return true;
}

}  // namespace appell
