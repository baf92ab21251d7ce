#include <appell/scene.hpp>

namespace appell {

const char* toString(GeometryType type) {
  switch (type) {
    case GeometryType::Box: return "box";
    case GeometryType::Cylinder: return "cylinder";
    case GeometryType::Sphere: return "sphere";
    case GeometryType::Mesh: return "mesh";
  }
  return "?";
}

int Scene::contactIndex(const std::string& name) const {
  for (int k = 0; k < static_cast<int>(contacts.size()); ++k)
    if (contacts[k].name == name) return k;
  return -1;
}

int Scene::constraintRows() const {
  int m = 0;
  for (const auto& c : constraints) m += c->rows();
  return m;
}

}  // namespace appell
