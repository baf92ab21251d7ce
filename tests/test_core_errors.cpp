// Bad model input is rejected by ModelBuilder::build() with a ModelError that
// names the body and the reason — never a crash, never a model that silently
// computes nonsense. Each case also has its valid neighbour, so a check that
// rejects everything would fail here too.
#include <appell/appell.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>

using namespace appell;

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

Inertia good() { return {1.0, Vec3(0.1, 0, 0), Vec3(0.2, 0.3, 0.4).asDiagonal()}; }

/// A two-body model: "base" (revolute from the world) and "arm", where `edit`
/// may spoil the arm's entry before it is added.
struct ArmSpec {
  int parent = 0;
  SE3 placement = SE3::Identity();
  JointType type = JointType::Revolute;
  Vec3 axis = Vec3::UnitZ();
  Inertia inertia = good();
};

Model build(const std::function<void(ArmSpec&)>& edit) {
  ModelBuilder b;
  b.addBody("base", -1, SE3::Identity(), JointType::Revolute, Vec3::UnitX(), good());
  ArmSpec s;
  edit(s);
  b.addBody("arm", s.parent, s.placement, s.type, s.axis, s.inertia);
  return b.build();
}

/// Builds, expects a ModelError whose message contains every fragment.
void expectError(const std::function<void(ArmSpec&)>& edit,
                 const std::vector<std::string>& fragments) {
  try {
    build(edit);
    ADD_FAILURE() << "no error; expected one mentioning '" << fragments.back() << "'";
  } catch (const ModelError& e) {
    const std::string msg = e.what();
    for (const auto& f : fragments)
      EXPECT_NE(msg.find(f), std::string::npos) << "message '" << msg << "' lacks '" << f << "'";
  }
}

}  // namespace

TEST(CoreErrors, ValidModelBuilds) {
  EXPECT_NO_THROW(build([](ArmSpec&) {}));
  // Massless bodies are fine where they cannot make the dynamics singular: a
  // fixed attachment (sensor frame), or a moving link that carries mass.
  ModelBuilder b;
  const int base = b.addBody("base", -1, SE3::Identity(), JointType::Revolute, Vec3::UnitX(), good());
  b.addBody("sensor", base, SE3::Identity(), JointType::Fixed, Vec3::UnitZ(), Inertia{});
  const int link = b.addBody("massless_link", base, SE3::Identity(), JointType::Revolute,
                             Vec3::UnitY(), Inertia{});
  SE3 X;
  X.p = Vec3(0, 0, 0.5);
  b.addBody("payload", link, X, JointType::Revolute, Vec3::UnitY(), good());
  EXPECT_NO_THROW(b.build());
  // A flat disk sits exactly on the triangle inequality (I₁ + I₂ = I₃).
  EXPECT_NO_THROW(build([](ArmSpec& s) { s.inertia.inertia_com = Vec3(1, 1, 2).asDiagonal(); }));
}

TEST(CoreErrors, NegativeMass) {
  expectError([](ArmSpec& s) { s.inertia.mass = -1.0; }, {"'arm'", "negative mass"});
}

TEST(CoreErrors, ZeroMassOnAMovingLeaf) {
  expectError([](ArmSpec& s) { s.inertia = Inertia{}; }, {"'arm'", "zero mass"});
  // … also when the leaf is reached through a massless fixed child.
  ModelBuilder b;
  b.addBody("base", -1, SE3::Identity(), JointType::Revolute, Vec3::UnitX(), good());
  b.addBody("hand", 0, SE3::Identity(), JointType::Prismatic, Vec3::UnitX(), Inertia{});
  b.addBody("tip", 1, SE3::Identity(), JointType::Fixed, Vec3::UnitX(), Inertia{});
  try {
    b.build();
    ADD_FAILURE() << "massless moving subtree accepted";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("'hand'"), std::string::npos) << e.what();
  }
}

