// Simbody 3.7 model of the thin rolling disk (disk_problem.hpp).
//
// Simbody has exact rolling for spheres and edges but not for a disk rim, so the
// contact is a Constraint::Custom (Sherman, Seth & Delp, "Simbody: multibody
// dynamics for biomedical research", Procedia IUTAM 2, 2011, on how Simbody
// treats holonomic, nonholonomic and acceleration-only rows). With the disk
// centre c, axle a = R e_z, r = P − c = −R u, u = (e_z − a_z a)/s, s = √(1 − a_z²):
//   position row   c_z − R s = 0                                   (holonomic)
//   its derivative e_z · (v_c + ω × r)
//   its 2nd deriv. e_z · (a_c + α × r + ω × ṙ),  ṙ = −R u̇
//   velocity rows  e_x,y · (v_c + ω × r) = 0                       (nonholonomic)
//   their deriv.   e_x,y · (a_c + α × r + ω × ṙ)
// with ȧ = ω × a, ṡ = −a_z ȧ_z / s, u̇ = (−ȧ_z a − a_z ȧ)/s − u ṡ/s. The rows'
// forces are the multipliers applied at P (world frame), so Simbody's G and the
// forces it applies are transposes of each other, as its Custom interface asks.
#include "peer_engines.hpp"

#include <Simbody.h>

#include <stdexcept>

namespace peers {
namespace {

using namespace SimTK;

struct RimGeometry {
  Vec3 r, rdot;  // P − c and its time derivative (ṙ only when ω is given)
};

RimGeometry rimGeometry(const Rotation& R_GB, const Vec3* w, Real radius) {
  const Vec3 a = R_GB.z().asVec3();
  const Real s = std::sqrt(1 - a[2] * a[2]);
  const Vec3 u = (Vec3(0, 0, 1) - a[2] * a) / s;
  RimGeometry g;
  g.r = -radius * u;
  g.rdot = Vec3(0);
  if (w) {
    const Vec3 adot = *w % a;
    const Real sdot = -a[2] * adot[2] / s;
    const Vec3 udot = (-adot[2] * a - a[2] * adot) / s - u * (sdot / s);
    g.rdot = -radius * udot;
  }
  return g;
}

class RimContact : public Constraint::Custom::Implementation {
 public:
  RimContact(SimbodyMatterSubsystem& matter, const MobilizedBody& disk, Real radius)
      : Implementation(matter, 1, 2, 0), radius_(radius) {
    ground_ = addConstrainedBody(matter.Ground());
    disk_ = addConstrainedBody(disk);
  }
  Implementation* clone() const override { return new RimContact(*this); }

  void calcPositionErrors(const State&, const Array_<Transform, ConstrainedBodyIndex>& X_AB,
                          const Array_<Real, ConstrainedQIndex>&, Array_<Real>& perr) const override {
    const Transform& X = getBodyTransform(X_AB, disk_);
    const Real az = X.R().z()[2];
    perr[0] = X.p()[2] - radius_ * std::sqrt(1 - az * az);
  }
  void calcPositionDotErrors(const State& state, const Array_<SpatialVec, ConstrainedBodyIndex>& V_AB,
                             const Array_<Real, ConstrainedQIndex>&, Array_<Real>& pverr) const override {
    const RimGeometry g = rimGeometry(getBodyRotationFromState(state, disk_), nullptr, radius_);
    const SpatialVec& V = getBodyVelocity(V_AB, disk_);
    pverr[0] = (V[1] + V[0] % g.r)[2];
  }
  void calcPositionDotDotErrors(const State& state, const Array_<SpatialVec, ConstrainedBodyIndex>& A_AB,
                                const Array_<Real, ConstrainedQIndex>&, Array_<Real>& paerr) const override {
    paerr[0] = contactAcceleration(state, A_AB)[2];
  }
  void addInPositionConstraintForces(const State& state, const Array_<Real>& multipliers,
                                     Array_<SpatialVec, ConstrainedBodyIndex>& forces,
                                     Array_<Real, ConstrainedQIndex>&) const override {
    applyAtContact(state, Vec3(0, 0, multipliers[0]), forces);
  }
  void calcVelocityErrors(const State& state, const Array_<SpatialVec, ConstrainedBodyIndex>& V_AB,
                          const Array_<Real, ConstrainedUIndex>&, Array_<Real>& verr) const override {
    const RimGeometry g = rimGeometry(getBodyRotationFromState(state, disk_), nullptr, radius_);
    const SpatialVec& V = getBodyVelocity(V_AB, disk_);
    const Vec3 vp = V[1] + V[0] % g.r;
    verr[0] = vp[0];
    verr[1] = vp[1];
  }
  void calcVelocityDotErrors(const State& state, const Array_<SpatialVec, ConstrainedBodyIndex>& A_AB,
                             const Array_<Real, ConstrainedUIndex>&, Array_<Real>& vaerr) const override {
    const Vec3 ap = contactAcceleration(state, A_AB);
    vaerr[0] = ap[0];
    vaerr[1] = ap[1];
  }
  void addInVelocityConstraintForces(const State& state, const Array_<Real>& multipliers,
                                     Array_<SpatialVec, ConstrainedBodyIndex>& forces,
                                     Array_<Real, ConstrainedUIndex>&) const override {
    applyAtContact(state, Vec3(multipliers[0], multipliers[1], 0), forces);
  }

