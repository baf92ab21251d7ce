// Test-only constraints for the solver, projection and simulator tests (small,
// exact, independent of the contacts module):
//   BodyRows     rows fixed in one body's frame (a body-fixed covector w_b;
//                world covector = the body pose acting on it). A body-fixed
//                covector has κ = 0 exactly: d/dt (W·V) = W·a because
//                Ẇ = V ×* W and (V ×* W)·V = 0. Covers knife edges (lateral
//                velocity of a blade point) and point rows.
//   RollingBall  a sphere of radius R centred at a body's origin rolling on the
//                plane z = 0: material velocity at the lowest point x = p − R e_z
//                along e_x, e_y (no slip) and e_z (holonomic, gap p_z − R).
//                The contact point moves with ẋ = ṗ, so κ = tᵀ(ω × ṗ).
#pragma once

#include <appell/appell.hpp>
#include <appell/kinematics.hpp>

#include <string>
#include <vector>

namespace appell::test {

inline Vec6 pointRow(const Vec3& x, const Vec3& t) {
  Vec6 w;
  w << x.cross(t), t;
  return w;
}

class BodyRows final : public Constraint {
 public:
  BodyRows(std::string name, int body, std::vector<Vec6> rows_body, std::vector<double> b = {},
           std::vector<double> kappa = {})
      : name_(std::move(name)), body_(body), w_(std::move(rows_body)), b_(std::move(b)),
        kappa_(std::move(kappa)) {
    b_.resize(w_.size(), 0.0);
    kappa_.resize(w_.size(), 0.0);
  }
  const std::string& name() const override { return name_; }
  int rows() const override { return static_cast<int>(w_.size()); }
  int bodyA() const override { return body_; }
  RowKind rowKind(int) const override { return RowKind::Custom; }
  std::string rowLabel(int k) const override { return "r" + std::to_string(k); }
  bool holonomic(int) const override { return false; }
  void evaluate(const Model&, const Data& data, double, const VecX&, const VecX&,
                RowBlock& out) const override {
    const SE3& X = data.oMi[body_];
    for (int k = 0; k < rows(); ++k) {
      out.Wa.row(k) = X.actForce(w_[k]).transpose();
      out.b[k] = b_[k];
      out.kappa[k] = kappa_[k];
      out.gap[k] = 0;
    }
    out.frame.point = X.p;
  }

 private:
  std::string name_;
  int body_;
  std::vector<Vec6> w_;
  std::vector<double> b_, kappa_;
};

class RollingBall final : public Constraint {
 public:
  RollingBall(std::string name, int body, double radius)
      : name_(std::move(name)), body_(body), R_(radius) {}
  const std::string& name() const override { return name_; }
  int rows() const override { return 3; }
  int bodyA() const override { return body_; }
  RowKind rowKind(int k) const override {
    static constexpr RowKind kinds[] = {RowKind::Tangent1, RowKind::Tangent2, RowKind::Normal};
    return kinds[k];
  }
  bool holonomic(int k) const override { return k == 2; }
  void evaluate(const Model&, const Data& data, double, const VecX&, const VecX&,
                RowBlock& out) const override {
    const Vec3 p = data.oMi[body_].p;
    const Vec6 V = spatialVelocityWorld(data, body_);
    const Vec3 w = V.head<3>();
    const Vec3 pdot = V.tail<3>() + w.cross(p);
    const Vec3 x = p - R_ * Vec3::UnitZ();
    for (int k = 0; k < 3; ++k) {
      const Vec3 t = Vec3::Unit(k);
      out.Wa.row(k) = pointRow(x, t).transpose();
      out.b[k] = 0;
      out.kappa[k] = t.dot(w.cross(pdot));
      out.gap[k] = 0;
    }
    out.gap[2] = p.z() - R_;
    out.frame.point = x;
    out.frame.normal = Vec3::UnitZ();
    out.frame.gap = p.z() - R_;
  }

 private:
  std::string name_;
  int body_;
  double R_;
};

/// A ball (floating joint): mass m, rotational inertia `I` about the centre of
/// mass, the centre of mass at `com` from the geometric centre (body origin).
inline Model ballModel(double m, const Mat3& I, const Vec3& com, const Vec3& g = {0, 0, -9.81}) {
  ModelBuilder b;
  b.addBody("ball", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(), Inertia{m, com, I},
            "free");
  b.setGravity(g);
  return b.build();
}

/// Emelyanova–Fufaev sleigh on an incline of angle α in world coordinates: prismatic x,
/// prismatic y (y down the slope), revolute φ; blade point at the last body's
/// origin with blade direction e_x (body), centre of mass at distance l
/// perpendicular to the blade, (0, −l) in the body, so U = m g (y − l cos φ) sin α.
/// The carriages carry `carriage_mass` each.
inline Model sleighModel(double m, double Izz, double l, double alpha, double carriage_mass) {
  ModelBuilder b;
  const Mat3 Ic = Vec3(carriage_mass * 0.01, carriage_mass * 0.01, carriage_mass * 0.01).asDiagonal();
  b.addBody("cx", -1, SE3::Identity(), JointType::Prismatic, Vec3::UnitX(),
            Inertia{carriage_mass, Vec3::Zero(), Ic}, "x");
  b.addBody("cy", 0, SE3::Identity(), JointType::Prismatic, Vec3::UnitY(),
            Inertia{carriage_mass, Vec3::Zero(), Ic}, "y");
  b.addBody("sleigh", 1, SE3::Identity(), JointType::Revolute, Vec3::UnitZ(),
            Inertia{m, Vec3(0, -l, 0), Vec3(Izz, Izz, Izz).asDiagonal()}, "phi");
  b.setGravity(Vec3(0, 9.81 * std::sin(alpha), -9.81 * std::cos(alpha)));
  return b.build();
}

/// The blade row: lateral velocity of the blade point (body origin), direction e_y (body).
inline std::shared_ptr<BodyRows> knifeEdge(int body, const std::string& name = "blade") {
  return std::make_shared<BodyRows>(name, body, std::vector<Vec6>{pointRow(Vec3::Zero(), Vec3::UnitY())});
}

}  // namespace appell::test
