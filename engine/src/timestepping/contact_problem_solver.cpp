// ContactProblemSolver (appell/contact_problem.hpp): the time-stepping
// scheme's own contact-problem solver (contact_problem.hpp) over a problem
// given as data — the same Gauss–Seidel and active-set finish, so a
// recorded step's problem re-solved from its warm start (and with the
// finish modes the step skipped) gives its impulses bit for bit.
#include <appell/contact_problem.hpp>

#include "timestepping/contact_problem.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace appell {

struct ContactProblemSolver::Impl {
  timestepping::ContactProblem problem;
};

namespace {

// The block structure must tile the rows: [n, f…, e…] one after another.
void checkLayout(const ContactProblemData& d) {
  const int n = d.rows();
  int at = 0;
  for (const ContactProblemBlock& b : d.blocks) {
    if (b.first != at || b.friction_rows < 0 || b.friction_rows > 2 || b.equality_rows < 0 ||
        b.equality_rows > 5 || !(b.mu >= 0))
      throw std::invalid_argument("ContactProblemSolver: block of constraint " +
                                  std::to_string(b.constraint) + " at row " + std::to_string(b.first) +
                                  " does not follow the last block, or has a bad row count or μ");
    at += 1 + b.friction_rows + b.equality_rows;
  }
  if (at != n || d.W.rows() != n || d.W.cols() != n || d.target.size() != n)
    throw std::invalid_argument("ContactProblemSolver: W, u_free, target and the blocks' rows disagree in size");
  if (!d.W.allFinite() || !d.u_free.allFinite() || !d.target.allFinite())
    throw std::invalid_argument("ContactProblemSolver: W, u_free and target must be finite");
  const auto& skip = d.skipped_finish_modes;
  if ((!skip.empty() && skip.size() != d.blocks.size()) ||
      std::any_of(skip.begin(), skip.end(), [](int m) { return m < 0 || m > 2; }))
    throw std::invalid_argument("ContactProblemSolver: skipped_finish_modes must be empty or one mode "
                                "(0 open, 1 pushing, 2 sliding) per block; got " +
                                std::to_string(skip.size()) + " for " + std::to_string(d.blocks.size()) +
                                " blocks");
}

void checkStart(const VecX& start, int n) {
  if (start.size() != n || !start.allFinite())
    throw std::invalid_argument("ContactProblemSolver: the start (or impulses) must be " + std::to_string(n) +
                                " finite numbers, got " + std::to_string(start.size()));
}

}  // namespace

ContactProblemSolver::ContactProblemSolver(const ContactProblemData& d)
    : impl_(std::make_unique<Impl>()) {
  checkLayout(d);
  timestepping::ContactProblem& p = impl_->problem;
  p.reserve(d.rows(), static_cast<int>(d.blocks.size()));
  for (const ContactProblemBlock& b : d.blocks) p.add(b.friction_rows, b.equality_rows, b.mu);
  p.W.topLeftCorner(p.n, p.n) = d.W;
  p.u_free.head(p.n) = d.u_free;
  p.target.head(p.n) = d.target;
  p.skip_modes.assign(d.skipped_finish_modes.begin(), d.skipped_finish_modes.end());
}

ContactProblemSolver::~ContactProblemSolver() = default;
ContactProblemSolver::ContactProblemSolver(ContactProblemSolver&&) noexcept = default;
ContactProblemSolver& ContactProblemSolver::operator=(ContactProblemSolver&&) noexcept = default;

ContactProblemSolver::Result ContactProblemSolver::solve(const VecX& start, double tol,
                                                         int max_sweeps, VecX& P, VecX& u) {
  timestepping::ContactProblem& p = impl_->problem;
  checkStart(start, p.n);
  if (!(tol > 0) || max_sweeps < 1)
    throw std::invalid_argument("ContactProblemSolver: tol > 0 and max_sweeps ≥ 1 are required");
  p.P.head(p.n) = start;
  p.solve(tol, max_sweeps);
  P = p.P.head(p.n);
  u = p.u.head(p.n);
  return {p.sweeps, p.residual, p.converged, p.polished};
}

double ContactProblemSolver::residual(const VecX& P) {
  timestepping::ContactProblem& p = impl_->problem;
  checkStart(P, p.n);
  p.P.head(p.n) = P;
  p.u.head(p.n) = p.u_free.head(p.n);
  p.u.head(p.n).noalias() += p.W.topLeftCorner(p.n, p.n) * P;
  double r = 0;
  for (const timestepping::ProblemBlock& b : p.blocks) r = std::max(r, p.blockResidual(b));
  return r;
}

}  // namespace appell