// A massless body may move only if what it carries resists its motion in every
// direction; otherwise the mass matrix is singular and ABA would return huge
// numbers silently.
TEST(CoreErrors, MasslessBodyWhoseMotionMeetsNoInertia) {
  {
    ModelBuilder b;  // free-floating massless frame + wheel: they can counter-rotate
    b.addBody("virtual_base", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(), Inertia{});
    b.addBody("wheel", 0, SE3::Identity(), JointType::Revolute, Vec3::UnitZ(), good());
    try {
      b.build();
      ADD_FAILURE() << "singular model accepted";
    } catch (const ModelError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("'virtual_base'"), std::string::npos) << msg;
      EXPECT_NE(msg.find("singular"), std::string::npos) << msg;
    }
  }
  {
    ModelBuilder b;  // two coaxial revolutes through one point, the first massless
    b.addBody("hub", -1, SE3::Identity(), JointType::Revolute, Vec3::UnitY(), Inertia{});
    b.addBody("rotor", 0, SE3::Identity(), JointType::Revolute, Vec3::UnitY(), good());
    EXPECT_THROW(b.build(), ModelError);
  }
  {
    ModelBuilder b;  // the usual URDF massless base_link rigidly carrying the mass: fine
    b.addBody("base_link", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(), Inertia{});
    b.addBody("chassis", 0, SE3::Identity(), JointType::Fixed, Vec3::UnitZ(), good());
    b.addBody("wheel", 1, SE3::Identity(), JointType::Revolute, Vec3::UnitZ(), good());
    EXPECT_NO_THROW(b.build());
  }
}

/// Builds with notes; returns them.
std::vector<std::string> notesOf(const std::function<void(ArmSpec&)>& edit) {
  ModelBuilder b;
  b.addBody("base", -1, SE3::Identity(), JointType::Revolute, Vec3::UnitX(), good());
  ArmSpec s;
  edit(s);
  b.addBody("arm", s.parent, s.placement, s.type, s.axis, s.inertia);
  std::vector<std::string> notes;
  b.build(&notes);
  return notes;
}

// A massless rotor with rotational inertia (a motor's reflected inertia) is a
// positive semi-definite spatial inertia: it runs where its joint's motion
// meets inertia — fixed to a massive body, or turning about an axis it has a
// moment about — and is refused on a prismatic joint, whose motion it does not resist.
TEST(CoreErrors, ZeroMassWithRotationalInertia) {
  EXPECT_TRUE(notesOf([](ArmSpec& s) { s.inertia.mass = 0; s.type = JointType::Fixed; }).empty());
  const auto notes = notesOf([](ArmSpec& s) { s.inertia.mass = 0; });
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("body 'arm': massless"), std::string::npos) << notes[0];
  expectError([](ArmSpec& s) { s.inertia.mass = 0; s.type = JointType::Prismatic; },
              {"'arm'", "joint 'arm_joint' (prismatic) moves no inertia", "have zero mass"});
}

TEST(CoreErrors, InertiaNotPositiveSemiDefinite) {
  expectError([](ArmSpec& s) { s.inertia.inertia_com = Vec3(0.2, -0.3, 0.4).asDiagonal(); },
              {"'arm'", "not positive semi-definite", "principal moments -0.3 0.2 0.4"});
  // Round-off below zero is zero: a flat body, singular but carried by its
  // joint (the zero moment is about y, the joint turns about z).
  const auto notes = notesOf([](ArmSpec& s) { s.inertia.inertia_com = Vec3(0.2, -1e-18, 0.2).asDiagonal(); });
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("body 'arm': singular inertia (mass 1 kg, principal moments -1e-18 0.2 0.2)"),
            std::string::npos)
      << notes[0];
  // About its zero moment's axis, with the centre of mass on it, nothing resists.
  expectError([](ArmSpec& s) {
    s.inertia.inertia_com = Vec3(0.2, 0.0, 0.2).asDiagonal();
    s.inertia.com.setZero();
    s.axis = Vec3::UnitY();
  }, {"'arm'", "moves no inertia", "singular"});
}

TEST(CoreErrors, TriangleInequalityIsANote) {
  // Rotated, so the check must work on principal moments, not the diagonal.
  const auto notes = notesOf([](ArmSpec& s) {
    const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    s.inertia.inertia_com = R * Vec3(1.0, 1.0, 2.5).asDiagonal() * R.transpose();
  });
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("body 'arm': principal moments 1 1 2.5 violate the triangle inequality by 20 %"),
            std::string::npos)
      << notes[0];
}

TEST(CoreErrors, AsymmetricInertia) {
  expectError([](ArmSpec& s) { s.inertia.inertia_com(0, 1) = 0.05; }, {"'arm'", "not symmetric"});
}

