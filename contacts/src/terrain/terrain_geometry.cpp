// A smooth shape on a terrain mesh: the plane contact with the face that holds
// its contact point (terrain.hpp states the model).
#include "geometry_internal.hpp"
#include "terrain_index.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

namespace appell::detail {

namespace {

// Barycentric coordinates of p in face f (support frame), from signed areas
// along the face normal.
Vec3 barycentric(const TerrainMesh& t, const TerrainIndex& idx, int f, const Vec3& p) {
  const auto& tri = t.triangles[f];
  const Vec3& a = t.vertices[tri[0]];
  const Vec3& b = t.vertices[tri[1]];
  const Vec3& c = t.vertices[tri[2]];
  const Vec3& n = idx.normal[f];
  const double area = n.dot((b - a).cross(c - a));
  return Vec3(n.dot((b - p).cross(c - p)), n.dot((c - p).cross(a - p)),
              n.dot((a - p).cross(b - p))) /
         area;
}

constexpr double kInsideTol = 1e-12;
/// How much nearer than a holding face an edge or vertex must be (m).
constexpr double kFaceMargin = 1e-12;

// Reason text naming the edge or vertex; a per-thread buffer so that setting
// it does not allocate (valid until this thread's next terrain query).
const char* edgeReason(const TerrainMesh& t, const TerrainIndex& idx, int f, const Vec3& lambda) {
  thread_local char text[200];
  int negative = 0, k_neg = 0, k_pos = 0;
  for (int k = 0; k < 3; ++k) {
    if (lambda(k) < -kInsideTol) {
      ++negative;
      k_neg = k;
    } else {
      k_pos = k;
    }
  }
  if (negative == 1) {
    const int j = idx.neighbour[f][k_neg];
    if (j >= 0)
      std::snprintf(text, sizeof text,
                    "contact on a terrain edge between faces %d and %d (no face holds the contact "
                    "point; the surface has no tangent plane there)",
                    f, j);
    else
      std::snprintf(text, sizeof text,
                    "contact beyond the terrain's boundary edge of face %d (vertices %d, %d)", f,
                    t.triangles[f][(k_neg + 1) % 3], t.triangles[f][(k_neg + 2) % 3]);
  } else {
    std::snprintf(text, sizeof text,
                  "contact on terrain vertex %d (corner of face %d; no face holds the contact "
                  "point)",
                  t.triangles[f][k_pos], f);
  }
  return text;
}

// The contact with one feature, extended past its bounds: a region's plane
// beyond its faces, an edge's line beyond its ends. Between events the
// simulator keeps each closed contact on the feature it had at the event
// (docs/contacts.md §4): the dynamics inside a step are then smooth, and a
// change of feature is an event located for all contacts together.
void latchedGeometry(const Shape& shape, const TerrainMesh& t, int feature, const SupportState& S,
                     const SE3& pose, const Vec6& V, ContactGeometry& out,
                     const GeometryOptions& opt) {
  const TerrainIndex& idx = *t.index;
  out.singular = false;
  out.reason = nullptr;
  if (feature < idx.regions) {
    Plane plane;
    plane.point = t.vertices[t.triangles[idx.region_face[feature]][0]];
    plane.normal = idx.normal[idx.region_face[feature]];
    planeGeometry(shape, plane, S, pose, V, out, opt);
  } else if (feature < idx.regions + idx.edges) {
    const auto& ends = idx.edge_ends[feature - idx.regions];
    if (!terrainEdgeGeometry(shape, t.vertices[ends[0]], t.vertices[ends[1]], S, pose, V, out, opt,
                             false))
      markSingular(out, "no contact with the terrain edge the contact is latched to (the body "
                        "lies across its line)");
  } else if (feature < idx.regions + idx.edges + static_cast<int>(t.vertices.size())) {
    if (!terrainVertexGeometry(shape, t.vertices[feature - idx.regions - idx.edges], S, pose, V,
                               out, opt))
      markSingular(out, "no contact with the terrain vertex the contact is latched to");
  } else {
    markSingular(out, "latched terrain feature out of range");
  }
  out.feature = feature;
}

// Whether an edge or vertex contact's normal n (support frame) leaves the
// surface on its outer side (its pseudonormal's, TerrainIndex): a body that
// has passed through an edge in one step of free flight is nearest to it
// from behind, where it is no contact (the faces' planes give its negative
// gap there).
bool frontSide(const TerrainIndex& idx, int piece, const Vec3& n) {
  if (piece < idx.regions) return true;
  if (piece < idx.regions + idx.edges) return n.dot(idx.edge_normal[piece - idx.regions]) > 0;
  return n.dot(idx.vertex_normal[piece - idx.regions - idx.edges]) > 0;
}

// An edge between two faces of one flat region.
bool internalEdge(const TerrainIndex& idx, int e) {
  const auto& f = idx.edge_face[e];
  return f[1] >= 0 && idx.region[f[0]] == idx.region[f[1]];
}

// Box of the body in the support frame from its extreme points along the
// support axes, and half its largest side.
double bodyBox(const Shape& shape, const SupportState& S, const SE3& pose,
               const GeometryOptions& opt, Vec3& lo, Vec3& hi) {
  const SE3 inv = S.pose.inverse();
  for (int i = 0; i < 3; ++i) {
    for (int s = -1; s <= 1; s += 2) {
      const Vec3 d = S.pose.R.col(i) * static_cast<double>(s);
      const GaussPoint g = inverseGaussMap(shape, pose.R.transpose() * d, opt.singular_tol);
      const double x = inv.apply(pose.apply(g.y))(i);
      if (s < 0) lo(i) = x;
      else hi(i) = x;
    }
  }
  return 0.5 * (hi - lo).maxCoeff() + 1e-9;
}

// Another point of a pair whose other points hold `excluded`: the nearest
// separate piece (separatePiece) not among them whose gap is within the
// margin of the body box (half the body's largest side), else that margin
// as the gap. One query of the box grown by the margin holds every such
// piece (a face with gap g meets the box grown by |g|).
void separateGeometry(const Shape& shape, const TerrainMesh& t, const SupportState& S,
                      const SE3& pose, const Vec6& V, ContactGeometry& out,
                      const GeometryOptions& opt, std::span<const int> excluded) {
  const TerrainIndex& idx = *t.index;
  Vec3 lo, hi;
  const double margin = bodyBox(shape, S, pose, opt, lo, hi);
  lo.array() -= margin;
  hi.array() += margin;
  const SE3 inv = S.pose.inverse();
  const Vec3 c_s = inv.apply(pose.apply(shapeCentre(shape)));
  const double bound = boundingRadius(shape);
  double best_gap = margin;
  int best = -1;
  ContactGeometry trial;
  // Where the body touches the excluded pieces (extended, as latched): a
  // candidate there is the same place of contact seen from the next piece.
  std::array<Vec3, 4> held;
  int nheld = 0;
  for (int e : excluded) {
    if (nheld == 4) break;
    latchedGeometry(shape, t, e, S, pose, V, trial, opt);
    if (!trial.singular) held[nheld++] = trial.support_point;
  }
  const double same = kSamePlace * boundingRadius(shape);
  auto take = [&](int piece) {
    const Vec3 n = S.pose.R.transpose() * trial.normal;
    if (!(trial.gap < best_gap) || excludedPiece(excluded, piece) ||
        !frontSide(idx, piece, n) || !separatePiece(t, piece, n))
      return;
    for (int i = 0; i < nheld; ++i)
      if ((trial.support_point - held[i]).norm() <= same) return;
    best = piece;
    best_gap = trial.gap;
    out = trial;
  };
  forEachFaceInBox(idx, lo, hi, [&](int f) {
    const auto& tri = t.triangles[f];
    Plane plane;
    plane.point = t.vertices[tri[0]];
    plane.normal = idx.normal[f];
    trial.singular = false;
    trial.reason = nullptr;
    planeGeometry(shape, plane, S, pose, V, trial, opt);
    if (barycentric(t, idx, f, inv.apply(trial.support_point)).minCoeff() >= -kInsideTol) {
      take(idx.regionFeature(f));
      return;
    }
    // Its edges and vertices, when the triangle can be nearer than the best.
    const double reach =
        (c_s - nearestPointOnTriangle(c_s, t.vertices[tri[0]], t.vertices[tri[1]],
                                      t.vertices[tri[2]]))
            .norm() -
        bound;
    if (!(trial.gap < best_gap) || !(reach < best_gap)) return;
    // An edge between two faces of one flat region, and a vertex all of whose
    // edges are such, are never separate (their normal cannot lean out of a
    // plane on both sides): no solve for them.
    for (int k = 0; k < 3; ++k) {
      const int e = idx.edge[f][k];
      const auto& ends = idx.edge_ends[e];
      if (!internalEdge(idx, e) &&
          terrainEdgeGeometry(shape, t.vertices[ends[0]], t.vertices[ends[1]], S, pose, V, trial,
                              opt))
        take(idx.edgeFeature(f, k));
      const int w = idx.weld[tri[k]];
      bool interior = true;
      for (int i = idx.vertex_edge_start[w]; i < idx.vertex_edge_start[w + 1] && interior; ++i)
        interior = internalEdge(idx, idx.vertex_edge[i]);
      if (!interior && terrainVertexGeometry(shape, t.vertices[w], S, pose, V, trial, opt))
        take(idx.vertexFeature(tri[k]));
    }
  });
  if (best < 0) {
    noPieceInReach(S, pose, margin, out);
    return;
  }
  out.feature = best;
}

}  // namespace

void terrainGeometry(const Shape& shape, const TerrainMesh& terrain, const SupportState& S,
                     const SE3& pose, const Vec6& V, ContactGeometry& out,
                     const GeometryOptions& opt, int latched, std::span<const int> excluded) {
  if (!terrain.index) {
    out = ContactGeometry{};
    markSingular(out, "terrain index not built (create the mesh with makeTerrain)");
    return;
  }
  const TerrainIndex& idx = *terrain.index;
  if (const auto* sphere = std::get_if<Sphere>(&shape)) {
    terrainSphereGeometry(*sphere, terrain, S, pose, V, out, opt, latched, excluded);
    return;
  }
  if (latched >= 0) {
    latchedGeometry(shape, terrain, latched, S, pose, V, out, opt);
    return;
  }
  if (!excluded.empty()) {
    separateGeometry(shape, terrain, S, pose, V, out, opt, excluded);
    return;
  }

  // The body's box grown by half its largest side: every face whose plane
  // contact lies within that margin of the body overlaps it.
  const SE3 inv = S.pose.inverse();
  Vec3 lo, hi;
  const double margin = bodyBox(shape, S, pose, opt, lo, hi);
  lo.array() -= margin;
  hi.array() += margin;

  ContactGeometry trial, feature;
  bool features = false;
  // The body's bounding sphere (support frame): centre and radius.
  const Vec3 c_s = inv.apply(pose.apply(shapeCentre(shape)));
  const double bound = boundingRadius(shape);
  int best = -1, nearest = -1, best_feature = -1;
  double nearest_gap = INFINITY;  // the ranking score below
  Vec3 nearest_lambda = Vec3::Zero();
  auto consider = [&](int f) {
    Plane plane;
    plane.point = terrain.vertices[terrain.triangles[f][0]];
    plane.normal = idx.normal[f];
    trial.singular = false;
    trial.reason = nullptr;
    planeGeometry(shape, plane, S, pose, V, trial, opt);
    const Vec3 foot = inv.apply(trial.support_point);
    const Vec3 lambda = barycentric(terrain, idx, f, foot);
    if (lambda.minCoeff() >= -kInsideTol) {
      if (best < 0 || trial.gap < out.gap) {
        best = f;
        best_feature = idx.regionFeature(f);
        out = trial;
      }
      return;
    }
    if (!features) return;
    // Not held by its face: the body may be nearest to one of its edges or
    // vertices (over a crease or a corner). The face's plane gap bounds the
    // triangle's distance from below, so only a triangle whose plane is
    // nearer than the best contact so far is worth those solves. An edge or
    // vertex counts from its outer side only (frontSide): a body that has
    // passed through it is behind the surface, not touching it; from that
    // side its gap is signed like a face's, so a body falling onto a ridge
    // is seen sinking into it (the touchdown's event function).
    // Near a convex edge the edge's gap exceeds the face's by only
    // O(distance² / radius): an edge or vertex must beat a holding face by
    // more than round-off (kFaceMargin), or the piece flickers to the edge
    // before the contact point reaches it.
    auto better = [&](const ContactGeometry& g, int piece) {
      if (!frontSide(idx, piece, S.pose.R.transpose() * g.normal)) return false;
      if (best < 0) return true;
      return g.gap < out.gap - (best_feature < idx.regions ? kFaceMargin : 0.0);
    };
    // A second, sharper lower bound: the distance from the body's bounding
    // sphere to the triangle.
    const auto& tri = terrain.triangles[f];
    const double reach =
        (c_s - nearestPointOnTriangle(c_s, terrain.vertices[tri[0]], terrain.vertices[tri[1]],
                                      terrain.vertices[tri[2]]))
            .norm() -
        bound;
    if (best < 0 || (trial.gap < out.gap && reach < out.gap)) {
      for (int k = 0; k < 3; ++k) {
        // Each edge with its welded ends in one order, whichever face offers
        // it, so that its tangent frame is the latched edge's (same rows).
        const auto& ends = idx.edge_ends[idx.edge[f][k]];
        if (terrainEdgeGeometry(shape, terrain.vertices[ends[0]], terrain.vertices[ends[1]], S,
                                pose, V, feature, opt) &&
            better(feature, idx.edgeFeature(f, k))) {
          best = f;
          best_feature = idx.edgeFeature(f, k);
          out = feature;
        }
        if (terrainVertexGeometry(shape, terrain.vertices[idx.weld[tri[k]]], S, pose, V, feature,
                                  opt) &&
            better(feature, idx.vertexFeature(tri[k]))) {
          best = f;
          best_feature = idx.vertexFeature(tri[k]);
          out = feature;
        }
      }
    }
    if (best < 0) {
      // Rank the faces that do not hold the point by |gap| plus how far the
      // foot lies outside the triangle (max over edges of −λ_k times the
      // altitude onto edge k): the face the body is over names the edge.
      const double area2 = std::abs(
          idx.normal[f].dot((terrain.vertices[tri[1]] - terrain.vertices[tri[0]])
                                .cross(terrain.vertices[tri[2]] - terrain.vertices[tri[0]])));
      double outside = 0;
      for (int k = 0; k < 3; ++k) {
        const double edge =
            (terrain.vertices[tri[(k + 2) % 3]] - terrain.vertices[tri[(k + 1) % 3]]).norm();
        outside = std::max(outside, -lambda(k) * area2 / edge);
      }
      const double score = std::abs(trial.gap) + outside;
      if (score >= nearest_gap) return;
      nearest = f;
      nearest_gap = score;
      nearest_lambda = lambda;
      out = trial;  // finite values to leave if no face holds the point
    }
  };
  // Widen the box until it must hold the best face: a face holding the
  // contact with gap g meets the body's box grown by |g| (its foot is that
  // far from a body point), so once a holding face with |gap| ≤ margin is
  // known, no face outside the box can do better. Without a holding face
  // the margin doubles until the box covers the whole terrain. A body high
  // above the terrain (an open contact in flight) costs O(log n) queries,
  // not a sweep over every face.
  const auto& root = idx.bvh->getBV(0).bv.obb;
  const Vec3 root_half = root.axis.cwiseAbs() * root.extent;
  for (double m = margin;; m = best >= 0 ? std::abs(out.gap) * (1 + 1e-9) + 1e-12 : 2 * m) {
    const Vec3 qlo = lo.array() - (m - margin), qhi = hi.array() + (m - margin);
    // Faces first (cheap, and usually one holds), then the edges and
    // vertices of the triangles that could still be nearer.
    features = false;
    detail::forEachFaceInBox(idx, qlo, qhi, consider);
    features = true;
    detail::forEachFaceInBox(idx, qlo, qhi, consider);
    if (best >= 0 && std::abs(out.gap) <= m) break;
    const bool covers = ((qlo - (root.To - root_half)).array() <= 0).all() &&
                        ((qhi - (root.To + root_half)).array() >= 0).all();
    if (covers) break;
  }
  if (best >= 0) {
    out.feature = best_feature;
    return;
  }
  out.feature = -1;
  if (nearest < 0) {
    markSingular(out, "no terrain face near the body");
    return;
  }
  markSingular(out, edgeReason(terrain, idx, nearest, nearest_lambda));
}

}  // namespace appell::detail
