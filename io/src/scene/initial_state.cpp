// Is the scene's initial state on the constraint manifold? And if asked,
// put it there: q onto the holonomic gaps, then v onto A v + b = 0.
#include <appell/urdf.hpp>

#include <appell/constrained_dynamics.hpp>
#include <appell/projection.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace appell {

namespace {

struct Worst {
  double value = 0;
  int row = -1;
  bool gap = false;
};

Worst worstRow(const Data& data, const ConstraintList& constraints, const ConstraintData& cd,
               const VecX& v) {
  Worst w;
  VecX r;
  velocityResiduals(data, constraints, cd, v, r);
  for (int i = 0; i < cd.m; ++i) {
    if (!cd.isActive(cd.row_constraint[i])) continue;  // open: its gap is a clearance
    if (std::abs(cd.gap(i)) > w.value) w = {std::abs(cd.gap(i)), i, true};
    if (std::abs(r(i)) > w.value) w = {std::abs(r(i)), i, false};
  }
  return w;
}

std::string describeRow(const Scene& scene, const ConstraintData& cd, int row) {
  const int c = cd.row_constraint[row];
  const Constraint& con = *scene.constraints[c];
  const bool contact = c < static_cast<int>(scene.contacts.size());
  return std::string(contact ? "contact '" : "constraint '") + con.name() + "' row '" +
         con.rowLabel(row - cd.offset[c]) + "'";
}

[[noreturn]] void singular(const Scene& scene, const ConstraintData& cd) {
  throw SceneError(scene.source + ": initial state: the contact geometry is singular: " +
                   cd.singular_reason);
}

void notFinite(const Scene& scene, const InitialStateReport& r) {
  if (!std::isfinite(r.velocity_residual) || !std::isfinite(r.gap_residual))
    throw SceneError(scene.source + ": initial state: the constraint rows are not finite there");
}

}  // namespace

