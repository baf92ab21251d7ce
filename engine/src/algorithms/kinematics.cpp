#include <appell/kinematics.hpp>

#include "model/joint_transform.hpp"

namespace appell {

namespace {

inline auto qSeg(const VecX& q, const Joint& j) { return q.segment(j.idx_q, j.nq); }
inline auto vSeg(const VecX& v, const Joint& j) { return v.segment(j.idx_v, j.nv); }

void placeBody(const Model& model, Data& data, const VecX& q, int i) {
  const Joint& j = model.joints[i];
  data.liMi[i] = model.placement[i] * detail::jointTransform(j, qSeg(q, j));
  const int p = model.parent[i];
  data.oMi[i] = p < 0 ? data.liMi[i] : data.oMi[p] * data.liMi[i];
}

/// Records the state the kinematics are now for (no allocation: Data sized them).
void stamp(Data& data, const VecX& q, const VecX* v) {
  data.kinematics_q = q;
  data.kinematics_has_v = v != nullptr;
  if (v) data.kinematics_v = *v;
}

}  // namespace

void forwardKinematics(const Model& model, Data& data, const VecX& q) {
  for (int i = 0; i < model.nbodies; ++i) placeBody(model, data, q, i);
  stamp(data, q, nullptr);
}

void forwardKinematics(const Model& model, Data& data, const VecX& q, const VecX& v) {
  for (int i = 0; i < model.nbodies; ++i) {
    placeBody(model, data, q, i);
    const Joint& j = model.joints[i];
    const int p = model.parent[i];
    Vec6 vi = detail::jointMotion(j, vSeg(v, j));
    if (p >= 0) vi += data.liMi[i].actInv(data.v[p]);
    data.v[i] = vi;
  }
  stamp(data, q, &v);
}

void forwardKinematicsIfStale(const Model& model, Data& data, const VecX& q, const VecX& v) {
  if (data.kinematics_has_v && data.kinematics_q.size() == q.size() &&
      data.kinematics_v.size() == v.size() && data.kinematics_q == q && data.kinematics_v == v)
    return;
  forwardKinematics(model, data, q, v);
}

void forwardKinematics(const Model& model, Data& data, const VecX& q, const VecX& v,
                       const VecX& a) {
  for (int i = 0; i < model.nbodies; ++i) {
    placeBody(model, data, q, i);
    const Joint& j = model.joints[i];
    const int p = model.parent[i];
    const Vec6 vJ = detail::jointMotion(j, vSeg(v, j));
    Vec6 vi = vJ, ai = detail::jointMotion(j, vSeg(a, j));
    if (p >= 0) {
      vi += data.liMi[i].actInv(data.v[p]);
      ai += data.liMi[i].actInv(data.a[p]);
    }
    // Featherstone (2008) eq. 5.7: a_i = X a_p + S q̈ + v_i × S q̇  (Ṡ = 0 here).
    data.v[i] = vi;
    data.a[i] = ai + crossMotion(vi, vJ);
  }
  stamp(data, q, &v);
}

Vec6 spatialVelocityWorld(const Data& data, int body) { return data.oMi[body].act(data.v[body]); }
Vec6 spatialAccelerationWorld(const Data& data, int body) { return data.oMi[body].act(data.a[body]); }

void spatialJacobianWorld(const Model& model, const Data& data, int body, MatX& J) {
  J.setZero(6, model.nv);
  for (int k = body; k >= 0; k = model.parent[k]) {
    const Joint& j = model.joints[k];
    for (int c = 0; c < j.nv; ++c) J.col(j.idx_v + c) = data.oMi[k].act(j.S.col(c));
  }
}

Vec3 pointPosition(const Data& data, int body, const Vec3& r) { return data.oMi[body].apply(r); }

Vec6 pointVelocity(const Data& data, int body, const Vec3& r) {
  const Vec6& v = data.v[body];
  const Mat3& R = data.oMi[body].R;
  return spatial(R * angular(v), R * (linear(v) + angular(v).cross(r)));
}

Vec6 pointAcceleration(const Data& data, int body, const Vec3& r) {
  // Classical acceleration of a body point from the spatial acceleration
  // (Featherstone 2008, §2.11): p̈ = a_O + α × r + ω × (v_O + ω × r), body coordinates.
  const Vec6& v = data.v[body];
  const Vec6& a = data.a[body];
  const Vec3 w = angular(v);
  const Mat3& R = data.oMi[body].R;
  const Vec3 acc = linear(a) + angular(a).cross(r) + w.cross(linear(v) + w.cross(r));
  return spatial(R * angular(a), R * acc);
}

void pointJacobian(const Model& model, const Data& data, int body, const Vec3& r, MatX& J) {
  const Vec3 x = pointPosition(data, body, r);
  J.setZero(6, model.nv);
  for (int k = body; k >= 0; k = model.parent[k]) {
    const Joint& j = model.joints[k];
    for (int c = 0; c < j.nv; ++c) {
      const Vec6 s = data.oMi[k].act(j.S.col(c));
      J.col(j.idx_v + c) << angular(s), linear(s) + angular(s).cross(x);
    }
  }
}

Vec6 pointJacobianDotTimesV(const Data& data, int body, const Vec3& r) {
  return pointAcceleration(data, body, r);
}

}  // namespace appell
