// The joint type table's lookups and the coordinate names it gives a model
// (joint_types.hpp): the CSV's q:/v: columns, --set and Python's names.
#include <appell/joint_types.hpp>

#include <stdexcept>

namespace appell {

const JointTypeInfo* findJointType(const std::string& name) {
  for (const JointTypeInfo& e : kJointTypes)
    if (name == e.name) return &e;
  return nullptr;
}

std::vector<std::string> coordinateNames(const Model& model, bool velocities) {
  std::vector<std::string> names;
  names.reserve(static_cast<std::size_t>(velocities ? model.nv : model.nq));
  for (int j = 0; j < model.nbodies; ++j) {
    const JointTypeInfo& t = jointTypeInfo(model.joints[j].type);
    const int n = velocities ? t.nv : t.nq;
    for (int k = 0; k < n; ++k)
      names.push_back(model.joint_names[j] + (velocities ? t.velocity_names[k] : t.position_names[k]));
  }
  return names;
}

int localCoordinateIndex(const Model& model, const std::string& name) {
  for (int j = 0; j < model.nbodies; ++j) {
    const Joint& joint = model.joints[j];
    const std::string& jn = model.joint_names[j];
    if (name.compare(0, jn.size(), jn) != 0) continue;
    const std::string coord = name.substr(jn.size());
    const JointTypeInfo& t = jointTypeInfo(joint.type);
    for (int k = 0; k < t.nv; ++k)
      if (coord == t.velocity_names[k]) return joint.idx_v + k;
    for (int k = 0; k < t.nq; ++k) {
      if (coord != t.position_names[k]) continue;
      if (t.quaternion >= 0 && k >= t.quaternion && k < t.quaternion + 4)
        throw std::invalid_argument("'" + name + "' is a quaternion component, not a coordinate of its own; name a "
                                    "rotation slot (" + jn + ".wx, .wy, .wz: rotations about the body axes)");
      // Positions that are local coordinates themselves: θ = Δq from the
      // type's position slot on (a floating joint's x, y, z are slots 3–5).
      return joint.idx_v + t.position_slot + k;
    }
  }
  return -1;
}

}  // namespace appell
