// Trajectory CSV: one named column per number, values that read back exactly.
#include <appell/output.hpp>
#include <appell/urdf.hpp>

#include <gtest/gtest.h>

#include <cstdlib>
#include <sstream>

using namespace appell;

namespace {

const std::string kData = std::string(APPELL_SOURCE_DIR) + "/tests/data/io/";

std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') cur += '"', ++i;
      else if (c == '"') quoted = false;
      else cur += c;
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  out.push_back(cur);
  return out;
}

}  // namespace

TEST(IoOutput, ColumnsNameEveryJointCoordinateAndContactRow) {
  const Scene s = loadScene(kData + "scenes/ball_turntable.urdf");
  const auto cols = trajectoryColumns(s.model, s.constraints);
  const std::vector<std::string> expected = {
      "time",
      "q:root_joint.x", "q:root_joint.y", "q:root_joint.z",
      "q:root_joint.qx", "q:root_joint.qy", "q:root_joint.qz", "q:root_joint.qw",
      "v:root_joint.wx", "v:root_joint.wy", "v:root_joint.wz",
      "v:root_joint.vx", "v:root_joint.vy", "v:root_joint.vz",
      "energy", "residual",
      "point:ball_table.x", "point:ball_table.y", "point:ball_table.z",
      "normal:ball_table.x", "normal:ball_table.y", "normal:ball_table.z",
      "lambda:ball_table.tangent1", "lambda:ball_table.tangent2", "lambda:ball_table.normal",
      "closed:ball_table", "event:ball_table"};  // a unilateral contact's mode and events
  EXPECT_EQ(cols, expected);

  const Model m = loadUrdfModel(kData + "all_joints.urdf");
  const auto c2 = trajectoryColumns(m, {});
  EXPECT_EQ(static_cast<int>(c2.size()), 1 + m.nq + m.nv + 2);
  EXPECT_EQ(c2[1 + 7], "q:rev");
  EXPECT_EQ(c2[1 + 10], "q:plan.x");
  EXPECT_EQ(c2[1 + 12], "q:plan.theta");
  EXPECT_EQ(c2[1 + m.nq + 6 + 3 + 2], "v:plan.omega");
}

TEST(IoOutput, SamplesReadBackExactly) {
  const Scene s = loadScene(kData + "scenes/ball_turntable.urdf");
  Data data(s.model);
  ConstraintData cd(s.model, s.constraints);
  evaluateConstraints(s.model, data, s.constraints, cd, 0.0, s.q0, s.v0);
  std::vector<ContactFrame> frames;
  for (const auto& b : cd.blocks) frames.push_back(b.frame);
  VecX lambda(3);
  lambda << 0.1 / 3.0, -2e-17, 9.81;

  std::ostringstream out;
  TrajectoryWriter w(out, s);
  w.write(0.0, s.q0, s.v0, 1.0 / 7.0, 3e-16, frames, lambda);
  w.write(0.01, s.q0, s.v0, M_PI, 0.0, frames, lambda);
  EXPECT_EQ(w.samples(), 2);

  std::istringstream in(out.str());
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(splitCsv(line), w.columns());
  std::getline(in, line);
  const auto f = splitCsv(line);
  ASSERT_EQ(f.size(), w.columns().size());
  auto val = [&](const std::string& name) {
    for (std::size_t k = 0; k < f.size(); ++k)
      if (w.columns()[k] == name) return std::strtod(f[k].c_str(), nullptr);
    ADD_FAILURE() << "no column " << name;
    return 0.0;
  };
  EXPECT_EQ(val("q:root_joint.x"), 0.5);
  EXPECT_EQ(val("v:root_joint.vy"), 1.0);
  EXPECT_EQ(val("energy"), 1.0 / 7.0);  // shortest round-trip form: exact
  EXPECT_EQ(val("residual"), 3e-16);
  EXPECT_EQ(val("lambda:ball_table.tangent1"), 0.1 / 3.0);
  EXPECT_EQ(val("lambda:ball_table.tangent2"), -2e-17);
  // The contact point of the ball on the table, and the table's normal.
  EXPECT_NEAR(val("point:ball_table.x"), 0.5, 1e-15);
  EXPECT_NEAR(val("point:ball_table.z"), 0.0, 1e-15);
  EXPECT_NEAR(val("normal:ball_table.z"), 1.0, 1e-15);
  std::getline(in, line);
  EXPECT_EQ(std::strtod(splitCsv(line)[0].c_str(), nullptr), 0.01);
  EXPECT_FALSE(std::getline(in, line));

  // Wrong sizes are refused, not written.
  EXPECT_THROW(w.write(0.02, s.q0, s.v0, 0, 0, frames, VecX::Zero(2)), std::invalid_argument);
  EXPECT_THROW(w.write(0.02, s.q0, s.v0, 0, 0, {}, lambda), std::invalid_argument);
  EXPECT_EQ(w.samples(), 2);
}

TEST(IoOutput, NamesWithCommasAreQuoted) {
  ModelBuilder b;
  Inertia I{1.0, Vec3::Zero(), Mat3::Identity()};
  b.addBody("a", -1, SE3::Identity(), JointType::Revolute, Vec3::UnitZ(), I, "hinge, left");
  const Model m = b.build();
  std::ostringstream out;
  TrajectoryWriter w(out, m, {});
  EXPECT_EQ(out.str(), "time,\"q:hinge, left\",\"v:hinge, left\",energy,residual\n");
}
