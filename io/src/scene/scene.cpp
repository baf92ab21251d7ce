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

std::vector<Shape> collisionShapes(const LinkGeometry& link) {
  std::vector<Shape> shapes;
  for (const Geometry& g : link.collision) {
    switch (g.type) {
      case GeometryType::Box: shapes.emplace_back(Box{0.5 * g.box_size, g.origin}); break;
      case GeometryType::Cylinder: shapes.emplace_back(Cylinder{g.radius, g.length, g.origin}); break;
      case GeometryType::Sphere: shapes.emplace_back(Sphere{g.radius, g.origin.p}); break;
      case GeometryType::Mesh: {
        Mesh m{g.mesh_path, g.mesh_scale, g.origin, {}, {}};
        if (g.mesh) {
          m.vertices = g.mesh->vertices;
          m.triangles = g.mesh->triangles;
        }
        shapes.emplace_back(std::move(m));
        break;
      }
    }
  }
  return shapes;
}

int Scene::contactIndex(const std::string& name) const {
  for (int k = 0; k < static_cast<int>(contacts.size()); ++k)
    if (contacts[k]->name() == name) return k;
  return -1;
}

namespace {
// Whether the scene declares constant efforts (<effort>): a non-zero tau of nv.
bool hasConstantForces(const Scene& s) {
  return s.tau.size() > 0 && s.tau.size() == s.model.nv && s.tau.cwiseAbs().maxCoeff() > 0;
}
}  // namespace

Simulator::JointForces Scene::jointForces() const {
  const bool constant = hasConstantForces(*this);
  if (!constant && actuators.empty()) return {};
  // Copies of the forces (a later change to the scene does not reach a
  // running simulation); the model by reference (its owner outlives us).
  return [model = &model, tau = constant ? tau : VecX::Zero(model.nv), actuators = actuators](
             double t, const VecX& q, const VecX& v, VecX& out) {
    out = tau;
    applyActuators(*model, actuators, t, q, v, out);
  };
}

Simulator::JointForces Scene::constantJointForces() const {
  if (!hasConstantForces(*this)) return {};
  return [tau = tau](double, const VecX&, const VecX&, VecX& out) { out = tau; };
}

bool Scene::driven() const {
  return !actuators.empty() || (tau.size() && tau.cwiseAbs().maxCoeff() > 0);
}

int Scene::constraintRows() const {
  int m = 0;
  for (const auto& c : constraints) m += c->rows();
  return m;
}

}  // namespace appell