 private:
  // a_c + α × r + ω × ṙ: the derivative of v_c + ω × r with r = P − c.
  Vec3 contactAcceleration(const State& state, const Array_<SpatialVec, ConstrainedBodyIndex>& A_AB) const {
    const Vec3& w = getBodyAngularVelocityFromState(state, disk_);
    const RimGeometry g = rimGeometry(getBodyRotationFromState(state, disk_), &w, radius_);
    const SpatialVec& A = getBodyAcceleration(A_AB, disk_);
    return A[1] + A[0] % g.r + w % g.rdot;
  }
  void applyAtContact(const State& state, const Vec3& F, Array_<SpatialVec, ConstrainedBodyIndex>& forces) const {
    const RimGeometry g = rimGeometry(getBodyRotationFromState(state, disk_), nullptr, radius_);
    const Vec3 P = getBodyOriginLocationFromState(state, disk_) + g.r;
    forces[disk_][0] += g.r % F;
    forces[disk_][1] += F;
    forces[ground_][0] -= P % F;
    forces[ground_][1] -= F;
  }

  Real radius_;
  ConstrainedBodyIndex ground_, disk_;
};

Vec3 toSimTK(const V3& x) { return Vec3(x.x(), x.y(), x.z()); }
V3 fromSimTK(const Vec3& x) { return V3(x[0], x[1], x[2]); }

struct SimbodyDisk {
  MultibodySystem system;
  SimbodyMatterSubsystem matter{system};
  GeneralForceSubsystem forces{system};
  MobilizedBody::Free disk;
  State state;

  explicit SimbodyDisk(const DiskProblem& p) {
    if (p.half_thickness != 0) throw std::invalid_argument("simbody: thin disk only");
    Force::UniformGravity(forces, matter, Vec3(0, 0, -p.gravity));
    const Body::Rigid body(MassProperties(p.mass, Vec3(0), Inertia(p.A(), p.A(), p.C())));
    disk = MobilizedBody::Free(matter.Ground(), Transform(), body, Transform());
    Constraint::Custom(new RimContact(matter, disk, p.radius));
    system.realizeTopology();
    state = system.getDefaultState();
    Mat33 R;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) R(i, j) = p.initial.rotation(i, j);
    disk.setQToFitTransform(state, Transform(Rotation(R, true), toSimTK(p.initial.centre)));
    disk.setUToFitVelocity(state, SpatialVec(toSimTK(p.initial.omega), toSimTK(p.initial.velocity)));
    system.realize(state, Stage::Acceleration);
  }
  DiskState read(const State& s) const {
    system.realize(s, Stage::Velocity);
    DiskState d;
    const Transform& X = disk.getBodyTransform(s);
    d.centre = fromSimTK(X.p());
    const Mat33& R = X.R().asMat33();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) d.rotation(i, j) = R(i, j);
    const SpatialVec& V = disk.getBodyVelocity(s);
    d.omega = fromSimTK(V[0]);
    d.velocity = fromSimTK(V[1]);
    return d;
  }
};

}  // namespace

PeerRun runSimbody(const DiskProblem& p, const std::string& method, double accuracy) {
  SimbodyDisk model(p);
  std::unique_ptr<Integrator> integ;
  if (method == "merson") integ = std::make_unique<RungeKuttaMersonIntegrator>(model.system);
  else if (method == "rk3") integ = std::make_unique<RungeKutta3Integrator>(model.system);
  else throw std::invalid_argument("simbody: unknown method '" + method + "'");
  integ->setAccuracy(accuracy);
  integ->setAllowInterpolation(false);  // land on 1 s and 10 s by stepping, not interpolating
  PeerRun r;
  r.engine = "simbody";
  r.method = method;
  r.setting = accuracy;
  // stepTo() also returns at events such as the start of a continuous interval
  // (its first call returns at t = 0): call it until the time is reached.
  auto advance = [&](double t_end) {
    while (integ->getTime() < t_end && !integ->isSimulationOver()) integ->stepTo(t_end);
  };
  const double t0 = cpuSeconds();
  integ->initialize(model.state);
  advance(1.0);
  const double t1 = cpuSeconds();
  r.at1 = model.read(integ->getState());
  const double t2 = cpuSeconds();
  advance(p.duration);
  const double t3 = cpuSeconds();
  r.cpu = (t1 - t0) + (t3 - t2);
  r.ok = std::abs(integ->getTime() - p.duration) < 1e-9;
  if (!r.ok) r.message = "stopped at t = " + std::to_string(integ->getTime());
  r.at10 = model.read(integ->getState());
  r.steps = integ->getNumStepsTaken();
  r.evaluations = integ->getNumRealizations();
  return r;
}

double simbodyEvaluationSeconds(const DiskProblem& p, int n) {
  SimbodyDisk model(p);
  State s = model.state;
  std::vector<double> batches;
  const int per = 200;
  for (int k = 0; k < n; ++k) {
    const double t0 = cpuSeconds();
    for (int i = 0; i < per; ++i) {
      s.updQ()[0] += 0.0;  // invalidates Stage::Position and above: a fresh evaluation
      model.system.realize(s, Stage::Acceleration);
    }
    batches.push_back((cpuSeconds() - t0) / per);
  }
  return median(batches);
}

}  // namespace peers
