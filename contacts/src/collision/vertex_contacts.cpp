// Candidate vertices of non-smooth shapes and their point contacts
// (vertex_contacts.hpp states the model).
#include <appell/overloaded.hpp>
#include <appell/vertex_contacts.hpp>

#include <Eigen/Eigenvalues>

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

#include <algorithm>
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

// The hull vertices farthest along kMaxHullContacts directions of a
// spherical Fibonacci lattice (vertex_contacts.hpp): z_k = 1 − (2k + 1)/K,
// azimuth k·π(3 − √5). Ties go to the earlier hull vertex, so the set is
// deterministic. Kept in hull order.
std::vector<int> supportPoints(const std::vector<Vec3>& points, const std::vector<int>& hull) {
  const int K = kMaxHullContacts;
  const double golden_angle = M_PI * (3.0 - std::sqrt(5.0));
  std::vector<char> kept(hull.size(), 0);
  for (int k = 0; k < K; ++k) {
    const double z = 1.0 - (2.0 * k + 1.0) / K;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const Vec3 d(r * std::cos(k * golden_angle), r * std::sin(k * golden_angle), z);
    std::size_t best = 0;
    double farthest = d.dot(points[hull[0]]);
    for (std::size_t i = 1; i < hull.size(); ++i) {
      const double reach = d.dot(points[hull[i]]);
      if (reach > farthest) best = i, farthest = reach;
    }
    kept[best] = 1;
  }
  std::vector<int> out;
  for (std::size_t i = 0; i < hull.size(); ++i)
    if (kept[i]) out.push_back(hull[i]);
  return out;
}

// Meshes with more vertices skip Qhull (see contactVertices).
constexpr std::size_t kQhullVertices = 20000;

// The support points must span a volume, as Qhull requires of the hull
// (their covariance's smallest eigenvalue not below 10⁻¹² of its largest).
void requireVolume(const std::vector<Vec3>& points, const std::vector<int>& ids, const std::string& what) {
  Vec3 mean = Vec3::Zero();
  for (int i : ids) mean += points[i];
  mean /= static_cast<double>(ids.size());
  Mat3 cov = Mat3::Zero();
  for (int i : ids) cov += (points[i] - mean) * (points[i] - mean).transpose();
  const Vec3 eig = Eigen::SelfAdjointEigenSolver<Mat3>(cov, Eigen::EigenvaluesOnly).eigenvalues();
  if (!(eig[0] > 1e-12 * eig[2]))
    throw std::invalid_argument(what + ": its vertices span no volume (a flat or degenerate "
                                       "mesh has no convex hull to touch with)");
}

}  // namespace

std::vector<Vec3> contactVertices(const Shape& shape, int rim_points, int* hull_vertices) {
  if (hull_vertices) *hull_vertices = 0;
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
            std::vector<int> hull;
            if (m.vertices.size() > kQhullVertices) {
              // The farthest point along a direction is a hull vertex: the
              // support points come straight from all the vertices, O(K n),
              // without the hull (Qhull on 1.8·10⁵ points on a sphere takes
              // seconds).
              hull.resize(m.vertices.size());
              for (std::size_t i = 0; i < hull.size(); ++i) hull[i] = static_cast<int>(i);
              hull = supportPoints(m.vertices, hull);
              requireVolume(m.vertices, hull, "mesh '" + m.file + "'");
              if (hull_vertices) *hull_vertices = static_cast<int>(m.vertices.size());
            } else {
              hull = hullVertexIndices(m.vertices, "mesh '" + m.file + "'");
              if (static_cast<int>(hull.size()) > kMaxHullContacts) {
                if (hull_vertices) *hull_vertices = static_cast<int>(m.vertices.size());
                hull = supportPoints(m.vertices, hull);
              }
            }
            std::vector<Vec3> out;
            for (int id : hull) out.push_back(m.pose.apply(m.vertices[id]));
            return out;
          },
          [&](const auto&) {
            return refuse("has a smooth contact point of its own; it needs no vertex contacts");
          }},
      shape);
}

std::vector<std::shared_ptr<ShapeContact>> makeVertexContacts(const ContactSpec& spec,
                                                              int rim_points, std::string* warning) {
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
    int hull_vertices = 0;
    vertices = contactVertices(spec.shape, rim_points, &hull_vertices);
    if (hull_vertices > 0 && warning)
      *warning = "contact '" + name + "': the mesh's convex hull has more than " +
                 std::to_string(kMaxHullContacts) + " of its " + std::to_string(hull_vertices) +
                 " vertices; its " + std::to_string(vertices.size()) + " support points in " +
                 std::to_string(kMaxHullContacts) + " evenly spread directions are the contacts";
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
