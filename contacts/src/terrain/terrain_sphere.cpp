// A sphere on a terrain mesh: the contact is at the mesh point nearest to the
// sphere's centre, on a face, an edge or a vertex — so a ball rolls across
// the edges and vertices of the mesh, pivoting about them, instead of
// stopping there (terrain.hpp states the face model).
//
// With c the centre, x the nearest mesh point and d = |c − x|:
//   n = (c − x)/d,  gap = d − ρ,  contact point c − ρ n, support point x.
// The normal's rate follows from c's velocity relative to the support,
// u = V_B(c) − V_S(c), and the support's rotation Ω (e: the edge direction):
//   face    ṅ = Ω × n                                (the plane contact, exactly)
//   edge    ṅ = Ω × n + (1 − n nᵀ)(1 − e eᵀ) u / d   (x slides along the edge)
//   vertex  ṅ = Ω × n + (1 − n nᵀ) u / d             (x stays put)
// (differentiate n = P(c − a)/|P(c − a)| in the support frame, P = 1 − e eᵀ
// on an edge, 1 on a vertex). The body-frame normal at the contact is
// m = −Rᵀ n, so ṁ = −Rᵀ(ṅ − ω × n). Where the nearest feature changes (face
// → edge → face) n is continuous and ṅ jumps: the curvature the ball rolls
// on changes, as on any piecewise-flat surface.
//
// Nearest point on a triangle with its feature: Voronoi regions of the
// vertices, edges and face (Ericson, Real-Time Collision Detection, 2005,
// §5.1.5).
#include "geometry_internal.hpp"
#include "terrain_index.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace appell::detail {

namespace {

struct Nearest {
  Vec3 x = Vec3::Zero();  ///< support frame
  int face = -1;
  int feature = -1;       ///< 0: face; 1 + k: edge opposite vertex k; 4 + k: vertex k
};

// Nearest point of triangle (a, b, c) to p, with the feature holding it.
Nearest nearestOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  Nearest r;
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return r.x = a, r.feature = 4, r;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return r.x = b, r.feature = 5, r;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return r.x = a + d1 / (d1 - d3) * ab, r.feature = 3, r;  // edge ab
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return r.x = c, r.feature = 6, r;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return r.x = a + d2 / (d2 - d6) * ac, r.feature = 2, r;  // edge ac
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)  // edge bc
    return r.x = b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b), r.feature = 1, r;
  const double denom = 1 / (va + vb + vc);
  r.x = a + ab * (vb * denom) + ac * (vc * denom);
  r.feature = 0;
  return r;
}

}  // namespace

Vec3 nearestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  return nearestOnTriangle(p, a, b, c).x;
}

