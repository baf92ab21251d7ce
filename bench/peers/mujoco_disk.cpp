// MuJoCo 2.2.2 model of the disk (disk_problem.hpp).
//
// MuJoCo has no thin disk and no velocity-level constraint: rolling comes from
// soft frictional contact (Todorov, Erez & Tassa, "MuJoCo: a physics engine for
// model-based control", IROS 2012; the solver's reference acceleration makes
// every constraint a damped spring of time constant solref[0], so contacts
// penetrate and frictional contacts creep by design). The disk is therefore a
// cylinder of half-height h with the thin disk's inertia given explicitly, on a
// plane, with solref time constant 2·dt (the stiffest MuJoCo's documentation
// recommends), friction 1 and an elliptic cone, stepped by MuJoCo's default
// semi-implicit Euler; optionally with MuJoCo's "noslip" post-processing
// (noslip_iterations > 0: a projected Gauss–Seidel pass on the friction
// forces without regularisation, which its documentation offers against creep).
#include "peer_engines.hpp"

#include <mujoco/mujoco.h>

#include <cstdio>
#include <cstring>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace peers {
namespace {

std::string modelXml(const DiskProblem& p, double dt, int noslip) {
  std::ostringstream x;
  x.precision(17);
  x << "<mujoco model='rolling_cylinder'>\n"
    << "  <option timestep='" << dt << "' gravity='0 0 " << -p.gravity
    << "' integrator='Euler' cone='elliptic' noslip_iterations='" << noslip << "'/>\n"
    << "  <worldbody>\n"
    << "    <geom name='floor' type='plane' size='0 0 1' friction='1 0.005 0.0001' solref='" << 2 * dt
    << " 1'/>\n"
    << "    <body name='disk'>\n"
    << "      <freejoint/>\n"
    << "      <inertial pos='0 0 0' mass='" << p.mass << "' diaginertia='" << p.A() << " " << p.A() << " "
    << p.C() << "'/>\n"
    << "      <geom type='cylinder' size='" << p.radius << " " << p.half_thickness
    << "' friction='1 0.005 0.0001' solref='" << 2 * dt << " 1'/>\n"
    << "    </body>\n"
    << "  </worldbody>\n"
    << "</mujoco>\n";
  return x.str();
}

struct MujocoDisk {
  mjModel* m = nullptr;
  mjData* d = nullptr;

  MujocoDisk(const DiskProblem& p, double dt, int noslip) {
    if (!(p.half_thickness > 0)) throw std::invalid_argument("mujoco: needs a cylinder of positive thickness");
    const std::string xml = modelXml(p, dt, noslip);
    auto vfs = std::make_unique<mjVFS>();  // ≈ 2 MB: not on the stack
    mj_defaultVFS(vfs.get());
    const char* name = "rolling_cylinder.xml";
    if (mj_makeEmptyFileVFS(vfs.get(), name, static_cast<int>(xml.size())) != 0)
      throw std::runtime_error("mujoco: cannot create the in-memory model file");
    std::memcpy(vfs->filedata[vfs->nfile - 1], xml.data(), xml.size());
    char error[1000] = "";
    m = mj_loadXML(name, vfs.get(), error, sizeof error);
    mj_deleteVFS(vfs.get());
    if (!m) throw std::runtime_error(std::string("mujoco: ") + error);
    d = mj_makeData(m);
    const Eigen::Quaterniond q(p.initial.rotation);
    for (int k = 0; k < 3; ++k) d->qpos[k] = p.initial.centre[k];
    d->qpos[3] = q.w();
    d->qpos[4] = q.x();
    d->qpos[5] = q.y();
    d->qpos[6] = q.z();
    // Free joint: linear velocity in the world frame, angular in the body frame.
    const V3 wb = p.initial.rotation.transpose() * p.initial.omega;
    for (int k = 0; k < 3; ++k) {
      d->qvel[k] = p.initial.velocity[k];
      d->qvel[3 + k] = wb[k];
    }
    mj_forward(m, d);
  }
  ~MujocoDisk() {
    mj_deleteData(d);
    mj_deleteModel(m);
  }
  MujocoDisk(const MujocoDisk&) = delete;
  MujocoDisk& operator=(const MujocoDisk&) = delete;

  DiskState read() const {
    DiskState s;
    const Eigen::Quaterniond q(d->qpos[3], d->qpos[4], d->qpos[5], d->qpos[6]);
    s.rotation = q.normalized().toRotationMatrix();
    s.centre = V3(d->qpos[0], d->qpos[1], d->qpos[2]);
    s.velocity = V3(d->qvel[0], d->qvel[1], d->qvel[2]);
    s.omega = s.rotation * V3(d->qvel[3], d->qvel[4], d->qvel[5]);
    return s;
  }
};

}  // namespace

PeerRun runMujoco(const DiskProblem& p, double dt, int noslip, bool diagnostics) {
  MujocoDisk md(p, dt, noslip);
  PeerRun r;
  r.engine = "mujoco";
  r.method = noslip > 0 ? "euler-noslip" : "euler";
  r.setting = dt;
  const long n1 = std::lround(1.0 / dt), n10 = std::lround(p.duration / dt);
  double slip_sum = 0;
  const double t0 = cpuSeconds();
  double paused = 0;
  for (long i = 1; i <= n10; ++i) {
    mj_step(md.m, md.d);
    if (diagnostics) {
      for (int c = 0; c < md.d->ncon; ++c)
        r.max_penetration = std::max(r.max_penetration, -md.d->contact[c].dist);
      const double s = slipSpeed(p, md.read());
      r.max_slip = std::max(r.max_slip, s);
      slip_sum += s;
    }
    if (i == n1) {
      const double tp = cpuSeconds();
      r.at1 = md.read();
      paused += cpuSeconds() - tp;
    }
  }
  r.cpu = cpuSeconds() - t0 - paused;
  r.at10 = md.read();
  r.steps = n10;
  r.evaluations = n10;  // one forward pass per Euler step
  r.mean_slip = slip_sum / static_cast<double>(n10);
  r.ok = std::isfinite(r.at10.centre.norm());
  if (!r.ok) r.message = "non-finite state";
  return r;
}

double mujocoForwardSeconds(const DiskProblem& p, double dt, int n) {
  MujocoDisk md(p, dt, 0);
  std::vector<double> batches;
  const int per = 2000;
  for (int k = 0; k < n; ++k) {
    const double t0 = cpuSeconds();
    for (int i = 0; i < per; ++i) mj_forward(md.m, md.d);
    batches.push_back((cpuSeconds() - t0) / per);
  }
  return median(batches);
}

}  // namespace peers
