// The <appell> scene block: supports and their motion, contacts and their
// shapes (from collision geometry or explicit), initial state, efforts,
// settings — and the initial-state check with its projection.
#include <appell/dynamics.hpp>
#include <appell/kinematics.hpp>
#include <appell/urdf.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <regex>
#include <string>
#include <utility>
#include <vector>

using namespace appell;

namespace {

const std::string kData = std::string(APPELL_SOURCE_DIR) + "/tests/data/io/";

template <class T>
const T& as(const Shape& s) {
  EXPECT_TRUE(std::holds_alternative<T>(s)) << "shape is " << shapeName(s);
  return std::get<T>(s);
}

}  // namespace

TEST(IoScene, BallOnTurntable) {
  const Scene s = loadScene(kData + "scenes/ball_turntable.urdf");
  EXPECT_EQ(s.source, kData + "scenes/ball_turntable.urdf");
  ASSERT_EQ(s.model.nbodies, 1);
  EXPECT_EQ(s.model.joints[0].type, JointType::Floating);
  EXPECT_TRUE(s.model.gravity.isApprox(Vec3(0, 0, -9.81)));

  ASSERT_EQ(s.supports.size(), 1u);
  EXPECT_EQ(s.supports[0].name, "table");
  const auto& plane = std::get<Plane>(s.supports[0].surface);
  EXPECT_TRUE(plane.normal.isApprox(Vec3::UnitZ()));
  ASSERT_TRUE(isMoving(s.supports[0].motion));
  // The table's material velocity at (0.5, 0, 0) is Ω × r = (0, 1, 0).
  const SupportState st = supportState(s.supports[0].motion, 0.0);
  EXPECT_TRUE(st.pointVelocity(Vec3(0.5, 0, 0)).isApprox(Vec3(0, 1, 0), 1e-15));

  ASSERT_EQ(s.contacts.size(), 1u);
  ASSERT_EQ(s.constraints.size(), 1u);
  // The contact is described once, by its constraint.
  const ShapeContact& c = *s.contacts[0];
  EXPECT_EQ(s.contacts[0], s.constraints[0]);
  EXPECT_EQ(c.name(), "ball_table");
  EXPECT_EQ(s.model.body_names[c.bodyA()], "ball");
  EXPECT_EQ(c.bodyA(), 0);
  EXPECT_EQ(c.kind(), ContactKind::Rolling);
  EXPECT_EQ(c.support().name, s.supports[0].name);
  EXPECT_DOUBLE_EQ(c.mu(), 0.6);
  EXPECT_DOUBLE_EQ(c.spec().mu, 0.6);
  EXPECT_EQ(s.contact_origins[0].shape_source, "collision[0] (sphere)");
  EXPECT_GT(s.contact_origins[0].line, 0);
  EXPECT_DOUBLE_EQ(as<Sphere>(c.shape()).radius, 0.1);
  EXPECT_EQ(s.constraints[0]->name(), "ball_table");
  EXPECT_EQ(s.constraints[0]->rows(), 3);
  EXPECT_EQ(s.constraintRows(), 3);
  EXPECT_EQ(s.contactIndex("ball_table"), 0);
  EXPECT_EQ(s.contactIndex("nope"), -1);

  // Initial state as declared, and it satisfies the moving constraint.
  ASSERT_EQ(s.q0.size(), 7);
  EXPECT_TRUE(s.q0.head<3>().isApprox(Vec3(0.5, 0, 0.1)));
  EXPECT_NEAR(s.q0(6), 1.0, 1e-15);
  EXPECT_TRUE(s.v0.isApprox((VecX(6) << 0, 0, 0, 0, 1, 0).finished()));
  Scene copy = s;
  const InitialStateReport r = checkInitialState(copy, false);
  EXPECT_LT(r.velocity_residual, 1e-14);
  EXPECT_LT(r.gap_residual, 1e-14);
  EXPECT_FALSE(r.projected);

  EXPECT_EQ(s.settings.integrator, "dopri5");
  EXPECT_DOUBLE_EQ(s.settings.dt, 0.01);
  EXPECT_DOUBLE_EQ(s.settings.tol, 1e-9);
  EXPECT_DOUBLE_EQ(s.settings.duration, 12.5);
  EXPECT_EQ(s.settings.formulation, "kkt");
  EXPECT_TRUE(s.tau.isZero());
}

