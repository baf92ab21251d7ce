// Format versions of the <appell> block: a scene whose numbers would mean
// something else under the current conventions is read as written when it
// says its format, and warned about when it does not.
//
// Format 1 → 2 (commit 44be170): a planar joint with normal a moved along
// t₁ = unitOrthogonal(a) (Eigen's: for a = z, t₁ = −y), t₂ = a × t₁; it now
// moves along t₁ = the joint frame's x (y when a is within 45° of x) projected
// into the plane, t₂ = a × t₁. Both pairs are right-handed about a, so the
// new in-plane coordinates are the old ones turned by the fixed rotation
//   C = [t₁ₙ·t₁ₒ  t₁ₙ·t₂ₒ; t₂ₙ·t₁ₒ  t₂ₙ·t₂ₒ]:
// positions x_n = C x_o; the angle φ about a is the same; the body-frame
// velocities v_n = C v_o (2-D rotations commute with Rot(φ) in
// (ẋ₁, ẋ₂) = Rot(φ)(v₁, v₂)); the efforts f_n = C f_o (C orthogonal keeps
// the power f·v).
#include "scene/block.hpp"

#include <cmath>
#include <sstream>

namespace appell::io {

namespace {

// A direction as a message shows it: components rounded to 1e-6, no "-0".
std::string shown(const Vec3& v) {
  std::ostringstream s;
  s << "(";
  for (int k = 0; k < 3; ++k) {
    const double c = std::round(v[k] * 1e6) / 1e6;
    s << (k ? " " : "") << (c == 0 ? 0.0 : c);
  }
  s << ")";
  return s.str();
}

}  // namespace

void applySceneFormat(const XmlSource& src, const AppellBlock& block, Scene& scene) {
  if (!block.element || block.format == kSceneFormat) return;
  const Model& model = scene.model;
  for (int j = 0; j < model.nbodies; ++j) {
    const Joint& joint = model.joints[j];
    if (joint.type != JointType::Planar) continue;
    const Vec3 t1_old = joint.axis.unitOrthogonal(), t2_old = joint.axis.cross(t1_old);
    Eigen::Matrix2d C;
    C << joint.t1.dot(t1_old), joint.t1.dot(t2_old), joint.t2.dot(t1_old), joint.t2.dot(t2_old);
    if ((C - Eigen::Matrix2d::Identity()).cwiseAbs().maxCoeff() < 1e-12) continue;  // unchanged
    if (block.format == 1) {
      scene.q0.segment<2>(joint.idx_q) = C * scene.q0.segment<2>(joint.idx_q);
      scene.v0.segment<2>(joint.idx_v) = C * scene.v0.segment<2>(joint.idx_v);
      scene.tau.segment<2>(joint.idx_v) = C * scene.tau.segment<2>(joint.idx_v);
      continue;
    }
    scene.warnings.push_back(located(
        src, block.element,
        "no format given, read as format=\"" + std::to_string(kSceneFormat) + "\": planar joint '" +
            model.joint_names[j] + "' moves along t1 = " + shown(joint.t1) + ", t2 = " + shown(joint.t2) +
            " of its joint frame (<initial>, <effort> and the CSV columns .x .y, .vx .vy); scenes written before "
            "format 2 meant t1 = " + shown(t1_old) + ", t2 = " + shown(t2_old) +
            " — write <appell format=\"2\"> to keep the new meaning, format=\"1\" to read the old one"));
  }
}

}  // namespace appell::io
