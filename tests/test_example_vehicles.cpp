// Example vehicles (examples/diff_drive, car, ntrailer): load each URDF, run it
// with the Simulator (tree solver, Dormand–Prince at a tight tolerance) and
// check its physics against closed forms: straight-line acceleration of the
// diff-drive robot, the work–energy balance of driven scenes, the
// minimum-norm wheel loads of the car (static and accelerating), the trailers
// falling in line behind the tractor.
#include <appell/kinematics.hpp>
#include <appell/simulator.hpp>
#include <appell/urdf.hpp>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <variant>
#include <cmath>
#include <string>
#include <vector>

namespace appell {
namespace {

std::string examplePath(const std::string& rel) {
  return std::string(APPELL_SOURCE_DIR) + "/examples/" + rel;
}

Mat3 rootRotation(const VecX& q) {
  return Eigen::Quaterniond(q[6], q[3], q[4], q[5]).normalized().toRotationMatrix();
}
double yaw(const VecX& q) {
  const Mat3 R = rootRotation(q);
  return std::atan2(R(1, 0), R(0, 0));
}

std::unique_ptr<Simulator> simulate(const Scene& s, Formulation f = Formulation::Tree,
                                    double rtol = 1e-10) {
  IntegratorOptions io;
  io.rtol = rtol;
  io.atol = rtol * 1e-2;
  io.h_max = 0.05;
  auto sim = std::make_unique<Simulator>(s.model, s.constraints,
                                         makeSolver(f, s.model, s.constraints),
                                         IntegratorType::DormandPrince54, io);
  if (s.tau.size() == s.model.nv && s.tau.cwiseAbs().maxCoeff() > 0) {
    const VecX tau = s.tau;
    sim->setJointForces([tau](double, const VecX&, const VecX&, VecX& out) { out = tau; });
  }
  // After the joint forces: setState evaluates λ and v̇ for reports with them.
  sim->setState(0.0, s.q0, s.v0);
  return sim;
}

struct Stats {
  double max_residual = 0, max_gap = 0;
  int max_redundant = 0, min_redundant = 1 << 30;
  long steps = 0;
};

template <class Each>
void advance(Simulator& sim, double t_end, Stats& st, Each&& each) {
  double h = 0.01;
  while (sim.time() < t_end - 1e-14) {
    const StepStatus status = sim.step(std::min(h, t_end - sim.time()));
    ASSERT_TRUE(status.ok) << "at t = " << sim.time() << ": " << status.message;
    h = status.h_next;
    ++st.steps;
    st.max_residual = std::max(st.max_residual, sim.velocityResidual());
    st.max_gap = std::max(st.max_gap, sim.gapResidual());
    st.max_redundant = std::max(st.max_redundant, sim.redundantRows());
    st.min_redundant = std::min(st.min_redundant, sim.redundantRows());
    each(sim);
  }
}
void advance(Simulator& sim, double t_end, Stats& st) {
  advance(sim, t_end, st, [](const Simulator&) {});
}

/// λ index of each contact's normal row, in contact order.
std::vector<int> normalRows(const Scene& s) {
  std::vector<int> rows;
  int offset = 0;
  for (const auto& c : s.constraints) {
    for (int r = 0; r < c->rows(); ++r)
      if (c->rowKind(r) == RowKind::Normal) rows.push_back(offset + r);
    offset += c->rows();
  }
  return rows;
}

double totalMass(const Model& m) {
  double M = 0;
  for (const Inertia& I : m.inertias) M += I.mass;
  return M;
}

int vIndex(const Scene& s, const std::string& joint) {
  const int j = s.model.jointIndex(joint);
  EXPECT_GE(j, 0) << joint;
  return s.model.joints[j].idx_v;
}
int qIndex(const Scene& s, const std::string& joint) {
  const int j = s.model.jointIndex(joint);
  EXPECT_GE(j, 0) << joint;
  return s.model.joints[j].idx_q;
}

// ---------------------------------------------------------------------------
// Differential drive.

TEST(ExampleDiffDrive, MeshesLoadFromStlAndDae) {
  const Scene s = loadScene(examplePath("diff_drive/diff_drive.urdf"));
  std::vector<std::shared_ptr<const TriangleMesh>> meshes;
  for (const char* link : {"left_wheel", "right_wheel"}) {
    const int b = s.model.bodyIndex(link);
    ASSERT_GE(b, 0);
    ASSERT_EQ(s.geometry[b].visual.size(), 1u);
    const Geometry& g = s.geometry[b].visual[0];
    ASSERT_EQ(g.type, GeometryType::Mesh);
    ASSERT_TRUE(g.mesh);
    meshes.push_back(g.mesh);
  }
  EXPECT_NE(meshes[0]->source.find("wheel.stl"), std::string::npos);
  EXPECT_NE(meshes[1]->source.find("wheel.dae"), std::string::npos);
  // The same wheel in both formats: radius 0.1 about the y axle, width 0.04,
  // every STL vertex found among the DAE vertices (DAE keeps 6 digits).
  for (const auto& m : meshes) {
    EXPECT_EQ(m->triangles.size(), 2176u);
    EXPECT_EQ(m->vertices.size(), 1090u);
    double rmax = 0, ymin = 0, ymax = 0;
    for (const Vec3& p : m->vertices) {
      rmax = std::max(rmax, std::hypot(p.x(), p.z()));
      ymin = std::min(ymin, p.y());
      ymax = std::max(ymax, p.y());
    }
    EXPECT_NEAR(rmax, 0.1, 1e-6);
    EXPECT_NEAR(ymax - ymin, 0.04, 1e-6);
  }
  double worst = 0;
  for (const Vec3& p : meshes[0]->vertices) {
    double best = 1e300;
    for (const Vec3& q : meshes[1]->vertices) best = std::min(best, (p - q).norm());
    worst = std::max(worst, best);
  }
  EXPECT_LT(worst, 1e-6);
}

TEST(ExampleDiffDrive, TyresAreToriFromTheCylinderCollisions) {
  const Scene s = loadScene(examplePath("diff_drive/diff_drive.urdf"));
  ASSERT_EQ(s.contacts.size(), 3u);
  for (int k = 0; k < 2; ++k) {
    const auto* torus = std::get_if<Torus>(&s.contacts[k]->shape());
    ASSERT_NE(torus, nullptr) << s.contacts[k]->name() << ": " << shapeName(s.contacts[k]->shape());
    EXPECT_NEAR(torus->major + torus->minor, 0.1, 1e-15);  // outer radius = the cylinder's
    EXPECT_NEAR(torus->minor, 0.02, 1e-15);
    EXPECT_NEAR(std::abs(torus->axis.dot(Vec3::UnitY())), 1.0, 1e-12);  // the axle, link frame
  }
  EXPECT_NE(std::get_if<Sphere>(&s.contacts[2]->shape()), nullptr);
  EXPECT_EQ(s.contacts[2]->kind(), ContactKind::Sliding);
}

TEST(ExampleDiffDrive, EqualTorquesDriveStraightWithTheClosedFormAcceleration) {
  const Scene s = loadScene(examplePath("diff_drive/diff_drive.urdf"));
  const int iL = vIndex(s, "left_wheel_joint"), iR = vIndex(s, "right_wheel_joint");
  const int qL = qIndex(s, "left_wheel_joint"), qR = qIndex(s, "right_wheel_joint");
  ASSERT_EQ(s.tau[iL], s.tau[iR]);
  const double tau = s.tau[iL], r = 0.1, J = 0.0025, M = totalMass(s.model);
  // Straight line: M v̇ + 2 J v̇ / r² = 2 τ / r.
  const double a = (2 * tau / r) / (M + 2 * J / (r * r));
  auto sim = simulate(s);
  EXPECT_EQ(sim->redundantRows(), 1);  // both lateral rows: the axle cannot slide
  const double E0 = sim->energy();
  double max_work_err = 0, max_yaw = 0, max_y = 0;
  Stats st;
  advance(*sim, 3.0, st, [&](const Simulator& si) {
    const double work = tau * (si.q()[qL] - s.q0[qL]) + tau * (si.q()[qR] - s.q0[qR]);
    max_work_err = std::max(max_work_err, std::abs(si.energy() - E0 - work));
    max_yaw = std::max(max_yaw, std::abs(yaw(si.q())));
    max_y = std::max(max_y, std::abs(si.q()[1]));
  });
  const double t = sim->time();
  EXPECT_NEAR(sim->q()[0], 0.5 * a * t * t, 1e-8);
  EXPECT_NEAR((rootRotation(sim->q()) * sim->v().segment<3>(3)).x(), a * t, 1e-8);
  EXPECT_NEAR(sim->v()[iL], a * t / r, 1e-7);
  EXPECT_LT(max_yaw, 1e-10);
  EXPECT_LT(max_y, 1e-10);
  EXPECT_LT(max_work_err, 1e-8 * std::abs(E0));  // E − E0 = Σ τ Δφ
  EXPECT_LT(st.max_residual, 1e-10);
  EXPECT_LT(st.max_gap, 1e-10);
}

TEST(ExampleDiffDrive, StrongerRightWheelTurnsLeft) {
  const Scene s = loadScene(examplePath("diff_drive/diff_drive_turn.urdf"));
  const int iL = vIndex(s, "left_wheel_joint"), iR = vIndex(s, "right_wheel_joint");
  const int qL = qIndex(s, "left_wheel_joint"), qR = qIndex(s, "right_wheel_joint");
  ASSERT_LT(s.tau[iL], s.tau[iR]);
  auto sim = simulate(s);
  const double E0 = sim->energy();
  double max_work_err = 0;
  Stats st;
  advance(*sim, 3.0, st, [&](const Simulator& si) {
    const double work = s.tau[iL] * (si.q()[qL] - s.q0[qL]) + s.tau[iR] * (si.q()[qR] - s.q0[qR]);
    max_work_err = std::max(max_work_err, std::abs(si.energy() - E0 - work));
  });
  // Counter-clockwise from above: positive yaw and yaw rate, and the path
  // bends toward +y.
  const Vec3 omega = rootRotation(sim->q()) * sim->v().head<3>();
  EXPECT_GT(yaw(sim->q()), 0.1);
  EXPECT_GT(omega.z(), 0.0);
  EXPECT_GT(sim->q()[1], 0.0);
  EXPECT_GT(sim->q()[0], 0.0);
  EXPECT_GT(sim->v()[iR], sim->v()[iL]);
  // The axle midpoint never slides sideways: its velocity is along the heading.
  const Vec3 vel = rootRotation(sim->q()) * sim->v().segment<3>(3);
  EXPECT_NEAR(vel.dot(rootRotation(sim->q()).col(1)), 0.0, 1e-10);
  EXPECT_LT(max_work_err, 1e-8 * std::abs(E0));
  EXPECT_LT(st.max_residual, 1e-10);
  EXPECT_LT(st.max_gap, 1e-10);
}

// ---------------------------------------------------------------------------
// Four-wheeled car: redundant rows, minimum-norm loads on all four wheels.

struct CarGeometry {
  double a = 0.4;            // wheel x = ±a
  double r = 0.15, J = 0.01125;
  double W, M, xc, zc;       // weight, mass, whole-car centre of mass (x, height)
};
CarGeometry carGeometry(const Scene& s) {
  CarGeometry c;
  c.M = totalMass(s.model);
  c.W = c.M * 9.81;
  // Centre of mass of the whole car at the initial pose (wheels: their origins).
  Vec3 mc = Vec3::Zero();
  Data data(s.model);
  forwardKinematics(s.model, data, s.q0);
  for (int i = 0; i < s.model.nbodies; ++i)
    mc += s.model.inertias[i].mass * data.oMi[i].apply(s.model.inertias[i].com);
  mc /= c.M;
  c.xc = mc.x() - s.q0[0];
  c.zc = mc.z();
  return c;
}

// Minimum-norm normal loads λᵢ = W/4 + xᵢ S / (4 a²), S = Σ xᵢ λᵢ the required
// pitch moment (wheels at x = ±a symmetric in y).
void expectPlanarLoads(const Scene& s, const VecX& lambda, double S, double W, double tol,
                       const char* when) {
  const std::vector<int> n = normalRows(s);
  ASSERT_EQ(n.size(), 4u);
  const double a = 0.4;
  for (int k = 0; k < 4; ++k) {
    const double x = s.contacts[k]->name().rfind("front", 0) == 0 ? a : -a;
    EXPECT_NEAR(lambda[n[k]], W / 4 + x * S / (4 * a * a), tol) << when << ": " << s.contacts[k]->name();
    EXPECT_GT(lambda[n[k]], 0.1 * W / 4) << when;
  }
  EXPECT_NEAR(lambda[n[0]] + lambda[n[1]] + lambda[n[2]] + lambda[n[3]], W, tol) << when;
}

TEST(ExampleCar, RedundantRowsAndMinimumNormLoadsInSteadyMotion) {
  const Scene s = loadScene(examplePath("car/car.urdf"));
  ASSERT_EQ(s.constraintRows(), 12);
  const CarGeometry c = carGeometry(s);
  EXPECT_NEAR(c.M, 24.0, 1e-12);
  EXPECT_NEAR(c.xc, 20 * 0.1 / 24, 1e-12);
  auto sim = simulate(s);
  EXPECT_EQ(sim->redundantRows(), 3);
  EXPECT_EQ(sim->dynamics().rank, 9);
  const double E0 = sim->energy(), speed0 = sim->v()[3];
  // Steady straight motion: the loads are the static ones, S = W x_c,
  // i.e. 71.1225 N front and 46.5975 N rear.
  expectPlanarLoads(s, sim->lambda(), c.W * c.xc, c.W, 1e-9 * c.W, "t = 0");
  EXPECT_NEAR(sim->lambda()[normalRows(s)[0]], 71.1225, 1e-9);
  double max_energy_dev = 0, max_load_err = 0;
  Stats st;
  advance(*sim, 2.0, st, [&](const Simulator& si) {
    max_energy_dev = std::max(max_energy_dev, std::abs(si.energy() - E0));
    for (int k : normalRows(s)) {
      const double x = s.contacts[k / 3]->name().rfind("front", 0) == 0 ? 0.4 : -0.4;
      max_load_err = std::max(max_load_err, std::abs(si.lambda()[k] - (c.W / 4 + x * c.W * c.xc / (4 * 0.16))));
    }
  });
  EXPECT_EQ(st.min_redundant, 3);
  EXPECT_EQ(st.max_redundant, 3);
  EXPECT_LT(max_load_err, 1e-9 * c.W);
  EXPECT_LT(max_energy_dev / E0, 1e-8);
  EXPECT_NEAR(sim->v()[3], speed0, 1e-10);
  EXPECT_NEAR(sim->q()[0], 2.0 * speed0, 1e-9);
  EXPECT_LT(st.max_residual, 1e-10);
  EXPECT_LT(st.max_gap, 1e-10);
}

TEST(ExampleCar, RearWheelDriveShiftsLoadToTheRear) {
  Scene s = loadScene(examplePath("car/car.urdf"));
  const double tau = 3.0;
  s.tau.setZero();
  s.tau[vIndex(s, "rear_left_joint")] = tau;
  s.tau[vIndex(s, "rear_right_joint")] = tau;
  const CarGeometry c = carGeometry(s);
  // Straight line: (M + 4 J / r²) a = 2 τ / r. Pitch balance about the ground
  // point under the axle midpoint: W x_c − Σ xᵢ λᵢ = M z_c a + 4 J a / r
  // (the car's momentum moment plus the wheels spinning up).
  const double acc = (2 * tau / c.r) / (c.M + 4 * c.J / (c.r * c.r));
  const double S = c.W * c.xc - (c.M * c.zc + 4 * c.J / c.r) * acc;
  auto sim = simulate(s);
  expectPlanarLoads(s, sim->lambda(), S, c.W, 1e-9 * c.W, "t = 0");
  Stats st;
  advance(*sim, 1.0, st);
  expectPlanarLoads(s, sim->lambda(), S, c.W, 1e-9 * c.W, "t = 1");
  const Vec3 vel = rootRotation(sim->q()) * sim->v().segment<3>(3);
  EXPECT_NEAR(vel.x(), 1.0 + acc * 1.0, 1e-8);
  EXPECT_NEAR(yaw(sim->q()), 0.0, 1e-10);
  EXPECT_EQ(st.max_redundant, 3);
  EXPECT_LT(st.max_residual, 1e-10);
}

// ---------------------------------------------------------------------------
// N-trailer (N = 3): the trailers fall in line behind the tractor.

TEST(ExampleNTrailer, TrailersFallInLineBehindThePushedTractor) {
  const Scene s = loadScene(examplePath("ntrailer/ntrailer3.urdf"));
  ASSERT_EQ(s.model.nv, 6 + 2 * 3);
  ASSERT_EQ(s.constraintRows(), 4 + 2 * 3);
  std::vector<int> hitch;
  for (int k = 1; k <= 3; ++k) hitch.push_back(qIndex(s, "hitch" + std::to_string(k) + "_yaw"));
  double start = 0;
  for (int i : hitch) start = std::max(start, std::abs(s.q0[i]));
  ASSERT_GT(start, 0.3);
  auto sim = simulate(s, Formulation::Tree, 1e-9);
  EXPECT_EQ(sim->redundantRows(), 0);
  Stats st;
  std::vector<double> half(3);
  advance(*sim, 3.0, st);
  for (int k = 0; k < 3; ++k) half[k] = std::abs(sim->q()[hitch[k]]);
  advance(*sim, 6.0, st);
  for (int k = 0; k < 3; ++k) {
    EXPECT_LT(std::abs(sim->q()[hitch[k]]), 0.01) << "hitch " << k + 1;
    EXPECT_LT(std::abs(sim->q()[hitch[k]]), half[k] + 1e-12) << "hitch " << k + 1;
  }
  // Each trailer's axle point moves along its own heading (the knife edges).
  Data data(s.model);
  forwardKinematics(s.model, data, sim->q(), sim->v());
  for (int k = 1; k <= 3; ++k) {
    const int b = s.model.bodyIndex("trailer" + std::to_string(k));
    const Vec6 pv = pointVelocity(data, b, Vec3(-0.8, 0, -0.1));
    const Vec3 lateral = data.oMi[b].R.col(1);
    const Vec3 vpt = pv.tail<3>();  // [ω; ṗ]
    EXPECT_LT(std::abs(vpt.dot(lateral)), 1e-9 * std::max(1.0, vpt.norm())) << "trailer " << k;
    EXPECT_GT(vpt.norm(), 1.0) << "trailer " << k;
  }
  EXPECT_GT(sim->q().head<2>().norm(), 3.0);  // the train went somewhere
  EXPECT_LT(st.max_residual, 1e-10);
  EXPECT_LT(st.max_gap, 1e-10);
}

TEST(ExampleNTrailer, CoastingTrainConservesEnergy) {
  Scene s = loadScene(examplePath("ntrailer/ntrailer3.urdf"));
  s.tau.setZero();
  s.v0.setZero();
  s.v0[3] = 1.0;   // tractor forward at 1 m/s (body frame)
  s.v0[2] = 0.3;   // and turning
  const InitialStateReport rep = checkInitialState(s, true);
  ASSERT_TRUE(rep.projected);
  auto sim = simulate(s);
  const double E0 = sim->energy();
  ASSERT_GT(sim->kineticEnergy(), 0.1);
  double max_dev = 0;
  Stats st;
  advance(*sim, 3.0, st, [&](const Simulator& si) { max_dev = std::max(max_dev, std::abs(si.energy() - E0)); });
  EXPECT_LT(max_dev / E0, 1e-8);
  EXPECT_LT(st.max_residual, 1e-10);
  EXPECT_LT(st.max_gap, 1e-10);
}

}  // namespace
}  // namespace appell
