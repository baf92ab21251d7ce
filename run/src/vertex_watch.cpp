// The watch over what vertex contacts cannot see (vertex_watch.hpp).
#include "vertex_watch.hpp"

#include <appell/kinematics.hpp>

#include <sstream>

namespace appell::run_detail {

VertexWatch::VertexWatch(const Scene& scene) : scene_(scene) {
  for (const VertexGroup& g : scene.vertex_groups) {
    if (g.support < 0) continue;
    const Support& support = scene.supports[g.support];
    if (!std::holds_alternative<TerrainMesh>(support.surface) || support.body >= 0) continue;
    Group w;
    w.group = &g;
    w.shape = makeCollisionGeometry(g.shape);
    w.terrain = makeCollisionGeometry(support);
    w.terrain_pose = supportState(support.motion, 0.0).pose;
    groups_.push_back(std::move(w));
  }
  if (!groups_.empty()) data_ = std::make_unique<Data>(scene.model, MassMatrix::None);
}

bool VertexWatch::check(const Simulator& sim, std::string& why) {
  if (groups_.empty()) return true;
  forwardKinematics(scene_.model, *data_, sim.q());
  const ConstraintData& cd = sim.constraintData();
  for (const Group& w : groups_) {
    const VertexGroup& g = *w.group;
    Vec3 where;
    double depth = 0;
    if (!collide(*w.shape, data_->oMi[g.body], *w.terrain, w.terrain_pose, &where, &depth) ||
        depth <= kDepthTol)
      continue;
    double deepest_vertex = 0;
    for (int k = g.first; k < g.first + g.count; ++k) {
      const auto& c = *scene_.constraints[k];
      deepest_vertex = std::min(deepest_vertex, cd.gap[cd.offset[k] + c.unilateralRow()]);
    }
    if (-deepest_vertex > depth - kDepthTol) continue;  // a vertex accounts for it
    std::ostringstream s;
    s << "contact '" << g.name << "' (a " << shapeName(g.shape) << " on link '"
      << scene_.model.body_names[g.body] << "'): the terrain presses into it by " << depth
      << " m at (" << where.transpose() << ") between its vertices — a ridge or peak of "
      << "the mesh against a face, which its vertex contacts cannot carry; give the link a smooth "
         "contact shape there";
    why = s.str();
    return false;
  }
  return true;
}

}  // namespace appell::run_detail
