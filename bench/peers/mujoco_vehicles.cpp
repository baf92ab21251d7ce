// MuJoCo 2.2.2 models of the two vehicle scenes (vehicle_problem.hpp), built
// as MJCF from the same numbers as the appell scene files.
//
// The chassis is a body with a free joint and its explicit inertial (centre
// of mass off the link origin, diagonal inertia); each wheel is a child body
// at its axle point with its own inertial, on a hinge about the chassis y
// axis (skid-steer) or with no joint (the parked car: MuJoCo welds a jointless
// child to its parent — the brakes). The wheels' contact geometry is a sphere
// of the wheel radius by default: the appell scenes' tyres are tori with a
// 2–3 cm tube touching the ground in one point at the wheel radius below the
// axle, and a sphere with condim 3 is exactly that point contact (no torsional
// or rolling friction, as appell's rows have none here). A cylinder of the
// wheel's width is the other choice: MuJoCo's cylinder–plane collision then
// gives several points across the tread.
//
// Contacts are soft (Todorov, Erez & Tassa, "MuJoCo: a physics engine for
// model-based control", IROS 2012; Todorov, "Convex and analytically-
// invertible dynamics with contacts and constraints", ICRA 2014): each
// constraint's force is the solution of a convex problem whose reference
// acceleration is a damped spring (solref) and whose regularisation
// (solimp's impedance d < 1) lets a frictional contact slip at a speed
// proportional to the force it carries — the creep the parked car measures.
// `noslip_iterations` adds a projected Gauss–Seidel pass over the friction
// rows without regularisation; `impratio` (elliptic cones) makes friction
// stiffer than the normal direction.
//
// The servos are MuJoCo velocity actuators, force = kv (ctrl − q̇) clamped to
// ±limit (forcelimited) — appell's velocity servo law exactly, evaluated at
// the step's start (semi-implicit Euler), or with its velocity derivative
// in the implicit integrator.
#include "mujoco_vehicles.hpp"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace peers {
namespace {

std::string vec(const V3& v) {
  std::ostringstream o;
  o.precision(17);
  o << v.x() << " " << v.y() << " " << v.z();
  return o.str();
}

void inertial(std::ostringstream& x, const LinkInertia& l) {
  x << "<inertial pos='" << vec(l.com) << "' mass='" << l.mass << "' diaginertia='" << vec(l.diag) << "'/>\n";
}

std::string modelXml(const VehicleModel& v, const MujocoSettings& s) {
  std::ostringstream x;
  x.precision(17);
  x << "<mujoco model='vehicle'>\n"
    << "  <option timestep='" << s.dt << "' gravity='" << vec(v.gravity) << "' integrator='" << s.integrator
    << "' cone='" << s.cone << "' solver='" << s.solver << "' impratio='" << s.impratio
    << "' noslip_iterations='" << s.noslip << "' iterations='" << s.iterations << "' tolerance='" << s.tolerance
    << "'/>\n"
    << "  <default><geom condim='" << s.condim << "' friction='" << s.mu << " 0.005 0.0001'";
  if (!s.solref.empty()) x << " solref='" << s.solref << "'";
  if (!s.solimp.empty()) x << " solimp='" << s.solimp << "'";
  x << "/></default>\n"
    << "  <worldbody>\n"
    << "    <geom name='ground' type='plane' size='0 0 1'/>\n"
    << "    <body name='chassis' pos='0 0 " << v.wheel_radius << "'>\n"
    << "      <freejoint/>\n      ";
  inertial(x, v.chassis);
  for (int i = 0; i < 4; ++i) {
    x << "      <body name='wheel" << i << "' pos='" << vec(v.wheel_pos[i]) << "'>\n";
    if (!v.wheels_locked) x << "        <joint name='axle" << i << "' type='hinge' axis='0 1 0'/>\n";
    x << "        ";
    inertial(x, v.wheel);
    if (s.wheel_shape == "cylinder")
      x << "        <geom type='cylinder' size='" << v.wheel_radius << " " << v.wheel_width / 2
        << "' zaxis='0 1 0'/>\n";
    else
      x << "        <geom type='sphere' size='" << v.wheel_radius << "'/>\n";
    x << "      </body>\n";
  }
  x << "    </body>\n  </worldbody>\n";
  if (!v.wheels_locked) {
    x << "  <actuator>\n";
    for (int i = 0; i < 4; ++i)
      x << "    <velocity joint='axle" << i << "' kv='" << v.servo_kv << "' forcelimited='true' forcerange='"
        << -v.servo_limit << " " << v.servo_limit << "'/>\n";
    x << "  </actuator>\n";
  }
  x << "</mujoco>\n";
  return x.str();
}

struct MujocoVehicle {
  mjModel* m = nullptr;
  mjData* d = nullptr;
  MujocoVehicle(const VehicleModel& v, const MujocoSettings& s) {
    const std::string xml = modelXml(v, s);
    auto vfs = std::make_unique<mjVFS>();  // ≈ 2 MB: not on the stack
    mj_defaultVFS(vfs.get());
    const char* name = "vehicle.xml";
    if (mj_makeEmptyFileVFS(vfs.get(), name, static_cast<int>(xml.size())) != 0)
      throw std::runtime_error("mujoco: cannot create the in-memory model file");
    std::memcpy(vfs->filedata[vfs->nfile - 1], xml.data(), xml.size());
    char error[1000] = "";
    m = mj_loadXML(name, vfs.get(), error, sizeof error);
    mj_deleteVFS(vfs.get());
    if (!m) throw std::runtime_error(std::string("mujoco: ") + error + "\n" + xml);
    d = mj_makeData(m);
    if (!v.wheels_locked)
      for (int i = 0; i < 4; ++i) d->ctrl[i] = v.setpoint[i];  // the step command, from t = 0
    mj_forward(m, d);
  }
  ~MujocoVehicle() {
    mj_deleteData(d);
    mj_deleteModel(m);
  }
  MujocoVehicle(const MujocoVehicle&) = delete;
  MujocoVehicle& operator=(const MujocoVehicle&) = delete;

