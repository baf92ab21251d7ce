// appell info: what the scene declares and what that costs.
#include "commands.hpp"

#include <appell/appell.hpp>
#include <appell/constrained_dynamics.hpp>
#include <appell/run.hpp>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>

namespace appell::cli {

namespace {

const char* kInfoHelp = R"(usage: appell info SCENE.urdf [--package-path DIRS] [--project-initial] [--no-joint-limits]
                         [--balance-inertia] [--bound-inertia V] [--bound-mass M]

Prints the bodies (joint type, parent, mass), the degrees of freedom (nq, nv),
the links merged on fixed joints, the meshes (triangles, vertices), every
contact with its kind, support, shape and rows, the joint limits, actuators
and mimic couplings, and at the initial state
the rank of the constraint rows: redundant rows (e.g. a four-wheeled car) and
the residuals of the initial state. Inertias loaded with a defect (principal
moments that break the triangle inequality, a near-massless body carried by
its children) or repaired are named in warnings on stderr.

)" APPELL_INERTIA_HELP;

}  // namespace

int info(int argc, char** argv) {
  Args args(argc, argv, 2, kLoadOptions, kLoadFlags);
  if (args.has("help")) {
    std::cout << kInfoHelp;
    return 0;
  }
  const Scene scene = loadFromArgs(args, false);
  const Model& m = scene.model;
  std::cout << "scene " << scene.source << "\n";
  if (scene.robot_source != scene.source) std::cout << "robot " << scene.robot_source << "\n";
  std::cout
            << m.nbodies << " bodies, nq = " << m.nq << ", nv = " << m.nv
            << ", total mass " << m.totalMass() << " kg, gravity " << m.gravity.transpose() << "\n\n";
  // Columns as wide as the longest name (CAD exports have long ones).
  std::size_t wb = 4, wj = 5;
  for (int i = 0; i < m.nbodies; ++i) {
    wb = std::max(wb, m.body_names[i].size());
    wj = std::max(wj, m.joint_names[i].size());
  }
  const int cb = static_cast<int>(wb) + 2, cj = static_cast<int>(wj) + 2;
  std::cout << std::left << std::setw(cb) << "body" << std::setw(cj) << "joint" << std::setw(11)
            << "type" << std::setw(cb) << "parent" << "mass\n";
  for (int i = 0; i < m.nbodies; ++i)
    std::cout << std::setw(cb) << m.body_names[i] << std::setw(cj) << m.joint_names[i]
              << std::setw(11) << toString(m.joints[i].type) << std::setw(cb)
              << (m.parent[i] < 0 ? std::string("world") : m.body_names[m.parent[i]])
              << m.inertias[i].mass << "\n";
  // Links on fixed joints move with the link they hang on: one rigid body
  // (their inertias combined, as Pinocchio and KDL merge them).
  bool any_merged = false;
  for (const RigidGroup& g : rigidGroups(m)) {
    if (g.fixed.empty()) continue;
    if (!any_merged) std::cout << "\nmerged (links on fixed joints move as one body with the link they hang on):\n";
    any_merged = true;
    std::cout << "  " << m.body_names[g.body] << " +";
    for (size_t k = 0; k < g.fixed.size(); ++k) std::cout << (k ? ", " : " ") << m.body_names[g.fixed[k]];
    const Vec3 J = Eigen::SelfAdjointEigenSolver<Mat3>(g.inertia.inertia_com).eigenvalues();
    const Vec3& c = g.inertia.com;
    std::cout << ": mass " << g.inertia.mass << " kg, centre of mass (" << c.x() << ", " << c.y()
              << ", " << c.z() << ") in " << m.body_names[g.body] << ", principal moments ("
              << J.x() << ", " << J.y() << ", " << J.z() << ") kg m²\n";
  }
  // Meshes: what each link draws and collides with, and its size.
  bool any_mesh = false;
  for (const LinkGeometry& g : scene.geometry) {
    for (const auto* list : {&g.visual, &g.collision}) {
      for (const Geometry& geo : *list) {
        if (geo.type != GeometryType::Mesh) continue;
        if (!any_mesh) std::cout << "\nmeshes:\n";
        any_mesh = true;
        std::cout << "  " << std::setw(cb) << g.link << (list == &g.visual ? "visual    " : "collision ")
                  << geo.mesh_uri;
        if (geo.mesh)
          std::cout << ": " << geo.mesh->triangles.size() << " triangles, " << geo.mesh->vertices.size()
                    << " vertices";
        else
          std::cout << ": not loaded";
        if (geo.mesh_scale != Vec3::Ones())
          std::cout << ", scale (" << geo.mesh_scale.x() << ", " << geo.mesh_scale.y() << ", "
                    << geo.mesh_scale.z() << ")";
        std::cout << "\n";
      }
    }
  }
  std::cout << "\n" << scene.contacts.size() << " contacts, " << scene.constraintRows()
            << " constraint rows\n";
  for (size_t k = 0; k < scene.contacts.size(); ++k) {
    const ShapeContact& c = *scene.contacts[k];
    std::cout << "  " << std::setw(22) << c.name() << " link " << std::setw(cb)
              << m.body_names[c.bodyA()] << " " << std::setw(20) << toString(c.kind()) << " on "
              << std::setw(10) << c.support().name << " shape "
              << scene.contact_origins[k].shape_source;
    if (std::isfinite(c.mu())) std::cout << ", μ " << c.mu();
    std::cout << ", rows:";
    for (int r = 0; r < c.rows(); ++r) std::cout << " " << c.rowLabel(r);
    std::cout << "\n";
  }
  if (!scene.joint_limits.empty()) {
    std::cout << scene.joint_limits.size() << " joint limits (unilateral; --no-joint-limits ignores them):\n";
    for (const auto& l : scene.joint_limits)
      std::cout << "  " << std::setw(22) << l->name() << " " << (l->side() == LimitSide::Lower ? "q ≥ " : "q ≤ ")
                << l->bound() << ", restitution " << l->restitution() << "\n";
  }
  if (!scene.actuators.empty()) {
    std::cout << scene.actuators.size() << " actuator" << (scene.actuators.size() > 1 ? "s" : "") << ":\n";
    for (const Actuator& a : scene.actuators) {
      std::cout << "  " << std::setw(22) << a.name << " " << toString(a.type) << " servo on "
                << m.joint_names[a.joint] << ", kp " << a.kp << ", kv " << a.kv << ", |τ| ≤ " << a.effort_limit
                << ", set-point";
      for (std::size_t k = 0; k < a.setpoint.t.size(); ++k)
        std::cout << (k ? "," : "") << " " << a.setpoint.value[k] << " at t=" << a.setpoint.t[k];
      std::cout << "\n";
    }
  }
  if (!scene.couplings.empty()) {
    std::cout << scene.couplings.size() << " mimic coupling" << (scene.couplings.size() > 1 ? "s" : "")
              << " (holonomic joint-space rows):\n";
    for (const auto& c : scene.couplings)
      std::cout << "  " << std::setw(22) << c->name() << " " << m.joint_names[c->follower()] << " = "
                << c->multiplier() << " · " << m.joint_names[c->leader()] << " + " << c->offset() << "\n";
  }
  if (scene.constraintRows() > 0) {
    // The simulator's own start (tree solver, O(n)): which unilateral rows
    // are closed, and the rank the solver decides with its tolerances on
    // equilibrated rows — the numbers `appell run` then works with. No dense
    // m × nv matrix: a 10⁵-link chain with joint limits has 2·10⁵ rows.
    RunOptions options = runOptions(scene.settings);
    options.formulation = Formulation::Tree;
    const std::unique_ptr<Simulator> sim = makeSimulator(scene, options);
    const ConstraintData& cd = sim->constraintData();
    const int closed = cd.m_active, rank = closed - sim->redundantRows();
    std::cout << "at the initial state: " << closed << " of " << cd.m << " rows closed, rank " << rank
              << " (" << closed - rank << " redundant), " << m.nv - rank
              << " independent velocities; residuals |Av+b| = " << sim->velocityResidual()
              << ", gap = " << sim->gapResidual() << "\n";
    if (m.nv > 0 && m.nv - rank == 0 && anyContactCanSlip(scene.constraints))
      std::cout << "held still while its contacts stick: it moves only by slipping where μ is finite\n";
    else if (m.nv > 0 && m.nv - rank == 0)
      std::cerr << "appell info: warning: " << scene.source
                << ": the constraints leave 0 independent velocities — nothing in this scene can move "
                   "(axles out of line? rows that contradict each other?)\n";
    if (cd.singular) std::cout << "singular contact geometry: " << cd.singular_reason << "\n";
    if (!sim->lastStateError().empty())
      std::cout << "the initial state cannot start: " << sim->lastStateError() << "\n";
  }
  const SimulationSettings& s = scene.settings;
  std::cout << "\ndefaults: integrator " << s.integrator << ", dt " << s.dt << ", tol " << s.tol
            << ", duration " << s.duration << " s, formulation " << s.formulation << "\n";
  return 0;
}

}  // namespace appell::cli