TEST(IoScene, SleighKnifeEdgeAndSlidingFeet) {
  const Scene s = loadScene(kData + "scenes/sleigh.urdf");
  ASSERT_EQ(s.contacts.size(), 3u);
  EXPECT_EQ(s.contacts[0]->kind(), ContactKind::KnifeEdge);
  EXPECT_EQ(s.contact_origins[0].shape_source, "explicit");
  EXPECT_TRUE(as<PointShape>(s.contacts[0]->shape()).position.isZero());
  EXPECT_TRUE(s.contacts[0]->spec().options.blade_direction.isApprox(Vec3(2, 0, 0)));
  EXPECT_TRUE(s.contacts[0]->bladeDirection().isApprox(Vec3(1, 0, 0)));
  EXPECT_EQ(s.constraints[0]->rows(), 2);
  EXPECT_EQ(s.constraints[0]->rowLabel(0), "lateral");
  EXPECT_EQ(s.constraints[0]->rowKind(0), RowKind::Lateral);
  EXPECT_EQ(s.contacts[1]->kind(), ContactKind::Sliding);
  EXPECT_TRUE(as<PointShape>(s.contacts[1]->shape()).position.isApprox(Vec3(0.6, 0.2, 0)));
  EXPECT_EQ(s.constraints[1]->rows(), 1);
  EXPECT_EQ(s.constraintRows(), 4);
  EXPECT_TRUE(std::isinf(s.contacts[1]->mu()));
  // The tilted initial orientation puts all three points on the slope.
  Scene copy = s;
  EXPECT_LT(checkInitialState(copy, false).gap_residual, 1e-14);
  // Efforts: generalized forces on the floating base (body-frame torque z 0.5).
  ASSERT_EQ(s.tau.size(), 6);
  EXPECT_TRUE(s.tau.isApprox((VecX(6) << 0, 0, 0.5, 0, 0, 0).finished()));
  EXPECT_EQ(s.settings.integrator, "rk4");
  EXPECT_EQ(s.settings.formulation, "tree");  // the default
}

TEST(IoScene, ShapesFromCollisionGeometryAndExplicit) {
  LoadOptions opt;
  opt.check_initial_state = false;  // the shapes are what matters here
  const Scene s = loadScene(kData + "scenes/shapes.urdf", opt);
  ASSERT_EQ(s.model.nbodies, 2);
  EXPECT_EQ(s.model.parent[1], -1);  // two floating bodies under the world
  ASSERT_EQ(s.contacts.size(), 7u);

  // Plane given by a point and an unnormalised normal; conveyor motion.
  const auto& ground = std::get<Plane>(s.supports[0].surface);
  EXPECT_TRUE(ground.normal.isApprox(Vec3::UnitZ()));
  EXPECT_TRUE(ground.point.isApprox(Vec3(0, 0, -1)));
  EXPECT_TRUE(supportState(s.supports[0].motion, 1.0).V.tail<3>().isApprox(Vec3(0.5, 0, 0)));
  const auto& bowl = std::get<SphereSurface>(s.supports[1].surface);
  EXPECT_EQ(bowl.side, SphereSurface::Side::Inside);
  EXPECT_DOUBLE_EQ(bowl.radius, 2);
  const auto& globe = std::get<SphereSurface>(s.supports[2].surface);
  EXPECT_EQ(globe.side, SphereSurface::Side::Outside);
  const auto& tilt = std::get<SinusoidalTiltMotion>(s.supports[2].motion);
  EXPECT_DOUBLE_EQ(tilt.amplitude, 0.1);
  EXPECT_DOUBLE_EQ(tilt.frequency, 3);
  EXPECT_DOUBLE_EQ(tilt.phase, 0.5);
  EXPECT_TRUE(std::get<ConstantTwistMotion>(s.supports[3].motion).twist.head<3>().isApprox(Vec3::UnitZ()));

  // A cylinder collision is a disk rim in its mid-plane, axle along its z.
  const Disk& rim = as<Disk>(s.contacts[0]->shape());
  EXPECT_EQ(s.contact_origins[0].shape_source, "collision[0] (cylinder 'tread')");
  EXPECT_DOUBLE_EQ(rim.radius, 0.3);
  EXPECT_TRUE(rim.centre.isApprox(Vec3(0, 0.01, 0)));
  EXPECT_TRUE(rim.axis.isApprox(Vec3(0, -1, 0), 1e-15));
  EXPECT_EQ(s.contacts[0]->kind(), ContactKind::RollingWithoutSpin);
  EXPECT_EQ(s.constraints[0]->rows(), 4);
  // … or a torus with the same outer radius when a tyre radius is given.
  const Torus& tyre = as<Torus>(s.contacts[1]->shape());
  EXPECT_DOUBLE_EQ(tyre.minor, 0.04);
  EXPECT_NEAR(tyre.major + tyre.minor, 0.3, 1e-15);
  // Selected by index.
  EXPECT_DOUBLE_EQ(as<Sphere>(s.contacts[2]->shape()).radius, 0.05);
  EXPECT_EQ(s.contacts[2]->support().name, "bowl");
  // Explicit ellipsoid with orientation.
  const Ellipsoid& egg = as<Ellipsoid>(s.contacts[3]->shape());
  EXPECT_TRUE(egg.semi_axes.isApprox(Vec3(0.1, 0.2, 0.3)));
  EXPECT_TRUE(egg.centre.isApprox(Vec3(0, 0, 0.01)));
  EXPECT_TRUE((egg.orientation * Vec3::UnitX()).isApprox(Vec3::UnitY(), 1e-15));
  EXPECT_EQ(s.contacts[3]->bodyA(), 1);
  // Hemisphere: cap on the −z side by default.
  const SphericalCap& cap = as<SphericalCap>(s.contacts[4]->shape());
  EXPECT_DOUBLE_EQ(cap.radius, 0.2);
  EXPECT_NEAR(cap.half_angle, M_PI / 2, 1e-15);
  EXPECT_TRUE(cap.axis.isApprox(-Vec3::UnitZ()));
  // Explicit torus: radius is the outer radius.
  const Torus& t = as<Torus>(s.contacts[5]->shape());
  EXPECT_NEAR(t.major, 0.2, 1e-15);
  EXPECT_DOUBLE_EQ(t.minor, 0.1);
  EXPECT_TRUE(t.axis.isApprox(Vec3::UnitY()));
  // A knife edge on a disk takes its blade from the wheel plane.
  EXPECT_EQ(s.contacts[6]->kind(), ContactKind::KnifeEdge);
  EXPECT_EQ(s.constraints[6]->rows(), 2);
}

