// What vertex contacts cannot see (vertex_contacts.hpp): a terrain's own
// ridge or peak pressing into a face of a box or mesh between its vertices.
// After every step, FCL's collision depth between the whole shape and the
// terrain (collision.hpp) is compared with the vertex contacts' gaps: a
// penetration none of them accounts for stops the run, naming the contact,
// the point and the depth — never a box silently sinking onto a ridge.
// Only groups on terrain meshes are watched: on a plane or the outside of a
// sphere the vertices are where a convex shape touches first.
#pragma once

#include <appell/collision.hpp>
#include <appell/data.hpp>
#include <appell/scene.hpp>
#include <appell/simulator.hpp>

#include <memory>
#include <string>
#include <vector>

namespace appell::run_detail {

class VertexWatch {
 public:
  explicit VertexWatch(const Scene& scene);
  bool active() const { return !groups_.empty(); }
  /// False, with the reason in `why`, when a watched shape penetrates its
  /// terrain by more than `depth_tol` where no vertex contact does.
  bool check(const Simulator& sim, std::string& why);

 private:
  struct Group {
    const VertexGroup* group;
    std::shared_ptr<const CollisionGeometry> shape, terrain;
    SE3 terrain_pose;
  };
  const Scene& scene_;
  std::vector<Group> groups_;
  std::unique_ptr<Data> data_;
  static constexpr double kDepthTol = 1e-6;
};

}  // namespace appell::run_detail
