// Contacts of non-smooth shapes: a box, a cylinder standing on a face, a mesh
// foot become point contacts at their vertices.
//
// Why vertices. A convex polyhedron touches a convex support first at a
// vertex; an edge or face contact is several vertices touching at once, and
// the reaction of a face pressed flat is carried by its corners (any force
// distribution over a convex face is a convex combination of corner forces —
// the contact "polygon" of Trinkle, Pang, Sudarsky & Lo, "On dynamic
// multi-rigid-body contact problems with Coulomb friction", ZAMM 1997). So
// each candidate vertex becomes its own unilateral point contact (a
// PointShape contact of the same support), they make and break as events
// (contact_events.hpp), and a box landing flat closes four corners in one
// mode decision; their rows are redundant (4 normal rows on 3 freedoms) and
// the solvers' redundant-row handling shares the load (minimum norm).
//
// Candidate vertices (body frame):
//   Box       its 8 corners
//   Mesh      the vertices of the convex hull of its triangles (Qhull:
//             Barber, Dobkin & Huhdanpaa, "The Quickhull algorithm for convex
//             hulls", ACM TOMS 1996); a non-convex mesh foot touches with its
//             hull's vertices on a convex support. A hull of more than
//             kMaxHullContacts vertices (a scanned or finely tessellated
//             part: 10⁵ of them) is reduced to its support points in
//             kMaxHullContacts directions spread evenly over the sphere (a
//             spherical Fibonacci lattice: González, "Measurement of areas on
//             a sphere using Fibonacci and latitude–longitude lattices",
//             Math. Geosciences 2010): the vertex farthest along each
//             direction. The reduced set is the contact set of a polytope
//             inscribed in the hull whose support function is exact in those
//             directions; for a round hull of radius R the gap it leaves is
//             about R(1 − cos(δ/2)), δ ≈ √(4π/K) the directions' spacing
//             (1.2 % of R for K = 128). Every hull corner whose normal cone
//             holds one of the directions is kept — all 8 of a box.
//   Cylinder  its two rims as regular polygons of `rim_points` vertices (a
//             prism: standing on a face is exact; rolling on a rim is not —
//             a rim that rolls is a `disk` contact)
// Kinds: Sliding gives frictionless points (one normal row each); Rolling
// gives sticking points (the body point does not slip: two tangent rows and
// the normal row), which slip as Coulomb friction allows when μ is finite.
//
// What vertices do not cover: a support's own vertex or edge pressing into a
// face of the shape (a box landing on a terrain ridge). On a plane or the
// outside of a sphere that cannot happen; on a terrain mesh it can, and FCL's
// collide() on the whole shape (collision.hpp) is what detects it.
#pragma once

#include <appell/contacts.hpp>

#include <memory>
#include <string>
#include <vector>

namespace appell {

/// At most this many vertex contacts for a mesh (see above).
constexpr int kMaxHullContacts = 128;

/// Candidate contact vertices of a box, cylinder or mesh (body frame).
/// Throws std::invalid_argument naming the shape for any other shape, a mesh
/// without triangles, or a mesh whose vertices span no volume or area. When
/// a mesh's hull had to be reduced, `hull_vertices` (if given) receives the
/// mesh's vertex count, else 0. A mesh of more than 2·10⁴ vertices skips the
/// hull altogether: its support points are found among all its vertices
/// (the farthest point along a direction is a hull vertex), O(K n).
std::vector<Vec3> contactVertices(const Shape& shape, int rim_points = 16, int* hull_vertices = nullptr);

/// One point contact per candidate vertex of spec.shape, each with spec's
/// support, μ, restitution and unilateral flag, named "<spec name>/v<k>".
/// spec.kind must be Sliding or Rolling. Throws std::invalid_argument naming
/// the contact. When a mesh hull was reduced, `warning` (if given) receives
/// one line saying so (the loader's warning); it is left alone otherwise.
std::vector<std::shared_ptr<ShapeContact>> makeVertexContacts(const ContactSpec& spec,
                                                              int rim_points = 16,
                                                              std::string* warning = nullptr);

}  // namespace appell