TEST(CoreErrors, NonFiniteNumbers) {
  expectError([](ArmSpec& s) { s.inertia.mass = kNaN; }, {"'arm'", "non-finite"});
  expectError([](ArmSpec& s) { s.inertia.com.y() = kInf; }, {"'arm'", "non-finite"});
  expectError([](ArmSpec& s) { s.inertia.inertia_com(2, 2) = kNaN; }, {"'arm'", "non-finite"});
  expectError([](ArmSpec& s) { s.placement.p.x() = kNaN; }, {"'arm'", "placement is not finite"});
  expectError([](ArmSpec& s) { s.placement.R(1, 1) = kNaN; }, {"'arm'", "placement is not finite"});
  expectError([](ArmSpec& s) { s.axis.z() = kNaN; }, {"'arm'", "axis"});
  ModelBuilder b;
  b.addBody("base", -1, SE3::Identity(), JointType::Revolute, Vec3::UnitX(), good());
  b.setGravity(Vec3(0, 0, kNaN));
  EXPECT_THROW(b.build(), ModelError);
}

TEST(CoreErrors, ZeroAxis) {
  for (JointType t : {JointType::Revolute, JointType::Continuous, JointType::Prismatic,
                      JointType::Planar})
    expectError([t](ArmSpec& s) { s.type = t; s.axis = Vec3::Zero(); }, {"'arm'", "axis is zero"});
  // A non-unit axis is normalised, not rejected.
  EXPECT_NO_THROW(build([](ArmSpec& s) { s.axis = Vec3(0, 0, 3.0); }));
}

TEST(CoreErrors, BadParentIndex) {
  expectError([](ArmSpec& s) { s.parent = 5; }, {"'arm'", "parent index 5"});
  expectError([](ArmSpec& s) { s.parent = 1; }, {"'arm'", "parent index 1"});  // itself
  expectError([](ArmSpec& s) { s.parent = -2; }, {"'arm'", "parent index -2"});
}

TEST(CoreErrors, PlacementRotationNotOrthonormal) {
  expectError([](ArmSpec& s) { s.placement.R(0, 0) = 1.1; }, {"'arm'", "orthonormal"});
}

TEST(CoreErrors, DuplicateNames) {
  ModelBuilder b;
  b.addBody("base", -1, SE3::Identity(), JointType::Revolute, Vec3::UnitX(), good());
  b.addBody("base", 0, SE3::Identity(), JointType::Revolute, Vec3::UnitX(), good());
  EXPECT_THROW(b.build(), ModelError);
  ModelBuilder c;
  c.addBody("a", -1, SE3::Identity(), JointType::Revolute, Vec3::UnitX(), good(), "j");
  c.addBody("b", 0, SE3::Identity(), JointType::Revolute, Vec3::UnitX(), good(), "j");
  try {
    c.build();
    ADD_FAILURE() << "duplicate joint name accepted";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("'j'"), std::string::npos) << e.what();
  }
}

TEST(CoreErrors, UnknownIntegratorName) {
  try {
    integratorFromString("adams_bashforth");
    ADD_FAILURE() << "unknown integrator accepted";
  } catch (const std::invalid_argument& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("adams_bashforth"), std::string::npos);
    EXPECT_NE(msg.find("dopri5"), std::string::npos);
  }
  EXPECT_EQ(integratorFromString("rk4"), IntegratorType::RK4);
}

// Duplicate joint and body names are found in one pass (hash sets, not every
// pair) and named; a 10⁵-link chain builds (0.2 s; the pairwise checks took
// minutes).
TEST(CoreErrors, DuplicateJointNamesAndLongChains) {
  const Inertia link{1.0, Vec3(0, 0, -0.5), Vec3(0.1, 0.1, 0.01).asDiagonal()};
  {
    ModelBuilder b;
    b.addBody("a", -1, SE3::Identity(), JointType::Revolute, Vec3::UnitY(), link, "j");
    b.addBody("b", 0, SE3::Identity(), JointType::Revolute, Vec3::UnitY(), link, "j");
    try {
      b.build();
      ADD_FAILURE() << "two joints named j accepted";
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find("joint name 'j' is used twice"), std::string::npos) << e.what();
    }
  }
  ModelBuilder b;
  SE3 X;
  X.p = Vec3(0, 0, -1);
  int parent = -1;
  for (int i = 0; i < 100000; ++i)
    parent = b.addBody("l" + std::to_string(i), parent, parent < 0 ? SE3::Identity() : X, JointType::Revolute,
                       Vec3::UnitY(), link, "j" + std::to_string(i));
  const Model m = b.build();
  EXPECT_EQ(m.nbodies, 100000);
  EXPECT_EQ(m.nv, 100000);
  EXPECT_EQ(m.jointIndex("j99999"), 99999);
}
