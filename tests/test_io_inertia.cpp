// Inertias as CAD tools and robot vendors publish them (tests/data/io/inertia):
// what the dynamics can run loads with one warning per body, naming it and the
// size of the defect, and then runs — every formulation and CRBA agree with
// ABA, and 1 s of free fall and joint swing keeps the energy balance; what the
// solver cannot run (a massless leaf on a revolute joint: its articulated
// inertia is zero) is refused naming the joint and what to write instead. The
// opt-in repairs (balance, bound inertia, bound mass; MuJoCo's compiler
// options) change exactly the bodies they report.
#include <appell/appell.hpp>
#include <appell/dynamics.hpp>
#include <appell/run.hpp>
#include <appell/urdf.hpp>

#include "scene_helpers.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <random>

namespace appell {
namespace {

std::string dataFile(const std::string& name) {
  return std::string(APPELL_SOURCE_DIR) + "/tests/data/io/inertia/" + name;
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// The warnings that name `body`.
std::vector<std::string> warningsOf(const Scene& s, const std::string& body) {
  std::vector<std::string> out;
  for (const std::string& w : s.warnings)
    if (contains(w, "body '" + body + "'")) out.push_back(w);
  return out;
}

Vec3 principalMoments(const Inertia& I) {
  return Eigen::SelfAdjointEigenSolver<Mat3>(I.inertia_com).eigenvalues();
}

// v̇ at (q, v) by ABA, by CRBA (M v̇ = −h) and by each formulation: all agree.
void expectFormulationsAgree(const Scene& s, const VecX& q, const VecX& v) {
  const Model& m = s.model;
  Data data(m);
  const VecX zero = VecX::Zero(m.nv);
  const VecX a_aba = aba(m, data, q, v, zero);
  const MatX M = crba(m, data, q);
  const Eigen::LLT<MatX> llt(M);
  ASSERT_EQ(llt.info(), Eigen::Success) << "CRBA's mass matrix is not positive definite";
  const VecX a_crba = llt.solve(-nonLinearEffects(m, data, q, v));
  const double scale = 1 + a_aba.lpNorm<Eigen::Infinity>();
  EXPECT_LT((a_crba - a_aba).lpNorm<Eigen::Infinity>(), 1e-9 * scale) << s.source;
  const ConstraintList none;  // the joints alone: the limits' rows are the simulator's business
  for (Formulation f : {Formulation::Tree, Formulation::Multipliers, Formulation::Appell}) {
    const auto solver = makeSolver(f, m, none);
    ConstraintData cd(m, none);
    ConstrainedResult out;
    solver->solve(m, data, none, cd, q, v, zero, out);
    EXPECT_LT((out.vdot - a_aba).lpNorm<Eigen::Infinity>(), 1e-9 * scale)
        << s.source << " formulation " << toString(f);
  }
}

// 1 s of the scene's own motion (free fall of a floating base, joints
// swinging under gravity), Dormand–Prince at 1e-12, with each formulation:
// the energy balance closes to 1e-8 of the energy scale.
void expectEnergyBalance(const Scene& s) {
  for (Formulation f : {Formulation::Tree, Formulation::Multipliers, Formulation::Appell}) {
    const RunSummary r = runScene(s, test::tightRun(1.0, f));
    EXPECT_TRUE(r.ok) << s.source << " " << toString(f) << ": " << r.failure;
    EXPECT_NEAR(r.time, 1.0, 1e-12);
    EXPECT_LT(r.relativeEnergyDeviation(), 1e-8) << s.source << " " << toString(f);
  }
}

void expectRuns(const Scene& s) {
  expectFormulationsAgree(s, s.q0, s.v0);
  std::mt19937 rng(7);
  VecX v = VecX::Random(s.model.nv);
  expectFormulationsAgree(s, randomConfiguration(s.model, rng), v);
  expectEnergyBalance(s);
}

TEST(IoInertia, TriangleViolationOfACadExportLoadsWithOneWarning) {
  const Scene s = loadScene(dataFile("arm_triangle.urdf"));
  ASSERT_EQ(s.warnings.size(), 1u);
  const std::string& w = s.warnings[0];
  for (const char* part : {"arm_triangle.urdf:20: <link name=\"arm_left_1_link\">", "body 'arm_left_1_link'",
                           "principal moments 0.00155679 0.00597627 0.00777394",
                           "violate the triangle inequality by 3.09", "positive definite",
                           "raises I₁ to 0.00179767"})
    EXPECT_TRUE(contains(w, part)) << part << " in " << w;
  // The inertia is the one written: nothing is changed without being asked.
  const Vec3 d = principalMoments(s.model.inertias[s.model.bodyIndex("arm_left_1_link")]);
  EXPECT_NEAR(d(0), 0.00155679, 1e-8);
  expectRuns(s);
}

TEST(IoInertia, NearMasslessFloatingBaseWithAFixedChildLoads) {
  const Scene s = loadScene(dataFile("floating_base_fixed_child.urdf"));
  ASSERT_EQ(s.warnings.size(), 1u);
  const std::string& w = s.warnings[0];
  for (const char* part : {"<link name=\"base_link\">", "combined inertia with the fixed 'root_link'",
                           "singular inertia (mass 4.72 kg, principal moments", "3e-06)",
                           "beyond its joint 'root_joint'"})
    EXPECT_TRUE(contains(w, part)) << part << " in " << w;
  EXPECT_EQ(s.model.joints[0].type, JointType::Floating);
  expectRuns(s);
  // Free fall: the centre of mass of the whole robot falls as a point mass
  // does, z(1) = z(0) + vz(0) − g/2, whatever the joints do.
  Simulator sim(s.model, s.constraints, makeSolver(Formulation::Tree, s.model, s.constraints),
                IntegratorType::DormandPrince54, [] {
                  IntegratorOptions o;
                  o.rtol = o.atol = 1e-12;
                  return o;
                }());
  sim.setState(0, s.q0, s.v0);
  Data d(s.model);
  auto com = [&](const VecX& q, const VecX& v, Vec3& c, Vec3& cdot) {
    forwardKinematics(s.model, d, q, v);
    c.setZero();
    cdot.setZero();
    for (int i = 0; i < s.model.nbodies; ++i) {
      const Inertia& I = s.model.inertias[i];
      c += I.mass * d.oMi[i].apply(I.com);
      const Vec6& V = d.v[i];  // body frame (ω, v)
      cdot += I.mass * (d.oMi[i].R * (V.tail<3>() + V.head<3>().cross(I.com)));
    }
    c /= s.model.totalMass();
    cdot /= s.model.totalMass();
  };
  Vec3 c0, cd0, c1, cd1;
  com(s.q0, s.v0, c0, cd0);
  ASSERT_TRUE(sim.advanceTo(1.0, 1e-2).ok);
  com(sim.q(), sim.v(), c1, cd1);
  EXPECT_LT((c1 - (c0 + cd0 + 0.5 * s.model.gravity)).norm(), 1e-9);
  EXPECT_LT((cd1 - (cd0 + s.model.gravity)).norm(), 1e-9);
}

TEST(IoInertia, MasslessLinkBetweenTwoRevoluteJointsLoads) {
  const Scene s = loadScene(dataFile("massless_between_revolutes.urdf"));
  ASSERT_EQ(s.warnings.size(), 1u);
  const std::string& w = s.warnings[0];
  for (const char* part : {"<link name=\"wrist_yaw_link\">", "body 'wrist_yaw_link': massless",
                           "joint 'wrist_yaw'"})
    EXPECT_TRUE(contains(w, part)) << part << " in " << w;
  expectRuns(s);
}

TEST(IoInertia, MasslessLeafOnARevoluteJointIsRefused) {
  try {
    loadScene(dataFile("massless_leaf.urdf"));
    ADD_FAILURE() << "a massless leaf on a revolute joint loaded";
  } catch (const SceneError& e) {
    const std::string msg = e.what();
    for (const char* part :
         {"massless_leaf.urdf:24: <link name=\"finger\">: body 'finger': joint 'palm_joint' (revolute) "
          "moves no inertia: it and the bodies it carries have zero mass",
          "Sᵀ Iᴬ S, is singular", "Give 'finger' a mass and a positive definite tensor (its <inertial>), make "
          "'palm_joint' a fixed joint, or bound the inertias at load (--bound-mass, --bound-inertia)"})
      EXPECT_TRUE(contains(msg, part)) << part << " in " << msg;
  }
  // The bounds the message offers make it a body: it loads, reported.
  LoadOptions o;
  o.bound_mass = 1e-3;
  o.bound_inertia = 1e-6;
  const Scene s = loadScene(dataFile("massless_leaf.urdf"), o);
  const std::vector<std::string> w = warningsOf(s, "finger");
  ASSERT_EQ(w.size(), 1u);
  EXPECT_TRUE(contains(w[0], "repaired: mass 0 kg raised to 0.001 (bound mass); principal moments 0 0 0 "
                             "raised to at least 1e-06 kg m² (bound inertia)")) << w[0];
  const Inertia& I = s.model.inertias[s.model.bodyIndex("finger")];
  EXPECT_DOUBLE_EQ(I.mass, 1e-3);
  EXPECT_LT((principalMoments(I) - Vec3::Constant(1e-6)).norm(), 1e-18);
}

// Indefinite beyond round-off is a description error (a wrong sign), not CAD
// rounding: refused, saying what a tensor must be.
TEST(IoInertia, IndefiniteTensorIsRefused) {
  const std::string urdf = R"(<robot name="r">
  <link name="body"><inertial><mass value="1"/>
    <inertia ixx="0.01" ixy="0.02" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
</robot>)";
  const std::string msg = test::loadMessage(urdf, "sign.urdf");
  for (const char* part : {"sign.urdf:3: <inertia>", "body 'body'", "not positive semi-definite",
                           "principal moments -0.01 0.01 0.03", "a wrong sign of ixy, ixz or iyz"})
    EXPECT_TRUE(contains(msg, part)) << part << " in " << msg;
}

// --balance-inertia: I₁ raised to I₃ − I₂ along its own axis; the other
// moments, the axes, the mass and the centre of mass are kept, and the one
// warning says what changed.
TEST(IoInertia, BalanceRaisesTheSmallestMomentToTheTriangleBound) {
  LoadOptions o;
  o.balance_inertia = true;
  const Scene plain = loadScene(dataFile("arm_triangle.urdf"));
  const Scene s = loadScene(dataFile("arm_triangle.urdf"), o);
  ASSERT_EQ(s.warnings.size(), 1u);
  for (const char* part : {"body 'arm_left_1_link': repaired: smallest principal moment 0.00155679 raised "
                           "to 0.00179767 = I₃ − I₂", "broken by 3.09"})
    EXPECT_TRUE(contains(s.warnings[0], part)) << part << " in " << s.warnings[0];
  const int b = s.model.bodyIndex("arm_left_1_link");
  const Inertia &I = s.model.inertias[b], &I0 = plain.model.inertias[b];
  const Eigen::SelfAdjointEigenSolver<Mat3> e(I.inertia_com), e0(I0.inertia_com);
  EXPECT_NEAR(e.eigenvalues()(0), e.eigenvalues()(2) - e.eigenvalues()(1), 1e-15);
  EXPECT_NEAR(e.eigenvalues()(1), e0.eigenvalues()(1), 1e-15);
  EXPECT_NEAR(e.eigenvalues()(2), e0.eigenvalues()(2), 1e-15);
  EXPECT_NEAR(std::abs(e.eigenvectors().col(0).dot(e0.eigenvectors().col(0))), 1.0, 1e-12);
  EXPECT_EQ(I.mass, I0.mass);
  EXPECT_EQ(I.com, I0.com);  // nothing added but a rotational inertia
  // The other bodies are untouched.
  for (int i = 0; i < s.model.nbodies; ++i) {
    if (i != b) {
      EXPECT_EQ(s.model.inertias[i].inertia_com, plain.model.inertias[i].inertia_com);
    }
  }
}

// The scene's <simulation> carries the same repairs; LoadOptions override it.
TEST(IoInertia, SimulationElementCarriesTheRepairs) {
  std::string urdf = R"(<robot name="r">
  <link name="base"><inertial><mass value="2"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.03"/></inertial></link>
  <appell><simulation duration="1" balance_inertia="true" bound_mass="3"/></appell>
</robot>)";
  const Scene s = loadSceneFromString(urdf, ".", "sim.urdf");
  ASSERT_EQ(s.warnings.size(), 1u);
  for (const char* part : {"sim.urdf:2: <link name=\"base\">", "mass 2 kg raised to 3 (bound mass)",
                           "smallest principal moment 0.01 raised to 0.02"})
    EXPECT_TRUE(contains(s.warnings[0], part)) << part << " in " << s.warnings[0];
  EXPECT_DOUBLE_EQ(s.model.inertias[0].mass, 3.0);
  LoadOptions off;
  off.balance_inertia = false;
  off.bound_mass = 0;
  const Scene t = loadSceneFromString(urdf, ".", "sim.urdf", off);
  ASSERT_EQ(t.warnings.size(), 1u);
  EXPECT_TRUE(contains(t.warnings[0], "violate the triangle inequality by 33.3333 %")) << t.warnings[0];
  EXPECT_DOUBLE_EQ(t.model.inertias[0].mass, 2.0);
  for (const char* bad : {R"(bound_mass="-1")", R"(balance_inertia="yes")"}) {
    const std::string good = R"(balance_inertia="true" bound_mass="3")";
    std::string u = urdf;
    u.replace(u.find(good), good.size(), bad);
    EXPECT_TRUE(contains(test::loadMessage(u, "bad.urdf"), "bad.urdf:4: <simulation>")) << u;
  }
}

}  // namespace
}  // namespace appell
