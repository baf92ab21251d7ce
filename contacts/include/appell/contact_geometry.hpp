// Exact contact geometry between a smooth body shape and a (moving) support,
// with the rates the acceleration-level constraint terms need.
//
// Given the body pose {R, p} in the world, its world spatial velocity
// V = [ω; v_O] and the support's state, contactGeometry() finds the body point
// whose outward normal is −n (n: unit normal from the support toward the body):
//   plane           n = the plane normal
//   sphere, outside the body point nearest the sphere centre C
//   sphere, inside  the body point farthest from C (the bowl)
// and differentiates it. With m = −Rᵀn the body-frame normal, y = σ(m) the
// body point (shapes.hpp) and Σ = dσ/dm:
//   plane:   ṅ = Ω × n,        ṁ = Rᵀ((ω − Ω) × n)
//   sphere:  s = Rᵀ(C − p),  y − s = ε d m  (ε = −1 outside, +1 inside),
//            ṡ = Rᵀ(V_S(C) − V_B(C)),  (Σ − ε d)|_{m⊥} ṁ = (1 − m mᵀ) ṡ,
//            ṅ = ω × n − R ṁ
//   both:    ẋ = V_B(x) + R Σ ṁ      (material velocity + rolling of the point)
// (docs/contacts.md derives these.) Everything is fixed-size; no allocation.
#pragma once

#include <appell/shapes.hpp>
#include <appell/supports.hpp>

#include <span>

namespace appell {

struct ContactGeometry {
  Vec3 point = Vec3::Zero();          ///< contact point on the body, world
  Vec3 point_body = Vec3::Zero();     ///< the same point, body frame
  Vec3 support_point = Vec3::Zero();  ///< nearest point on the support, world (= point − gap n)
  Vec3 normal = Vec3::UnitZ();        ///< unit, from the support toward the body
  Vec3 t1 = Vec3::UnitX(), t2 = Vec3::UnitY();  ///< tangent frame, (t1, t2, n) right-handed
  double gap = 0;                     ///< signed distance (negative: penetration)
  // Rates along the motion (world frame):
  Vec3 point_rate = Vec3::Zero();     ///< velocity of the geometric contact point on the body
  Vec3 normal_rate = Vec3::Zero();
  Vec3 t1_rate = Vec3::Zero(), t2_rate = Vec3::Zero();
  bool singular = false;
  const char* reason = nullptr;       ///< static text, set when singular
  double margin = 1;                  ///< GaussPoint::margin of the body's point (1: no singular limit)
  int iterations = 0;                 ///< Newton iterations (ellipsoid on a sphere), else 0
  /// The piece of a piecewise support the contact is on — a terrain's flat
  /// region, edge or vertex (terrain.hpp numbers them) — or −1 on a smooth
  /// support.
  int feature = -1;
};

struct GeometryOptions {
  /// Below this, directions count as parallel (a disk lying flat, a knife
  /// edge along the normal, a sphere centre on a wheel's axis).
  double singular_tol = 1e-9;
  /// Newton on the ellipsoid–sphere pair's secular equation F(t) = 0:
  /// converged when the step |Δt| ≤ newton_tol · (|t| + a_max²); at most
  /// max_iterations, else the state is reported singular.
  double newton_tol = 1e-15;
  int max_iterations = 60;
};

/// Computes `out` for a shape on a support surface. `body_velocity` is the
/// world spatial velocity [ω; v_O]. Singular or invalid configurations set
/// out.singular and out.reason and leave finite values (never NaN).
/// `latched_feature` ≥ 0 (a value of out.feature): the contact with that piece
/// of a terrain only, extended past its bounds — the simulator keeps a closed
/// contact on one piece between events (docs/contacts.md §4); −1 searches.
/// `excluded` (a search only): the pieces the other points of the same pair
/// hold (ContactSpec::points). The search then takes the nearest *separate*
/// piece not among them — one where the distance to the terrain has a local
/// minimum, a second place where the body touches (a ball in a valley on
/// both slopes) — within a reach of the body's size; with none in reach,
/// out.feature = −1 and out.gap = that reach, a lower bound of the gap.
void contactGeometry(const Shape& shape, const SupportSurface& surface,
                     const SupportState& support, const SE3& body_pose,
                     const Vec6& body_velocity, ContactGeometry& out,
                     const GeometryOptions& options = {}, int latched_feature = -1,
                     std::span<const int> excluded = {});

}  // namespace appell
