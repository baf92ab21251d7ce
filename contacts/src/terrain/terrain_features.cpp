// A smooth convex shape against an edge or a vertex of a terrain mesh: the
// pieces of the face model (terrain_geometry.cpp) for a body over a crease
// or a corner, where no face holds its contact point.
//
// Vertex x: the outside of a sphere of radius 0 about x
// (geometry_sphere_surface.cpp), which already handles every shape.
//
// Edge through a with unit direction e (support frame). The nearest points of
// the body and the line satisfy n ⊥ e and P(y − a) ∥ n, where P = 1 − e eᵀ,
// n is the contact normal (from the line toward the body) and y = σ(−Rᵀn)
// the body's point with outward normal −n. Write n(φ) = cos φ n₀ + sin φ b₀
// on the circle ⊥ e and b = e × n (so dn/dφ = b, db/dφ = −n); the residual
//     f(φ) = b · (y − a) = 0
// has f′ = −(g + bᵀRΣRᵀb), g = n·(y − a) the gap, since dy/dφ = −RΣRᵀb:
// Newton converges while g plus the body's radius of curvature along b stays
// positive. Differentiating f = 0 in time (in the support frame, where the
// body moves with relative angular velocity ω − Ω and its point y with
// u = V_B(y) − V_S(y)) gives the normal's rate
//     ṅ = Ω × n + φ̇ b,   φ̇ = [b·u + bᵀRΣRᵀ((ω − Ω) × n)] / (g + bᵀRΣRᵀb),
// which for a sphere (Σ = ρ(1 − m mᵀ)) reduces to b·(u_c)/d of
// terrain_sphere.cpp. The body-frame normal m = −Rᵀn has ṁ = −Rᵀ(ṅ − ω × n).
#include "geometry_internal.hpp"
#include "terrain_index.hpp"

#include <cmath>