TEST(IoScene, ProjectionOfASlidingBallGivesFiveSevenths) {
  // The ball touches the plane, sliding at 1 m/s without spin. Projection
  // puts it, in the mass metric, onto rolling:
  // min m|v − v₀|² + I ω² subject to v = r ω gives v = v₀ m r² /(m r² + I)
  // = 5/7 for a homogeneous ball — the classic result (the impulse at the
  // contact conserves angular momentum about the contact point).
  LoadOptions opt;
  opt.project_initial_state = true;
  const Scene s = loadScene(kData + "bad/initial_violation.urdf", opt);
  EXPECT_NEAR(s.q0(2), 0.1, 1e-12);
  EXPECT_TRUE(s.q0.head<2>().isZero(1e-12));
  EXPECT_NEAR(s.q0.tail<4>().head<3>().norm(), 0.0, 1e-12);  // orientation unchanged
  EXPECT_NEAR(s.v0(3), 5.0 / 7.0, 1e-12);  // v_x (body frame)
  EXPECT_NEAR(s.v0(1), 5.0 / 7.0 / 0.1, 1e-10);              // ω_y = v_x / r
  EXPECT_NEAR(s.v0(0), 0, 1e-12);
  EXPECT_NEAR(s.v0(2), 0, 1e-12);
  EXPECT_NEAR(s.v0(5), 0, 1e-12);

  Scene again = s;
  const InitialStateReport r = checkInitialState(again, false);
  EXPECT_LT(r.velocity_residual, 1e-12);
  EXPECT_LT(r.gap_residual, 1e-12);
}

TEST(IoScene, LoadFromStringResolvesAgainstBaseDir) {
  const std::string xml = R"(<robot name="s">
    <link name="b"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
      <visual><geometry><mesh filename="meshes/cube.obj"/></geometry></visual></link>
    <appell><gravity xyz="0 0 -1.62"/></appell></robot>)";
  const Scene s = loadSceneFromString(xml, kData, "moon");
  EXPECT_EQ(s.source, "moon");
  EXPECT_TRUE(s.model.gravity.isApprox(Vec3(0, 0, -1.62)));
  EXPECT_EQ(s.geometry[0].visual[0].mesh->triangles.size(), 12u);
  // From the wrong folder the (visual) mesh is not found: a warning naming it.
  const Scene elsewhere = loadSceneFromString(xml, "/nonexistent", "moon");
  ASSERT_EQ(elsewhere.warnings.size(), 1u);
  EXPECT_EQ(elsewhere.warnings[0].rfind("moon:3: <mesh>:", 0), 0u) << elsewhere.warnings[0];
  EXPECT_NE(elsewhere.warnings[0].find("/nonexistent/meshes/cube.obj"), std::string::npos);
}

TEST(IoScene, CollisionShapesForCollisionDetection) {
  LoadOptions opt;
  opt.check_initial_state = false;
  const Scene s = loadScene(kData + "scenes/shapes.urdf", opt);
  const auto shapes = collisionShapes(s.geometry[0]);
  ASSERT_EQ(shapes.size(), 2u);
  const Cylinder& c = as<Cylinder>(shapes[0]);
  EXPECT_DOUBLE_EQ(c.radius, 0.3);
  EXPECT_DOUBLE_EQ(c.length, 0.05);
  EXPECT_TRUE(c.pose.p.isApprox(Vec3(0, 0.01, 0)));
  EXPECT_DOUBLE_EQ(as<Sphere>(shapes[1]).radius, 0.05);
  const Scene sl = loadScene(kData + "scenes/sleigh.urdf");
  EXPECT_TRUE(as<Box>(collisionShapes(sl.geometry[0])[0]).half_extents.isApprox(Vec3(0.4, 0.2, 0.025)));
}

