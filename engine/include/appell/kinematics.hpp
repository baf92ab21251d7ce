// Forward kinematics and Jacobians of body-fixed points.
#pragma once

#include <appell/data.hpp>

namespace appell {

/// Pose of each body (liMi, oMi).
void forwardKinematics(const Model& model, Data& data, const VecX& q);
/// … and body velocities (data.v).
void forwardKinematics(const Model& model, Data& data, const VecX& q, const VecX& v);
/// … and body accelerations (data.a) for joint accelerations `a` (no gravity).
void forwardKinematics(const Model& model, Data& data, const VecX& q, const VecX& v,
                       const VecX& a);

/// forwardKinematics(q, v) unless data already holds it for exactly this
/// (q, v) (Data::kinematics_q/v): the tree solver after the constraint rows
/// were evaluated at the same state does the kinematics once.
void forwardKinematicsIfStale(const Model& model, Data& data, const VecX& q, const VecX& v);

/// World-frame spatial velocity V = [ω; v_O] and acceleration dV/dt of a body
/// (v_O: velocity of the body point now at the world origin).
Vec6 spatialVelocityWorld(const Data& data, int body);
Vec6 spatialAccelerationWorld(const Data& data, int body);
/// World-frame spatial Jacobian (6 × nv): V = J v. Needs forwardKinematics(q).
void spatialJacobianWorld(const Model& model, const Data& data, int body, MatX& J);

/// Kinematic quantities of a point fixed in a body, in the world frame.
/// Require forwardKinematics with at least the matching inputs first.
Vec3 pointPosition(const Data& data, int body, const Vec3& point_local);
/// [ω; ṗ] of the body and the point, world frame.
Vec6 pointVelocity(const Data& data, int body, const Vec3& point_local);
/// [α; p̈] (classical acceleration of the point), world frame.
Vec6 pointAcceleration(const Data& data, int body, const Vec3& point_local);

/// J (6 × nv) with [ω; ṗ] = J v for a point fixed in `body`, world frame.
/// Columns of joints not on the body's path are zero. Needs forwardKinematics(q).
void pointJacobian(const Model& model, const Data& data, int body, const Vec3& point_local,
                   MatX& J);
/// J̇ v for the same point: [α; p̈] when v̇ = 0. Needs forwardKinematics(q, v, 0).
Vec6 pointJacobianDotTimesV(const Data& data, int body, const Vec3& point_local);

}  // namespace appell
