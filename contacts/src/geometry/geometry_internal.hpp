// Private pieces shared by the contact-geometry sources.
#pragma once

#include <appell/contact_geometry.hpp>
#include <appell/overloaded.hpp>

#include <cmath>

namespace appell::detail {

/// World spatial velocity split into its parts.
struct Twist {
  Vec3 w, v;  ///< ω and v_O
  explicit Twist(const Vec6& V) : w(V.head<3>()), v(V.tail<3>()) {}
  Vec3 at(const Vec3& x) const { return v + w.cross(x); }
};

/// Marks `out` singular with a static reason; keeps the finite values already there
/// and zeroes the rates (they are unusable there).
void markSingular(ContactGeometry& out, const char* reason);

/// Fills point, point_body and point_rate from the body-frame normal m, its rate
/// ṁ and the Gauss point at m:  x = R y + p,  ẋ = V_B(x) + R Σ ṁ.
void finishPoint(const SE3& pose, const Twist& body, const GaussPoint& g, const Vec3& mdot,
                 ContactGeometry& out);

/// t1 = normalize((1 − n nᵀ) e), t2 = n × t1 and their rates, for a reference
/// direction e(t) of any length with rate ė (needs n, ṅ in `out`). Requires
/// |(1 − n nᵀ) e| well above zero relative to |e| (callers pick e so that it
/// is ≥ |e|/√2).
void tangentFrame(const Vec3& e, const Vec3& edot, ContactGeometry& out);

/// The tangent frame of every smooth support (plane, sphere, terrain piece):
/// the frame (−y_S, x_S) at the support's pole p = z_S (R_S's third column)
/// carried to n along the great circle from p — the rotation R(p → n) about
/// p × n, i.e. parallel transport on the unit sphere of normals:
///     t1 = a − (p + n)(n·a)/(1 + p·n),  a = −y_S,   t2 = n × t1.
/// A smooth function of n and R_S everywhere but at the antipode n = −p (no
/// tangent field on a sphere lacks a singular point: the hairy-ball theorem),
/// so the rows' frame never switches along a path that avoids it
/// (docs/contacts.md §3). Needs n, ṅ in `out`; Ω is the support's angular
/// velocity (ṗ = Ω × p, ȧ = Ω × a).
void transportedFrame(const Mat3& RS, const Vec3& Omega, ContactGeometry& out);

/// Within this of the antipode (1 + p·n ≤ kAntipode, 1.4 µrad), where the
/// transported frame's round-off grows like ε/|p + n|, the frame is the
/// support's −y axis projected onto the tangent plane instead.
inline constexpr double kAntipode = 1e-12;

void planeGeometry(const Shape& shape, const Plane& plane, const SupportState& S, const SE3& pose,
                   const Vec6& V, ContactGeometry& out, const GeometryOptions& opt);

void sphereSurfaceGeometry(const Shape& shape, const SphereSurface& sphere, const SupportState& S,
                           const SE3& pose, const Vec6& V, ContactGeometry& out,
                           const GeometryOptions& opt);

/// Body-frame outward normal m of the shape's point nearest to (outside = true)
/// or farthest from (outside = false) the body-frame point s: in closed form,
/// or by Newton for the ellipsoid (`iterations` then counts its steps). Returns
/// false with a static reason where it is not unique or does not exist (m is
/// then a finite stand-in). Defined with the shapes (shapes.cpp).
bool extremalNormal(const Shape& shape, const Vec3& s, bool outside, const GeometryOptions& opt,
                    Vec3& m, int& iterations, const char*& reason);

/// Body-frame outward normal m of the ellipsoid point nearest to (outside = true)
/// or farthest from (outside = false) the body-frame point s, by Newton's method
/// on the tangential residual (1 − m mᵀ)(σ(m) − s) = 0. Returns false (with a
/// static reason) when it does not converge or the extremum is not the right kind.
bool ellipsoidExtremalNormal(const Ellipsoid& e, const Vec3& s, bool outside,
                             const GeometryOptions& opt, Vec3& m, int& iterations,
                             const char*& reason);

}  // namespace appell::detail