// Protects the static and kinetic coefficients of the scene block: both
// read into the contact (μ the static one), and every inconsistent
// combination refused by line and reason.
TEST(IoScene, StaticAndKineticFrictionCoefficients) {
  auto scene = [](const std::string& friction) {
    return R"(<robot name="s">
  <link name="ball"><inertial><mass value="1"/><inertia ixx="0.004" ixy="0" ixz="0" iyy="0.004" iyz="0" izz="0.004"/></inertial><collision><geometry><sphere radius="0.1"/></geometry></collision></link>
  <appell>
    <support name="ground" type="plane"/>
    <contact name="foot" link="ball" kind="rolling" support="ground" )" +
           friction + R"(/>
    <initial><joint name="root_joint" xyz="0 0 0.1"/></initial>
  </appell>
</robot>)";
  };
  const Scene s = loadSceneFromString(scene(R"(mu_static="0.6" mu_kinetic="0.4")"), kData, "two");
  EXPECT_DOUBLE_EQ(s.contacts[0]->friction(), 0.6);
  EXPECT_DOUBLE_EQ(s.contacts[0]->kineticFriction(), 0.4);
  const Scene one = loadSceneFromString(scene(R"(mu="0.5")"), kData, "one");
  EXPECT_DOUBLE_EQ(one.contacts[0]->kineticFriction(), 0.5) << "one coefficient for both";
  EXPECT_TRUE(std::isnan(one.contacts[0]->spinFriction())) << "no spin friction unless declared";
  // Spin friction: a length, on a contact with a spin row and a finite μ.
  auto spinning = [&](const std::string& attrs) {
    return std::regex_replace(scene(attrs), std::regex(R"(kind="rolling")"), R"(kind="rolling_without_spin")");
  };
  const Scene creep = loadSceneFromString(scene(R"(mu="0.5" creep_speed="0.05")"), kData, "creep");
  EXPECT_DOUBLE_EQ(creep.contacts[0]->creepSpeed(), 0.05);
  EXPECT_EQ(one.contacts[0]->creepSpeed(), 0) << "Coulomb with sticking unless declared";
  const Scene spin = loadSceneFromString(spinning(R"(mu="0.5" mu_spin="0.01")"), kData, "spin");
  EXPECT_DOUBLE_EQ(spin.contacts[0]->spinFriction(), 0.01);
  for (const std::string& attrs : {std::string(R"(mu_spin="0.01")"), std::string(R"(mu="0" mu_spin="0.01")")}) {
    try {
      loadSceneFromString(spinning(attrs), kData, "bad");
      ADD_FAILURE() << attrs << " accepted";
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find("'mu_spin' needs a finite 'mu' > 0"), std::string::npos) << e.what();
    }
  }
  for (const auto& [attrs, why] : std::vector<std::pair<std::string, std::string>>{
           {R"(mu="0.5" mu_static="0.6" mu_kinetic="0.4")", "give either 'mu' or 'mu_static'"},
           {R"(mu_kinetic="0.4")", "'mu_static' and 'mu_kinetic' go together"},
           {R"(mu_static="0.3" mu_kinetic="0.4")", "'mu_kinetic' must not exceed 'mu_static'"},
           {R"(mu_static="0.3" mu_kinetic="-1")", "must not be negative"},
           {R"(mu="0.5" mu_spin="-0.01")", "'mu_spin' must be a positive length"},
           {R"(mu="0.5" mu_spin="0.01")", "'mu_spin' needs kind=\"rolling_without_spin\""},
           {R"(mu="0.5" creep_speed="0")", "'creep_speed' must be a positive slip speed"},
           {R"(mu="0.5" creep_speed="-0.1")", "'creep_speed' must be a positive slip speed"},
           {R"(creep_speed="0.1")", "'creep_speed' needs a finite 'mu' > 0"},
           {R"(mu="0" creep_speed="0.1")", "'creep_speed' needs a finite 'mu' > 0"},
           {R"(mu_static="0.6" mu_kinetic="0.4" creep_speed="0.1")", "'creep_speed' takes one coefficient 'mu'"},
           {R"(mu="0.5" creep_speed="0.1" unilateral="false")", "a creep speed needs a unilateral contact"}}) {
    try {
      loadSceneFromString(scene(attrs), kData, "bad");
      ADD_FAILURE() << attrs << " accepted";
    } catch (const SceneError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind("bad:5: <contact name=\"foot\">", 0), 0u) << what;
      EXPECT_NE(what.find(why), std::string::npos) << what;
    }
  }
}
