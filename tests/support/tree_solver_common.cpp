// The functions declared in tree_solver_common.hpp, compiled once (see there for what they build).
#include "tree_solver_common.hpp"

namespace appell::test {

void LocalRows::evaluate(const Model&, const Data& data, double, const VecX&, const VecX&,
                         RowBlock& out) const {
  const int m = rows();
  for (int r = 0; r < m; ++r) {
    // A body covector w_b is the world covector w with w·V = w_b·V_b: w = ᵒX_b⁻ᵀ w_b.
    const Vec6 wa = a_ >= 0 ? data.oMi[a_].actForce(Ka_.row(r).transpose()) : Vec6::Zero();
    const Vec6 wb = b_ >= 0 ? data.oMi[b_].actForce(Kb_.row(r).transpose()) : Vec6::Zero();
    out.Wa.row(r) = wa.transpose();
    out.Wb.row(r) = wb.transpose();
    out.kappa[r] = kappa_[r];
    out.b[r] = bvel_[r];
    out.gap[r] = 0;
  }
}
void JointRows::evaluate(const Model&, const Data&, double, const VecX&, const VecX&,
                         RowBlock& out) const {
  out.A_joint = A_;
  out.abias_joint = abias_;
  out.b_joint = b_;
}
void makeConsistent(System& s, std::mt19937& rng) {
  const ConstraintList list = s.list();
  Data data(s.model);
  ConstraintData cd(s.model, list);
  for (auto& c : s.local) c->kappa().setZero(), c->bvel().setZero();
  for (auto& c : s.joint) c->abias().setZero(), c->bvel().setZero();
  evaluateConstraints(s.model, data, list, cd, 0.0, s.q, s.v);
  const VecX vd = randomVector(s.model.nv, rng), vs = randomVector(s.model.nv, rng);
  const VecX Avd = cd.A * vd + cd.abias, Avs = cd.A * vs;
  int o = 0;
  for (auto& c : s.local) {
    c->kappa() = -Avd.segment(o, c->rows());
    c->bvel() = -Avs.segment(o, c->rows());
    o += c->rows();
  }
  for (auto& c : s.joint) {
    c->abias() = -Avd.segment(o, c->rows());
    c->bvel() = -Avs.segment(o, c->rows());
    o += c->rows();
  }
}

ConstrainedResult treeSolve(const System& s) {
  const ConstraintList list = s.list();
  Data data(s.model);
  ConstraintData cd(s.model, list);
  evaluateConstraints(s.model, data, list, cd, 0.0, s.q, s.v);
  TreeSolver solver(s.model, list);
  ConstrainedResult out;
  solver.solve(s.model, data, list, cd, s.q, s.v, s.tau, out);
  return out;
}

void addJointCopyOfLastRow(System& s, const std::string& name, double scale) {
  const ConstraintList list = s.list();
  Data data(s.model);
  ConstraintData cd(s.model, list);
  evaluateConstraints(s.model, data, list, cd, 0.0, s.q, s.v);
  s.joint.push_back(std::make_shared<JointRows>(name, scale * cd.A.bottomRows(1)));
}

Vec6 randomRow(std::mt19937& rng) {
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> e(-1.5, 1.5);
  Vec6 w;
  for (int k = 0; k < 6; ++k) w[k] = g(rng);
  return std::pow(10.0, e(rng)) * w.normalized();
}

void addRandomRows(System& s, std::mt19937& rng, const RowRecipe& recipe) {
  std::uniform_real_distribution<double> u(0, 1), sc(-3, 3);
  std::uniform_int_distribution<int> nrows(1, 6), ncons(0, recipe.max_constraints);
  for (int i = 0; i < s.model.nbodies; ++i) {
    std::vector<Vec6> earlier;
    const int nc = ncons(rng);
    for (int c = 0; c < nc; ++c) {
      const int m = nrows(rng);
      Rows K(m, 6);
      for (int r = 0; r < m; ++r) {
        Vec6 w = randomRow(rng);
        const Mat6X& S = s.model.joints[i].S;
        if (!earlier.empty() && u(rng) < recipe.p_duplicate) {
          // The row first, then the scale (g++'s order when both were
          // operands of one product): every compiler draws the same rows.
          const size_t which = std::uniform_int_distribution<size_t>(0, earlier.size() - 1)(rng);
          w = sc(rng) * earlier[which];
          if (w.norm() == 0) w = randomRow(rng);
        } else if (S.cols() > 0 && S.cols() < 6 && u(rng) < recipe.p_immobile) {
          // w·S = 0: the body's own joint cannot move this row.
          w -= S * (S.transpose() * S).ldlt().solve(S.transpose() * w);
        }
        K.row(r) = w.transpose();
        earlier.push_back(w);
      }
      s.local.push_back(std::make_shared<LocalRows>(
          "rows" + std::to_string(s.local.size()) + "@body" + std::to_string(i), i, K));
    }
  }
}

System randomState(int n, bool floating, std::mt19937& rng, double v_scale, double tau_scale) {
  System s;
  s.model = randomTree(n, floating, rng);
  s.q = randomConfiguration(s.model, rng);
  s.v = randomVector(s.model.nv, rng, v_scale);
  s.tau = randomVector(s.model.nv, rng, tau_scale);
  return s;
}

System randomSystem(int n, bool floating, std::mt19937& rng, const RowRecipe& recipe) {
  System s = randomState(n, floating, rng, 1.5, 2.0);
  addRandomRows(s, rng, recipe);
  makeConsistent(s, rng);
  return s;
}

Vec6 weakRow(const Model& model, int i, double sigma, std::mt19937& rng) {
  const Vec6 s = model.joints[i].S.col(0).normalized();
  Vec6 w = randomRow(rng);
  w -= s.dot(w) * s;
  return sigma * s + std::sqrt(1 - sigma * sigma) * w.normalized();
}

void addWeakRows(System& s, int count, double sigma, std::mt19937& rng) {
  for (int i = s.model.nbodies - 1, added = 0; i > 0 && added < count; --i) {
    if (s.model.joints[i].nv != 1) continue;
    Rows K(1, 6);
    K.row(0) = weakRow(s.model, i, sigma, rng).transpose();
    s.local.push_back(std::make_shared<LocalRows>("weak@" + std::to_string(i), i, K));
    ++added;
  }
}

double relErr(const VecX& a, const VecX& b) { return (a - b).norm() / std::max(1.0, b.norm()); }

}  // namespace appell::test
