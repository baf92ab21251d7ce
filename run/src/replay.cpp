// The replay frames (replay.hpp): forward kinematics and the constraints'
// rows at each sample, the reaction forces from the sample's λ.
#include <appell/replay.hpp>

#include <appell/constrained_dynamics.hpp>
#include <appell/kinematics.hpp>
#include <appell/output.hpp>
#include <appell/simulator.hpp>
#include <appell/supports.hpp>

namespace appell {

namespace {

void appendPose(std::vector<double>& out, const SE3& X) {
  const Quat r(X.R);
  out.insert(out.end(), {X.p.x(), X.p.y(), X.p.z(), r.x(), r.y(), r.z(), r.w()});
}

ReplayFrame frameAt(const Scene& scene, Data& data, std::vector<RowBlock>& blocks, double t,
                    const VecX& q, const VecX& v, const VecX& lambda) {
  const Model& m = scene.model;
  ReplayFrame f{t, {}, {}, {}, {}, std::vector<double>(scene.constraints.size(), 1.0), {}};
  forwardKinematics(m, data, q, v);
  for (int b = 0; b < m.nbodies; ++b) appendPose(f.poses, data.oMi[b]);
  // A support frame moves as its motion says, or rides on its body (supports.hpp).
  for (const Support& s : scene.supports)
    appendPose(f.supports, s.body >= 0 ? data.oMi[s.body] * std::get<StaticMotion>(s.motion).pose
                                       : supportState(s.motion, t).pose);
  int row = 0;
  for (size_t c = 0; c < scene.constraints.size(); ++c) {
    const Constraint& con = *scene.constraints[c];
    con.evaluate(m, data, t, q, v, blocks[c]);
    Vec3 force = Vec3::Zero();
    if (!con.jointSpace())
      for (int r = 0; r < con.rows(); ++r) force += lambda[row + r] * blocks[c].Wa.row(r).tail<3>().transpose();
    row += con.rows();
    const Vec3& p = blocks[c].frame.point;
    f.points.insert(f.points.end(), {p.x(), p.y(), p.z()});
    f.forces.insert(f.forces.end(), {force.x(), force.y(), force.z()});
  }
  return f;
}

}  // namespace

std::vector<ReplayFrame> replayFrames(const Scene& scene, const TrajectoryTable& table) {
  const Model& m = scene.model;
  const std::vector<std::string> names = trajectoryColumns(m, scene.constraints);
  // Columns in the writer's order: time, q (nq), v (nv), energy, residual, then per constraint.
  std::vector<int> qcol, vcol, lcol;
  for (int i = 0; i < m.nq; ++i) qcol.push_back(table.require(names[1 + i]));
  for (int i = 0; i < m.nv; ++i) vcol.push_back(table.require(names[1 + m.nq + i]));
  for (const std::string& n : names)
    if (n.rfind("lambda:", 0) == 0) lcol.push_back(table.require(n));
  // Contact modes and events (unilateral contacts; absent in older files).
  std::vector<int> closed_col(scene.constraints.size(), -1), event_col(scene.constraints.size(), -1);
  for (size_t c = 0; c < scene.constraints.size(); ++c) {
    closed_col[c] = table.find("closed:" + scene.constraints[c]->name());
    event_col[c] = table.find("event:" + scene.constraints[c]->name());
  }
  Data data(m);
  std::vector<RowBlock> blocks(scene.constraints.size());
  for (size_t c = 0; c < blocks.size(); ++c) scene.constraints[c]->reserve(m, blocks[c]);
  VecX q(m.nq), v(m.nv), lambda(lcol.size());
  std::vector<ReplayFrame> frames;
  for (const auto& row : table.rows) {
    for (int i = 0; i < m.nq; ++i) q[i] = row[qcol[i]];
    for (int i = 0; i < m.nv; ++i) v[i] = row[vcol[i]];
    for (size_t i = 0; i < lcol.size(); ++i) lambda[i] = row[lcol[i]];
    frames.push_back(frameAt(scene, data, blocks, row[0], q, v, lambda));
    for (size_t c = 0; c < scene.constraints.size(); ++c) {
      if (closed_col[c] >= 0) frames.back().closed[c] = row[closed_col[c]];
      if (event_col[c] >= 0 && row[event_col[c]] != 0)
        frames.back().events.emplace_back(static_cast<int>(c), static_cast<int>(row[event_col[c]]));
    }
  }
  return frames;
}

std::vector<ReplayFrame> initialReplayFrame(const Scene& scene) {
  Simulator sim(scene.model, scene.constraints,
                makeSolver(formulationFromString(scene.settings.formulation), scene.model,
                           scene.constraints),
                IntegratorType::RK4);
  if (scene.tau.size() == scene.model.nv) {
    const VecX tau = scene.tau;
    sim.setJointForces([tau](double, const VecX&, const VecX&, VecX& out) { out = tau; });
  }
  sim.setState(0.0, scene.q0, scene.v0);
  Data data(scene.model);
  std::vector<RowBlock> blocks(scene.constraints.size());
  for (size_t c = 0; c < blocks.size(); ++c) scene.constraints[c]->reserve(scene.model, blocks[c]);
  return {frameAt(scene, data, blocks, 0.0, scene.q0, scene.v0, sim.lambda())};
}

}  // namespace appell
