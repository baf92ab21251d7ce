// Candidate vertices of non-smooth shapes and their point contacts
// (vertex_contacts.hpp states the model).
#include <appell/overloaded.hpp>
#include <appell/vertex_contacts.hpp>

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace appell {

namespace {

// Indices of the input points that are vertices of their convex hull (Qhull,
// "Qt": triangulated output; the hull vertices are the same either way).
std::vector<int> hullVertexIndices(const std::vector<Vec3>& points, const std::string& what) {
  std::vector<double> coords;
  coords.reserve(3 * points.size());
  for (const Vec3& p : points) coords.insert(coords.end(), {p.x(), p.y(), p.z()});
  qhT qh_storage;
  qhT* qh = &qh_storage;
  FILE* quiet = std::fopen("/dev/null", "w");
  qh_zero(qh, quiet);
  char options[] = "qhull Qt";
  const int status = qh_new_qhull(qh, 3, static_cast<int>(points.size()), coords.data(), False,
                                  options, nullptr, quiet);
  std::vector<int> ids;
  if (status == 0) {
    vertexT* vertex;
    FORALLvertices ids.push_back(qh_pointid(qh, vertex->point));
  }
  qh_freeqhull(qh, !qh_ALL);
  int curlong = 0, totlong = 0;
  qh_memfreeshort(qh, &curlong, &totlong);
  if (quiet) std::fclose(quiet);
  if (status != 0)
    throw std::invalid_argument(what + ": its vertices span no volume (a flat or degenerate "
                                       "mesh has no convex hull to touch with)");
  return ids;
}

}  // namespace

std::vector<Vec3> contactVertices(const Shape& shape, int rim_points) {
  validateShape(shape);
  auto refuse = [&](const std::string& why) -> std::vector<Vec3> {
    throw std::invalid_argument(std::string(shapeName(shape)) + ": " + why);
  };
  return std::visit(
      Overloaded{
          [](const Box& b) {
            std::vector<Vec3> out;
            for (int c = 0; c < 8; ++c)
              out.push_back(b.pose.apply(Vec3(c & 1 ? 1 : -1, c & 2 ? 1 : -1, c & 4 ? 1 : -1)
                                             .cwiseProduct(b.half_extents)));
            return out;
          },
          [&](const Cylinder& c) {
            if (rim_points < 3) return refuse("a rim polygon needs at least 3 points");
            std::vector<Vec3> out;
            for (double z : {-0.5 * c.length, 0.5 * c.length})
              for (int k = 0; k < rim_points; ++k) {
                const double a = 2 * M_PI * k / rim_points;
                out.push_back(c.pose.apply(Vec3(c.radius * std::cos(a), c.radius * std::sin(a), z)));
              }
            return out;
          },
          [&](const Mesh& m) {
            if (m.triangles.empty()) return refuse("mesh '" + m.file + "': its triangles were not loaded");
            std::vector<Vec3> out;
            for (int id : hullVertexIndices(m.vertices, "mesh '" + m.file + "'"))
              out.push_back(m.pose.apply(m.vertices[id]));
            return out;
          },
          [&](const auto&) {
            return refuse("has a smooth contact point of its own; it needs no vertex contacts");
          }},
      shape);
}

std::vector<std::shared_ptr<ShapeContact>> makeVertexContacts(const ContactSpec& spec,
                                                              int rim_points) {
  const std::string name =
      !spec.options.name.empty()
          ? spec.options.name
          : std::string(toString(spec.kind)) + "(body " + std::to_string(spec.body) + ", " +
                shapeName(spec.shape) + " on " + spec.support.name + ")";
  if (spec.kind != ContactKind::Sliding && spec.kind != ContactKind::Rolling)
    throw std::invalid_argument("contact '" + name + "': a " + shapeName(spec.shape) +
                                " touches with its vertices, which are points: kind 'sliding' "
                                "(frictionless) or 'rolling' (sticking points), not '" +
                                toString(spec.kind) + "'");
  std::vector<Vec3> vertices;
  try {
    vertices = contactVertices(spec.shape, rim_points);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("contact '" + name + "': " + e.what());
  }
  std::vector<std::shared_ptr<ShapeContact>> out;
  out.reserve(vertices.size());
  for (int k = 0; k < static_cast<int>(vertices.size()); ++k) {
    ContactSpec point = spec;
    point.shape = PointShape{vertices[k]};
    point.options.name = name + "/v" + std::to_string(k);
    out.push_back(makeContact(point));
  }
  return out;
}

}  // namespace appell
