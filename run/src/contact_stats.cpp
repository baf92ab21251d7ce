// Contact reactions read the way a vehicle engineer reads them: normal load,
// friction demand |f_t| / f_n against μ, and normals that pull. λ of a row
// with direction t is the force along t on the body (constraint.hpp), so the
// normal row carries the normal load and the tangent and lateral rows the
// friction force.
#include "contact_stats.hpp"

#include <appell/constraint_set.hpp>
#include <appell/kinematics.hpp>

#include <algorithm>
#include <cmath>

namespace appell::run_detail {

std::vector<ContactStats> contactStats(const Scene& scene) {
  std::vector<ContactStats> stats;
  int offset = 0;
  for (std::size_t k = 0; k < scene.constraints.size(); ++k) {
    const Constraint& c = *scene.constraints[k];
    ContactStats e;
    e.name = c.name();
    // μ belongs to the contact; constraints the scene does not declare as contacts have none.
    if (k < scene.contacts.size() && scene.contacts[k] == scene.constraints[k])
      e.mu = scene.contacts[k]->mu();
    e.creep_speed = c.creepSpeed();
    for (int r = 0; r < c.rows(); ++r) {
      const RowKind kind = c.rowKind(r);
      if (kind == RowKind::Normal) e.normal_row = offset + r;
      if (isTangential(kind)) e.tangential_rows.push_back(offset + r);
      if (kind == RowKind::Spin && std::isfinite(c.spinFriction()) && c.friction() > 0) {
        e.spin_row = offset + r;
        e.spin_scale = c.spinFriction() / c.friction();
      }
    }
    if (e.normal_row < 0 && c.rows() == 1) e.reaction_row = offset;
    offset += c.rows();
    stats.push_back(std::move(e));
  }
  return stats;
}

void markHeldNormals(std::vector<ContactStats>& stats, const Scene& scene, const Simulator& sim) {
  const Model& model = scene.model;
  Data data(model, MassMatrix::None);
  forwardKinematics(model, data, sim.q(), sim.v());
  const ConstraintData& cd = sim.constraintData();
  MatX J, A;
  VecX abias;
  for (std::size_t k = 0; k < stats.size() && k < scene.constraints.size(); ++k) {
    ContactStats& e = stats[k];
    // An open constraint's block holds zero rows: nothing to judge from them.
    if (e.normal_row < 0 || !cd.isActive(static_cast<int>(k))) continue;
    const Constraint& c = *scene.constraints[k];
    const int r = e.normal_row - cd.offset[k];
    if (c.jointSpace()) {  // its own sparse row (a joint limit: ±1 on its joint)
      const auto row = cd.blocks[k].A_joint.row(r);
      e.normal_held = row.size() == 0 || row.lpNorm<Eigen::Infinity>() <= 1e-12 *
                          std::max(1.0, cd.blocks[k].A_joint.lpNorm<Eigen::Infinity>());
      continue;
    }
    if (J.cols() != model.nv) J.resize(6, model.nv);
    A.resize(c.rows(), model.nv);
    abias.resize(c.rows());
    assembleConstraintRows(model, data, c, cd.blocks[k], J, A, abias);
    e.normal_held = A.row(r).lpNorm<Eigen::Infinity>() <= 1e-12 * std::max(1.0, A.lpNorm<Eigen::Infinity>());
  }
}

void sample(std::vector<ContactStats>& stats, double t, const VecX& lambda,
            const ConstraintData& cdata) {
  // A closed contact at zero load (a limit in free fall, a wheel at the
  // instant of lift-off) neither pulls nor has a friction demand: loads
  // within round-off of the sample's largest reaction count as zero.
  const double zero = 1e-9 * std::max(1.0, lambda.size() ? lambda.lpNorm<Eigen::Infinity>() : 0.0);
  for (ContactStats& e : stats) {
    if (e.reaction_row >= 0) {
      e.min_reaction = std::min(e.min_reaction, lambda[e.reaction_row]);
      e.max_reaction = std::max(e.max_reaction, lambda[e.reaction_row]);
    }
    if (e.normal_row < 0) continue;
    if (!cdata.isActive(cdata.row_constraint[e.normal_row])) {
      ++e.open_samples;
      continue;
    }
    const int c = cdata.row_constraint[e.normal_row];
    if (cdata.isSliding(c)) {
      ++e.sliding_samples;
      e.max_slip = std::max(e.max_slip, cdata.slide[c].slip.norm());
    }
    const double fn = lambda[e.normal_row];
    double ft2 = 0;
    for (int r : e.tangential_rows) ft2 += lambda[r] * lambda[r];
    if (e.spin_row >= 0) ft2 += std::pow(lambda[e.spin_row] / e.spin_scale, 2);
    const double ft = std::sqrt(ft2);
    e.min_normal = std::min(e.min_normal, fn);
    e.max_normal = std::max(e.max_normal, fn);
    if (e.normal_held) continue;  // the joints carry the normal: no load to judge
    if (fn < -zero) {  // a bilateral contact pulling, or a unilateral one at lift-off
      if (e.pulling++ == 0) e.first_pull = t;
      continue;
    }
    if (fn <= zero) continue;  // no load: nothing pulls, no friction to judge
    const double demand = ft / fn;
    if (demand > e.max_demand) {
      e.max_demand = demand;
      e.t_max_demand = t;
    }
    // Over μ is a finding only for a contact that is not sliding: a sliding
    // one carries μₖλₙ exactly (up to round-off, hence the 1e-9).
    if (!cdata.isSliding(c) && demand > e.mu * (1 + 1e-9) && e.over_mu++ == 0) e.first_slip = t;
  }
}

}  // namespace appell::run_detail
