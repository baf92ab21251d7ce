// The unilateral constraints' workspace, built once at construction: one
// detail::UnilateralRow per unilateral constraint (its row, bodies, contact
// law checked), the points of one pair linked, and every buffer of the
// event, impact, force and friction stages sized for all of them — so that
// no stage allocates inside a step.
#include <appell/simulator.hpp>

#include "simulator/simulator_impl.hpp"

#include <cmath>
#include <stdexcept>

namespace appell {

using detail::UnilateralRow;

/// Throws std::invalid_argument naming the constraint when its contact law
/// is outside its range (restitution in [0, 1], 0 ≤ μₖ ≤ μ, a finite creep
/// speed ≥ 0).
static void checkContactLaw(const Constraint& con) {
  const ContactLaw& law = con.contactLaw();
  const double e = law.restitution;
  if (!(e >= 0 && e <= 1))
    throw std::invalid_argument("Simulator: constraint '" + con.name() +
                                "' has restitution " + std::to_string(e) + " outside [0, 1]");
  const double mu = law.mu;
  if (!(mu >= 0))
    throw std::invalid_argument("Simulator: constraint '" + con.name() + "' has friction μ = " +
                                std::to_string(mu) + " (must be ≥ 0)");
  const double mu_k = law.mu_kinetic;
  if (!(mu_k >= 0 && mu_k <= mu))
    throw std::invalid_argument("Simulator: constraint '" + con.name() +
                                "' has kinetic friction μₖ = " + std::to_string(mu_k) +
                                " outside [0, μ = " + std::to_string(mu) + "]");
  const double creep = law.creep_speed;
  if (!(creep >= 0 && std::isfinite(creep)))
    throw std::invalid_argument("Simulator: constraint '" + con.name() + "' has creep speed " +
                                std::to_string(creep) + " (must be ≥ 0 and finite)");
  const double k = law.normal_stiffness, c = law.normal_damping;
  if (!(k >= 0 && std::isfinite(k) && c >= 0 && std::isfinite(c)) || (c > 0 && !(k > 0)))
    throw std::invalid_argument("Simulator: constraint '" + con.name() + "' has normal stiffness " +
                                std::to_string(k) + " and damping " + std::to_string(c) +
                                " (both ≥ 0 and finite; a damping needs a stiffness > 0)");
}

/// The row of unilateral constraint c, its contact law checked.
static UnilateralRow unilateralRowOf(const ConstraintList& constraints, const ConstraintData& cd,
                                     int c) {
  const Constraint& con = *constraints[c];
  UnilateralRow r;
  r.c = c;
  r.row = con.unilateralRow();
  if (r.row >= con.rows())
    throw std::invalid_argument("Simulator: constraint '" + con.name() +
                                "' names unilateral row " + std::to_string(r.row) + " of " +
                                std::to_string(con.rows()));
  r.global = cd.offset[c] + r.row;
  r.joint = con.jointSpace();
  r.a = con.bodyA();
  r.b = con.bodyB();
  if (r.joint) {
    r.cols = cd.blocks[c].joint_cols;
    r.a_joint = VecX::Zero(static_cast<int>(r.cols.size()));
  }
  checkContactLaw(con);
  const ContactLaw& law = con.contactLaw();
  if (std::isfinite(law.mu) && cd.slide[c].n > 0) {
    r.mu = law.mu;
    r.mu_k = law.mu_kinetic;
    r.nf = cd.slide[c].n;
    r.creep = law.creep_speed;
  }
  r.slot = con.pointSlot();
  return r;
}

void Simulator::Impl::setUpUnilateral() {
  for (int c = 0; c < static_cast<int>(constraints_.size()); ++c) {
    if (!constraints_[c]->unilateral()) continue;
    if (!uni_) uni_ = std::make_unique<detail::UnilateralState>();
    uni_->rows.push_back(unilateralRowOf(constraints_, *cdata_, c));
  }
  if (!uni_) return;
  for (const auto& r : uni_->rows)  // regularized friction: closed means sliding
    if (cdata_->regularized[r.c] && cdata_->isActive(r.c)) cdata_->setSliding(r.c, true);
  linkPointGroups();
  uni_->islands = detail::findIslands(model_, constraints_, *cdata_, uni_->rows);
  sizeUnilateralWorkspace();
}

/// Points of one pair (Constraint::pointGroup): each one's siblings.
void Simulator::Impl::linkPointGroups() {
  auto& u = *uni_;
  for (int i = 0; i < static_cast<int>(u.rows.size()); ++i) {
    const int group = constraints_[u.rows[i].c]->pointGroup();
    if (group < 0) continue;
    for (int j = 0; j < static_cast<int>(u.rows.size()); ++j)
      if (j != i && constraints_[u.rows[j].c]->pointGroup() == group) {
        if (u.rows[j].slot == u.rows[i].slot)
          throw std::invalid_argument("Simulator: contacts '" +
                                      constraints_[u.rows[i].c]->name() + "' and '" +
                                      constraints_[u.rows[j].c]->name() +
                                      "' are the same point of one pair");
        u.rows[i].siblings.push_back(j);
      }
    if (u.rows[i].siblings.size() > cdata_->blocks[u.rows[i].c].piece.excluded.size())
      throw std::invalid_argument("Simulator: contact '" + constraints_[u.rows[i].c]->name() +
                                  "' has more than 4 points");
  }
}

/// Every buffer of the unilateral stages, at its largest size: the friction
/// problems' for the largest island (islands.cpp), so that memory grows with
/// the scene, not with the square of its contacts.
void Simulator::Impl::sizeUnilateralWorkspace() {
  auto& u = *uni_;
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
  const int island_kf = u.islands.max_friction_contacts;
  const int island_nf = u.islands.max_friction_rows;
  const size_t runs = static_cast<size_t>(u.islands.count()) + 1;
  u.sliding.reserve(u.rows.size());
  u.sliding_runs.reserve(runs);
  u.G = MatX::Zero(model_.nv, island_kf);
  u.J = MatX::Zero(6, model_.nv);
  u.R = MatX::Zero(island_kf, island_kf);
  u.lam0 = VecX::Zero(kf);
  u.s = VecX::Zero(kf);
  u.tau_f = VecX::Zero(model_.nv);
  u.tau_unit = VecX::Zero(model_.nv);
  u.unit = u.res;
  u.onset.reserve(u.rows.size());
  u.onset_runs.reserve(runs);
  u.was_sliding.assign(u.rows.size(), 0);
  u.onset_problem.size(model_.nv, island_nf, island_kf, u.res);
  u.settle.reserve(u.rows.size());
  u.settle_runs.reserve(runs);
  u.settle_tau = VecX::Zero(model_.nv);
  u.settle_problem.size(model_.nv, island_nf, island_kf, u.res);
  u.swmax = VecX::Zero(island_kf);
  u.settle_factor.assign(island_kf, {});
  u.settle_factored.assign(island_kf, 0);
  u.vstick = VecX::Zero(model_.nv);
  u.vsum = VecX::Zero(model_.nv);
  u.over_W = MatX::Zero(island_nf, island_nf);
  u.over_g = VecX::Zero(island_nf);
  u.over_eig = Eigen::SelfAdjointEigenSolver<MatX>(island_nf);
  u.feature_ahead.assign(u.rows.size(), -1);
}

}  // namespace appell