  ChassisSample sample() const {
    ChassisSample c;
    c.t = d->time;
    c.origin = V3(d->qpos[0], d->qpos[1], d->qpos[2]);
    const Eigen::Quaterniond q(d->qpos[3], d->qpos[4], d->qpos[5], d->qpos[6]);
    c.rotation = q.normalized().toRotationMatrix();
    // Free joint: linear velocity of the body origin in the world frame,
    // angular velocity in the body frame.
    c.velocity = V3(d->qvel[0], d->qvel[1], d->qvel[2]);
    c.omega = c.rotation * V3(d->qvel[3], d->qvel[4], d->qvel[5]);
    if (m->nv == 10)
      for (int i = 0; i < 4; ++i) c.wheel_rate[i] = d->qvel[6 + i];  // the hinges, in body order
    c.contacts = d->ncon;
    c.friction_angle = frictionAngle();
    return c;
  }
  /// The largest angle between a contact's friction force and the opposite
  /// of its slip (the velocity of the wheel's material point at the contact),
  /// over contacts slipping faster than 1 mm/s.
  double frictionAngle() const {
    double worst = 0;
    for (int k = 0; k < d->ncon; ++k) {
      const mjContact& con = d->contact[k];
      mjtNum f[6], vel[6];
      mj_contactForce(m, d, k, f);
      const int body = m->geom_bodyid[con.geom2 > 0 ? con.geom2 : con.geom1];
      mj_objectVelocity(m, d, mjOBJ_BODY, body, vel, 0);  // world frame: angular, then linear at the origin
      const V3 w(vel[0], vel[1], vel[2]), vo(vel[3], vel[4], vel[5]);
      const V3 arm = V3(con.pos[0], con.pos[1], con.pos[2]) - V3(d->xpos[3 * body], d->xpos[3 * body + 1], d->xpos[3 * body + 2]);
      const V3 slip = vo + w.cross(arm);
      const V3 t1(con.frame[3], con.frame[4], con.frame[5]), t2(con.frame[6], con.frame[7], con.frame[8]);
      const V3 ft = f[1] * t1 + f[2] * t2;  // friction in the world (the frame's rows: normal, t1, t2)
      const V3 st = slip - slip.dot(V3(con.frame[0], con.frame[1], con.frame[2])) * V3(con.frame[0], con.frame[1], con.frame[2]);
      if (st.norm() < 1e-3 || ft.norm() < 1e-9) continue;
      worst = std::max(worst, std::acos(std::clamp(-ft.dot(st) / (ft.norm() * st.norm()), -1.0, 1.0)));
    }
    return worst;
  }
  double penetration() const {
    double p = 0;
    for (int c = 0; c < d->ncon; ++c) p = std::max(p, -d->contact[c].dist);
    return p;
  }
};

}  // namespace

std::string mujocoModelXml(const VehicleModel& v, const MujocoSettings& s) { return modelXml(v, s); }

double mujocoTotalMass(const VehicleModel& v, const MujocoSettings& s) {
  MujocoVehicle mv(v, s);
  double m = 0;
  for (int b = 0; b < mv.m->nbody; ++b) m += mv.m->body_mass[b];
  return m;
}

VehicleRun runMujocoVehicle(const VehicleModel& v, const MujocoSettings& s, const std::vector<double>& sample_times) {
  MujocoVehicle mv(v, s);
  VehicleRun r;
  r.engine = "mujoco";
  r.setting = s.name;
  r.samples.push_back(mv.sample());
  const long n = std::lround(v.duration / s.dt);
  size_t next = 0;
  while (next < sample_times.size() && sample_times[next] <= 0) ++next;
  double paused = 0;
  const double t0 = cpuSeconds();
  for (long i = 1; i <= n; ++i) {
    mj_step(mv.m, mv.d);
    if (next < sample_times.size() && mv.d->time >= sample_times[next] - 0.5 * s.dt) {
      const double tp = cpuSeconds();
      r.samples.push_back(mv.sample());
      r.max_penetration = std::max(r.max_penetration, mv.penetration());
      ++next;
      paused += cpuSeconds() - tp;
    }
  }
  r.cpu = cpuSeconds() - t0 - paused;
  r.steps = n;
  r.ok = std::isfinite(mv.d->qpos[0]) && std::isfinite(mv.d->qvel[0]);
  if (!r.ok) r.message = "non-finite state";
  return r;
}

}  // namespace peers