InitialStateReport checkInitialState(Scene& scene, bool project, double tol) {
  InitialStateReport report;
  const Model& model = scene.model;
  if (scene.q0.size() != model.nq || scene.v0.size() != model.nv)
    throw SceneError(scene.source + ": initial state has the wrong size (q " +
                     std::to_string(scene.q0.size()) + " for nq " + std::to_string(model.nq) +
                     ", v " + std::to_string(scene.v0.size()) + " for nv " +
                     std::to_string(model.nv) + ")");
  if (!scene.q0.allFinite() || !scene.v0.allFinite())
    throw SceneError(scene.source + ": initial state is not finite");
  if (scene.constraints.empty()) return report;

  // Rows only, nothing dense: O(n) for a model of any size.
  Data data(model, MassMatrix::None);
  ConstraintData cd(model, scene.constraints, DenseRows::None);
  evaluateConstraintRows(model, data, scene.constraints, cd, 0.0, scene.q0, scene.v0);
  // Contacts with clearance start open (as the simulator opens them): only
  // the closed ones must hold. A unilateral gap below −tol is penetration.
  for (int c = 0; c < static_cast<int>(scene.constraints.size()); ++c) {
    const Constraint& con = *scene.constraints[c];
    if (!con.unilateral()) continue;
    const double g = cd.gap[cd.offset[c] + con.unilateralRow()];
    if (g > tol) cd.setActive(c, false);
    if (g < -tol && !project) {
      std::ostringstream s;
      s << scene.source << ": initial state: contact '" << con.name()
        << "' penetrates its support by " << -g << " (gap " << g << ", tolerance " << tol
        << "); raise the body, or let the loader push it out (appell --project-initial; "
           "LoadOptions::project_initial_state)";
      throw SceneError(s.str());
    }
  }
  // A closed contact with finite μ that slips is not an error: it starts
  // sliding (the Simulator decides it so at setState), and only its normal
  // row must hold — a slip at CAD level too (an axle a micro-radian out of
  // line scrubs on its settled direction: docs/contacts.md §8). Asked to
  // project (--project-initial), the loader puts the state on every row
  // instead: the user asked for the constraints to hold.
  if (!project) {
    VecX residual;
    velocityResiduals(data, scene.constraints, cd, scene.v0, residual);
    const double floor = tol;
    for (int c = 0; c < static_cast<int>(scene.constraints.size()); ++c) {
      const Constraint& con = *scene.constraints[c];
      const auto& sr = cd.slide[c];
      if (!con.unilateral() || !cd.isActive(c) || sr.n == 0 || !std::isfinite(con.friction()))
        continue;
      double slip2 = 0;
      for (int i = 0; i < sr.n; ++i)
        slip2 += std::pow(sr.scale[i] * residual[cd.offset[c] + sr.row[i]], 2);
      if (std::sqrt(slip2) > floor) {
        cd.setSliding(c, true);
        report.sliding.push_back(con.name());
      }
    }
  }
  evaluateConstraintRows(model, data, scene.constraints, cd, 0.0, scene.q0, scene.v0);
  if (cd.singular) singular(scene, cd);
  report.velocity_residual = velocityResidual(data, scene.constraints, cd, scene.v0);
  report.gap_residual = gapResidual(cd);
  notFinite(scene, report);
  if (report.velocity_residual <= tol && report.gap_residual <= tol) return report;

  if (!project) {
    const Worst w = worstRow(data, scene.constraints, cd, scene.v0);
    std::ostringstream s;
    s << scene.source << ": initial state violates the constraints: " << describeRow(scene, cd, w.row)
      << (w.gap ? " has gap " : " has velocity residual |A v + b| = ") << w.value
      << " (tolerance " << tol << "; max gap " << report.gap_residual
      << ", max velocity residual " << report.velocity_residual
      << "); fix <initial>, or let the loader project it onto the constraints (appell "
           "--project-initial; LoadOptions::project_initial_state)";
    throw SceneError(s.str());
  }

  // The engine's projection (projection.hpp): Newton on the holonomic gaps in
  // the mass metric, then the solver's impulse solve v ← v − M⁻¹Aᵀμ onto
  // A v + b = 0 — the correction that disturbs the kinetic energy least. The
  // solver is the scene's own formulation, so a failure here is the one the
  // run would meet; every formulation returns the same v (it is unique).
  ProjectionOptions popt;
  if (tol > 0) popt.gap_tol = 0.01 * tol;
  popt.stall_tol = std::min(popt.stall_tol, popt.gap_tol);
  popt.max_iterations = 50;
  PositionProjector projector(model, scene.constraints, popt);
  auto solver = makeSolver(formulationFromString(scene.settings.formulation), model,
                           scene.constraints);
  VecX q = scene.q0, v = scene.v0, impulse(cd.m);
  const StateProjectionResult res = projectState(model, data, scene.constraints, cd, *solver,
                                                 projector, 0.0, q, v, impulse);
  report.iterations = res.position.iterations;
  report.projected = true;
  if (!res.ok) {
    // q and v are unchanged: name the worst row at the initial state.
    evaluateConstraintRows(model, data, scene.constraints, cd, 0.0, scene.q0, scene.v0);
    const Worst w = worstRow(data, scene.constraints, cd, scene.v0);
    std::ostringstream s;
    s << scene.source << ": initial state could not be projected onto the constraints: "
      << res.error << " (worst: " << describeRow(scene, cd, w.row)
      << (w.gap ? " has gap " : " has velocity residual ") << w.value << ", tolerance " << tol
      << ") after " << report.iterations << " Newton steps";
    throw SceneError(s.str());
  }
  evaluateConstraintRows(model, data, scene.constraints, cd, 0.0, q, v);
  if (cd.singular) singular(scene, cd);
  report.velocity_residual = velocityResidual(data, scene.constraints, cd, v);
  report.gap_residual = gapResidual(cd);
  notFinite(scene, report);
  if (report.velocity_residual > tol || report.gap_residual > tol) {
    const Worst w = worstRow(data, scene.constraints, cd, v);
    std::ostringstream s;
    s << scene.source << ": initial state could not be projected onto the constraints: "
      << describeRow(scene, cd, w.row) << (w.gap ? " keeps gap " : " keeps velocity residual ")
      << w.value << " (tolerance " << tol << ") after " << report.iterations << " Newton steps";
    throw SceneError(s.str());
  }
  scene.q0 = q;
  scene.v0 = v;
  return report;
}

}  // namespace appell
