// The bipeds of examples/biped: biped.urdf (box soles, four corner contacts
// per foot) and biped_mesh_feet.urdf (the same robot on CAD mesh soles
// declared with shape="collision": 28 coplanar hull vertices per foot touch
// at once). Each is dropped from 0.02 m with its position servos and joint
// limits on, under the default contact scheme, and checked against closed
// forms and against each other:
//   - touchdown near t = √(2h/g), approaching near √(2gh), every sole vertex at once;
//   - 5 s run to the end, event-driven throughout (no time-stepping window),
//     no slip after landing, the work balance closed;
//   - at rest each foot carries half the weight (mirror symmetry), in sum m g;
//   - the two bipeds stand at the same pose: the servos' static deflection
//     does not depend on the footprint while both soles are flat on the floor.
#include <appell/run.hpp>
#include <appell/simulator.hpp>
#include <appell/urdf.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace appell {
namespace {

constexpr double kDrop = 0.02;  // the soles' height above the floor at t = 0 (m)

struct Stand {
  RunSummary summary;
  VecX q;                         // the final configuration
  double left = 0, right = 0;     // the feet's total normal loads at the end (N)
  double mass = 0, g = 0;
};

Stand dropAndStand(const std::string& file) {
  const Scene scene = loadScene(std::string(APPELL_SOURCE_DIR) + "/examples/biped/" + file);
  Stand s;
  for (const Inertia& I : scene.model.inertias) s.mass += I.mass;
  s.g = scene.model.gravity.norm();
  const RunOptions options = runOptions(scene.settings);
  s.summary = runScene(scene, options, [&](const Simulator& sim) {
    s.q = sim.q();
    s.left = s.right = 0;
    int offset = 0;
    for (int k = 0; k < static_cast<int>(scene.constraints.size()); ++k) {
      const Constraint& c = *scene.constraints[k];
      const bool left = c.name().rfind("left_sole", 0) == 0, right = c.name().rfind("right_sole", 0) == 0;
      for (int r = 0; r < c.rows(); ++r)
        if ((left || right) && c.rowKind(r) == RowKind::Normal && sim.isClosed(k))
          (left ? s.left : s.right) += sim.lambda()[offset + r];
      offset += c.rows();
    }
  });
  return s;
}

void expectLandsAndStands(const Stand& s, int vertices_per_sole) {
  const RunSummary& r = s.summary;
  ASSERT_TRUE(r.ok) << r.failure;
  EXPECT_DOUBLE_EQ(r.time, 5.0);
  EXPECT_EQ(r.counters.windows, 0) << "event-driven throughout";
  EXPECT_LT(r.relativeEnergyDeviation(), 1e-8);
  // The drop: every vertex of both soles touches down at one instant, near
  // the free fall's time and speed — not exactly at them: the centre of mass
  // falls freely, but in flight the unloaded servos move the legs by a few
  // µm (measured: touchdown 4.9e-7 s late, 4.8e-6 m/s faster).
  const double t_land = std::sqrt(2 * kDrop / s.g), v_land = std::sqrt(2 * s.g * kDrop);
  int touchdowns = 0;
  double first = 1e300, last = -1e300;
  for (const RunEvent& e : r.events) {
    EXPECT_NE(e.kind, ContactEventKind::Slip) << e.contact << " at t = " << e.t;
    if (e.kind != ContactEventKind::Touchdown || e.t > 1.5 * t_land) continue;
    ++touchdowns;
    first = std::min(first, e.t);
    last = std::max(last, e.t);
    EXPECT_NEAR(e.t, t_land, 1e-5 * t_land) << e.contact;
    EXPECT_NEAR(e.speed_before, -v_land, 1e-5 * v_land) << e.contact;
    EXPECT_NEAR(e.speed_after, 0.0, 1e-12) << e.contact;
  }
  EXPECT_EQ(touchdowns, 2 * vertices_per_sole);
  EXPECT_EQ(first, last) << "the soles land flat: one event time";
  // At rest: the weight, shared equally by the mirror-image legs.
  const double weight = s.mass * s.g;
  EXPECT_NEAR(s.left + s.right, weight, 1e-6 * weight);
  EXPECT_NEAR(s.left, s.right, 1e-9 * weight);
}

TEST(ExampleBiped, BoxSolesLandAtOnceAndStand) {
  expectLandsAndStands(dropAndStand("biped.urdf"), 4);
}

TEST(ExampleBiped, MeshSolesLandAtOnceAndStandAtTheBoxSolesPose) {
  const Stand mesh = dropAndStand("biped_mesh_feet.urdf");
  expectLandsAndStands(mesh, 28);
  const Stand box = dropAndStand("biped.urdf");
  ASSERT_EQ(mesh.q.size(), box.q.size());
  EXPECT_LT((mesh.q - box.q).lpNorm<Eigen::Infinity>(), 1e-8)
      << "mesh " << mesh.q.transpose() << "\nbox  " << box.q.transpose();
}

}  // namespace
}  // namespace appell