namespace appell::detail {

Vec3 shapeCentre(const Shape& shape) {
  return std::visit(
      [](const auto& s) -> Vec3 {
        if constexpr (requires { s.centre; }) return s.centre;
        else if constexpr (requires { s.position; }) return s.position;
        else return s.pose.p;
      },
      shape);
}

double boundingRadius(const Shape& shape) {
  return std::visit(
      Overloaded{[](const PointShape&) { return 0.0; },
                 [](const Sphere& s) { return s.radius; },
                 [](const Ellipsoid& s) { return s.semi_axes.maxCoeff(); },
                 [](const Disk& s) { return s.radius; },
                 [](const Torus& s) { return s.major + s.minor; },
                 [](const SphericalCap& s) { return s.radius; },
                 [](const Box& s) { return double(s.half_extents.norm() + s.pose.p.norm()); },
                 [](const Cylinder& s) {
                   return std::hypot(s.radius, 0.5 * s.length) + s.pose.p.norm();
                 },
                 [](const Mesh&) { return double(INFINITY); }},
      shape);
}

bool terrainEdgeGeometry(const Shape& shape, const Vec3& a_s, const Vec3& b_s,
                         const SupportState& S, const SE3& pose, const Vec6& V,
                         ContactGeometry& out, const GeometryOptions& opt, bool segment) {
  const Twist body(V), sup(S.V);
  const Vec3 a = S.pose.apply(a_s);
  const Vec3 ab = S.pose.R * (b_s - a_s);
  const double length = ab.norm();
  const Vec3 e = ab / length;
  const Vec3 c = pose.apply(shapeCentre(shape));
  Vec3 n = (c - a) - e * e.dot(c - a);
  if (!(n.norm() > opt.singular_tol * length)) return false;
  n.normalize();
  GaussPoint g;
  Vec3 y, b;
  double gap = 0, kb = 0;
  bool converged = false;
  for (int it = 0; it < opt.max_iterations; ++it) {
    b = e.cross(n);
    g = inverseGaussMap(shape, -(pose.R.transpose() * n), opt.singular_tol);
    if (g.singular) return false;
    y = pose.apply(g.y);
    gap = n.dot(y - a);
    const Vec3 bb = pose.R.transpose() * b;
    kb = bb.dot(g.Sigma * bb);
    const double slope = gap + kb;
    if (!(slope > opt.singular_tol * length)) return false;
    const double delta = b.dot(y - a) / slope;  // −f/f′
    n = (std::cos(delta) * n + std::sin(delta) * b).normalized();
    out.iterations = it + 1;
    if (std::abs(delta) <= 1e-14) {
      converged = true;
      break;
    }
  }
  if (!converged) return false;
  b = e.cross(n);
  g = inverseGaussMap(shape, -(pose.R.transpose() * n), opt.singular_tol);
  if (g.singular) return false;
  y = pose.apply(g.y);
  gap = n.dot(y - a);
  const double along = e.dot(y - a);
  if (segment && (along < 0 || along > length)) return false;  // nearest to the line beyond it

  const Vec3 bb = pose.R.transpose() * b;
  const Mat3 RSR = pose.R * g.Sigma * pose.R.transpose();
  kb = bb.dot(g.Sigma * bb);
  const Vec3 u = body.at(y) - S.pointVelocity(y);
  const double phidot = (b.dot(u) + b.dot(RSR * (body.w - sup.w).cross(n))) / (gap + kb);
  const Vec3 ndot = sup.w.cross(n) + phidot * b;

  out.singular = false;
  out.reason = nullptr;
  out.normal = n;
  out.normal_rate = ndot;
  out.gap = gap;
  const Vec3 mdot = -(pose.R.transpose() * (ndot - body.w.cross(n)));
  finishPoint(pose, body, g, mdot, out);
  transportedFrame(S.pose.R, sup.w, out);  // the faces' frame, continuous across pieces
  return true;
}

bool terrainVertexGeometry(const Shape& shape, const Vec3& x_s, const SupportState& S,
                           const SE3& pose, const Vec6& V, ContactGeometry& out,
                           const GeometryOptions& opt) {
  SphereSurface point;
  point.centre = x_s;
  point.radius = 0;
  point.side = SphereSurface::Side::Outside;
  out.singular = false;
  out.reason = nullptr;
  sphereSurfaceGeometry(shape, point, S, pose, V, out, opt);
  return !out.singular;
}

bool separatePiece(const TerrainMesh& t, int feature, const Vec3& n) {
  const TerrainIndex& idx = *t.index;
  // How far past a face's plane the normal must lean (rad): on an edge
  // inside a flat region, or at a face's boundary, n lies in the plane.
  constexpr double kLean = 1e-9;
  if (feature < idx.regions) return true;
  if (feature < idx.regions + idx.edges) {
    const int e = feature - idx.regions;
    const Vec3& a = t.vertices[idx.edge_ends[e][0]];
    const Vec3 dir = t.vertices[idx.edge_ends[e][1]] - a;
    for (int f : idx.edge_face[e]) {
      if (f < 0) continue;
      int k = 0;
      while (k < 2 && idx.edge[f][k] != e) ++k;
      Vec3 u = idx.normal[f].cross(dir).normalized();
      if (u.dot(t.vertices[t.triangles[f][k]] - a) < 0) u = -u;  // into the face
      if (!(n.dot(u) < -kLean)) return false;
    }
    return true;
  }
  const int v = feature - idx.regions - idx.edges;
  for (int i = idx.vertex_edge_start[v]; i < idx.vertex_edge_start[v + 1]; ++i) {
    const auto& ends = idx.edge_ends[idx.vertex_edge[i]];
    const Vec3 d = t.vertices[ends[0] == v ? ends[1] : ends[0]] - t.vertices[v];
    if (!(n.dot(d) < -kLean * d.norm())) return false;
  }
  return true;
}

Vec3 nearestOnPiece(const TerrainMesh& t, int feature, const Vec3& p) {
  const TerrainIndex& idx = *t.index;
  if (feature < idx.regions) {
    const int f = idx.region_face[feature];
    const Vec3& n = idx.normal[f];
    return p - n * n.dot(p - t.vertices[t.triangles[f][0]]);
  }
  if (feature < idx.regions + idx.edges) {
    const auto& ends = idx.edge_ends[feature - idx.regions];
    const Vec3& a = t.vertices[ends[0]];
    const Vec3 e = (t.vertices[ends[1]] - a).normalized();
    return a + e * e.dot(p - a);
  }
  return t.vertices[feature - idx.regions - idx.edges];
}

void noPieceInReach(const SupportState& S, const SE3& pose, double reach, ContactGeometry& out) {
  out = ContactGeometry{};
  out.normal = S.pose.R.col(2);
  out.t1 = -S.pose.R.col(1);  // the transported frame at the pole
  out.t2 = S.pose.R.col(0);
  out.gap = reach;
  out.point = pose.p;
  out.support_point = pose.p - reach * out.normal;
  out.feature = -1;
}

}  // namespace appell::detail