void terrainSphereGeometry(const Sphere& sphere, const TerrainMesh& terrain, const SupportState& S,
                           const SE3& pose, const Vec6& V, ContactGeometry& out,
                           const GeometryOptions& opt, int latched,
                           std::span<const int> excluded) {
  const TerrainIndex& idx = *terrain.index;
  const Twist body(V), sup(S.V);
  const Vec3 c = pose.apply(sphere.centre);
  const Vec3 cs = S.pose.applyInv(c);  // support frame

  // The feature (TerrainIndex's numbering) and its point nearest the centre:
  // the latched one extended (a region's plane, an edge's line), or the
  // nearest over the mesh.
  int feature = latched;
  Vec3 xs = Vec3::Zero();
  // The piece a triangle's nearest point lies on: on an edge or a vertex but
  // along the face's normal (its boundary, or an edge between coplanar
  // faces), the face's region.
  auto pieceOf = [&](int f, const Nearest& nr) {
    const Vec3 d = cs - nr.x;
    const Vec3& nf = idx.normal[f];
    const bool on_plane = nf.dot(d) >= 0 && (d - nf * nf.dot(d)).norm() <= 1e-12 * d.norm();
    if (nr.feature == 0 || on_plane) return idx.regionFeature(f);
    if (nr.feature <= 3) return idx.edgeFeature(f, nr.feature - 1);
    return idx.vertexFeature(terrain.triangles[f][nr.feature - 4]);
  };
  if (latched < 0 && !excluded.empty()) {
    // Another point of the pair (the others hold `excluded`): the nearest
    // separate piece within 2ρ of the centre, else a gap of ρ.
    const double reach = 2 * sphere.radius;
    double best_d2 = reach * reach;
    // Where the excluded pieces are nearest the centre: a candidate whose
    // nearest point is there is the same place of contact seen from the
    // next piece (at the instant a held contact crosses onto it).
    std::array<Vec3, 4> held;
    const int nheld = std::min<int>(static_cast<int>(excluded.size()), 4);
    for (int i = 0; i < nheld; ++i) held[i] = nearestOnPiece(terrain, excluded[i], cs);
    forEachFaceInBox(idx, cs.array() - reach, cs.array() + reach, [&](int f) {
      const auto& tri = terrain.triangles[f];
      const Nearest nr = nearestOnTriangle(cs, terrain.vertices[tri[0]], terrain.vertices[tri[1]],
                                           terrain.vertices[tri[2]]);
      const double d2 = (cs - nr.x).squaredNorm();
      if (!(d2 < best_d2) || d2 == 0) return;
      const int piece = pieceOf(f, nr);
      if (excludedPiece(excluded, piece) ||
          !separatePiece(terrain, piece, (cs - nr.x) / std::sqrt(d2)))
        return;
      for (int i = 0; i < nheld; ++i)
        if ((nr.x - held[i]).norm() <= kSamePlace * sphere.radius) return;
      best_d2 = d2;
      feature = piece;
      xs = nr.x;
    });
    if (feature < 0) {
      noPieceInReach(S, pose, reach - sphere.radius, out);
      return;
    }
    if (feature >= idx.regions + idx.edges) xs = terrain.vertices[feature - idx.regions - idx.edges];
  } else if (latched < 0) {
    // Candidate faces: every triangle within distance r of the centre meets
    // the box cs ± r; r widens until the nearest point found lies within it.
    // Ties go to a face (a point on an edge or vertex inside a flat region
    // is on the region).
    Nearest best;
    double best_d2 = INFINITY;
    auto consider = [&](int f) {
      const auto& tri = terrain.triangles[f];
      Nearest n = nearestOnTriangle(cs, terrain.vertices[tri[0]], terrain.vertices[tri[1]],
                                    terrain.vertices[tri[2]]);
      const double d2 = (cs - n.x).squaredNorm();
      if (d2 < best_d2 || (n.feature == 0 && best.feature != 0 && d2 <= best_d2 * (1 + 1e-12))) {
        best_d2 = std::min(d2, best_d2);
        n.face = f;
        best = n;
      }
    };
    const auto& root = idx.bvh->getBV(0).bv.obb;
    const Vec3 root_half = root.axis.cwiseAbs() * root.extent;
    for (double r = 2 * sphere.radius;;
         r = std::isfinite(best_d2) ? std::sqrt(best_d2) * (1 + 1e-9) + 1e-12 : 2 * r) {
      const Vec3 lo = cs.array() - r, hi = cs.array() + r;
      forEachFaceInBox(idx, lo, hi, consider);
      if (best_d2 <= r * r) break;
      if (((lo - (root.To - root_half)).array() <= 0).all() &&
          ((hi - (root.To + root_half)).array() >= 0).all())
        break;
    }
    feature = pieceOf(best.face, best);
    if (feature >= idx.regions + idx.edges) xs = terrain.vertices[feature - idx.regions - idx.edges];
    else xs = best.x;
  }
  if (feature < idx.regions) {
    // On a flat region: the plane contact of its plane, exactly.
    Plane plane;
    plane.point = terrain.vertices[terrain.triangles[idx.region_face[feature]][0]];
    plane.normal = idx.normal[idx.region_face[feature]];
    planeGeometry(sphere, plane, S, pose, V, out, opt);
    out.feature = feature;
    return;
  }
  const bool on_edge = feature < idx.regions + idx.edges;
  Vec3 e = Vec3::Zero();  // on an edge: its direction (its welded ends in order)
  if (on_edge) {
    const auto& ends = idx.edge_ends[feature - idx.regions];
    const Vec3& a = terrain.vertices[ends[0]];
    const Vec3 es = (terrain.vertices[ends[1]] - a).normalized();
    if (latched >= 0) xs = a + es * es.dot(cs - a);  // the line's point nearest the centre
    e = S.pose.R * es;
  } else if (feature < idx.regions + idx.edges + static_cast<int>(terrain.vertices.size())) {
    xs = terrain.vertices[feature - idx.regions - idx.edges];
  } else {
    out = ContactGeometry{};
    markSingular(out, "latched terrain feature out of range");
    return;
  }
  const Vec3 x = S.pose.apply(xs);
  const double d = (c - x).norm();
  out = ContactGeometry{};
  out.feature = feature;
  if (!(d > opt.singular_tol * sphere.radius)) {
    out.point = c;
    out.support_point = x;
    out.gap = -sphere.radius;
    markSingular(out, "the sphere's centre lies on a terrain edge or vertex: no unique normal");
    return;
  }
  const Vec3 n = (c - x) / d;
  // The side of the surface the centre is on: a ball that has passed
  // through an edge or vertex (a long step of free flight) is behind it, and
  // its gap is negative there as behind a face (−d − ρ; continuous at d = 0).
  const Vec3 pseudo = S.pose.R * (on_edge ? idx.edge_normal[feature - idx.regions]
                                          : idx.vertex_normal[feature - idx.regions - idx.edges]);
  const double side = n.dot(pseudo) < 0 ? -1.0 : 1.0;
  const Vec3 u = body.at(c) - S.pointVelocity(c);
  Vec3 ndot = sup.w.cross(n);
  if (on_edge) {
    const Vec3 pu = u - e * e.dot(u);
    ndot += (pu - n * n.dot(pu)) / d;
  } else {
    ndot += (u - n * n.dot(u)) / d;
  }
  out.normal = n;
  out.normal_rate = ndot;
  out.gap = side * d - sphere.radius;
  const Vec3 m = -(pose.R.transpose() * n);
  const GaussPoint g = inverseGaussMap(sphere, m, opt.singular_tol);
  const Vec3 mdot = -(pose.R.transpose() * (ndot - body.w.cross(n)));
  finishPoint(pose, body, g, mdot, out);
  transportedFrame(S.pose.R, sup.w, out);  // the faces' frame, continuous across pieces
}

}  // namespace appell::detail
