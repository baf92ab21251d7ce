// Shared pieces of the tree-solver tests: test-only constraints with random
// body-local rows, consistent right sides, random systems (the dense
// references they are checked against: dense_reference.hpp).
#pragma once

#include <appell/appell.hpp>
#include <appell/kkt.hpp>
#include <appell/tree_solver.hpp>

#include <memory>
#include <random>
#include <string>

#include "random_tree.hpp"

namespace appell::test {

using Rows = Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor, 6, 6>;

/// Rows given as covectors in the frames of body A (and body B), constant there.
class LocalRows : public Constraint {
 public:
  LocalRows(std::string name, int a, const Rows& Ka, int b = -1, const Rows& Kb = Rows())
      : name_(std::move(name)), a_(a), b_(b), Ka_(Ka), Kb_(Kb),
        kappa_(VecX::Zero(Ka.rows())), bvel_(VecX::Zero(Ka.rows())) {}
  const std::string& name() const override { return name_; }
  int rows() const override { return static_cast<int>(Ka_.rows()); }
  int bodyA() const override { return a_; }
  int bodyB() const override { return b_; }
  RowKind rowKind(int) const override { return RowKind::Custom; }
  std::string rowLabel(int k) const override { return "row" + std::to_string(k); }
  bool holonomic(int) const override { return false; }
  void evaluate(const Model&, const Data& data, double, const VecX&, const VecX&,
                RowBlock& out) const override;

  VecX& kappa() { return kappa_; }
  VecX& bvel() { return bvel_; }
  Rows& rowsA() { return Ka_; }
  /// Row r (its covectors, κ and b) times s: the same constraint, rescaled.
  void scaleRow(int r, double s) {
    Ka_.row(r) *= s;
    if (Kb_.rows() > r) Kb_.row(r) *= s;
    kappa_[r] *= s;
    bvel_[r] *= s;
  }

 private:
  std::string name_;
  int a_, b_;
  Rows Ka_, Kb_;
  VecX kappa_, bvel_;
};

/// Rows over the generalized velocities: dense, or over the columns `cols`
/// only (A then has one column per entry of cols).
class JointRows : public Constraint {
 public:
  JointRows(std::string name, const MatX& A, std::vector<int> cols = {})
      : name_(std::move(name)), A_(A), abias_(VecX::Zero(A.rows())), b_(VecX::Zero(A.rows())),
        cols_(std::move(cols)) {}
  std::vector<int> jointColumns(const Model& model) const override {
    return cols_.empty() ? Constraint::jointColumns(model) : cols_;
  }
  const std::string& name() const override { return name_; }
  int rows() const override { return static_cast<int>(A_.rows()); }
  int bodyA() const override { return -1; }
  bool jointSpace() const override { return true; }
  RowKind rowKind(int) const override { return RowKind::Custom; }
  std::string rowLabel(int k) const override { return "joint" + std::to_string(k); }
  bool holonomic(int) const override { return false; }
  void evaluate(const Model&, const Data&, double, const VecX&, const VecX&,
                RowBlock& out) const override;

  VecX& abias() { return abias_; }
  VecX& bvel() { return b_; }

 private:
  std::string name_;
  MatX A_;
  VecX abias_, b_;
  std::vector<int> cols_;
};

/// A system under test: model, state, constraints (kept mutable for their right sides).
struct System {
  Model model;
  VecX q, v, tau;
  std::vector<std::shared_ptr<LocalRows>> local;
  std::vector<std::shared_ptr<JointRows>> joint;
  ConstraintList list() const {
    ConstraintList l;
    for (auto& c : local) l.push_back(c);
    for (auto& c : joint) l.push_back(c);
    return l;
  }
};

/// Sets κ and b so that a random v̇* and v* satisfy every row: A v̇* + abias = 0,
/// A v* + b = 0. Redundant rows are then consistent by construction.
void makeConsistent(System& s, std::mt19937& rng);

/// One tree solve of s at its state, with a solver built for it.
ConstrainedResult treeSolve(const System& s);

/// A joint-space constraint `name` whose one row is `scale` × the last row
/// of A at s's state: redundant with the tree rows (a loop row they make
/// immobile).
void addJointCopyOfLastRow(System& s, const std::string& name, double scale);

struct RowRecipe {
  double p_duplicate = 0.0;   ///< row = scale × an earlier row of the same body
  double p_immobile = 0.0;    ///< row orthogonal to the body's own joint subspace
  int max_constraints = 2;    ///< per body
};

Vec6 randomRow(std::mt19937& rng);

/// Random body-local rows on every body (some bodies get none).
void addRandomRows(System& s, std::mt19937& rng, const RowRecipe& recipe);

/// A random tree of n bodies at a random state (q, v, τ), no rows yet.
System randomState(int n, bool floating, std::mt19937& rng, double v_scale = 1.0,
                   double tau_scale = 1.0);

System randomSystem(int n, bool floating, std::mt19937& rng, const RowRecipe& recipe);

/// A unit row on body i that the body's own one-DoF joint moves with pivot
/// exactly σ: σ s + √(1 − σ²) w with w ⊥ s a random direction (which the
/// ancestors' joints generally move well).
Vec6 weakRow(const Model& model, int i, double sigma, std::mt19937& rng);

/// Adds one weak row (weakRow, pivot σ) on each of the last `count` one-DoF bodies.
void addWeakRows(System& s, int count, double sigma, std::mt19937& rng);

double relErr(const VecX& a, const VecX& b);

}  // namespace appell::test
