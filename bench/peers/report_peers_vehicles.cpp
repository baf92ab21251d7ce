// appell against MuJoCo 2.2.2 and Siconos 4.4 on two vehicle scenes
// (vehicle_problem.hpp), interleaved in one process: every repeat runs every
// row once, so load changes hit all engines alike. CPU time only.
//
//   build/bench/peers/report_peers_vehicles [--repeats N] [--out DIR]
//
// 1. Skid-steer on a step command (examples/skid_steer_step): the steady yaw
//    rate (heading change over 8–10 s ÷ 2 s, and over 6–8 s to show the turn
//    is steady), forward and lateral speed of the chassis origin, wheel rates,
//    CPU per simulated second. Physics check: every engine's yaw rate against
//    the closed-form steady turn at its sliding μ (skid_steady_state.hpp;
//    appell slides at μₖ 0.7 in both schemes — its time-stepping takes the
//    kinetic cone for a contact that slid at the last step; MuJoCo has one μ
//    per contact, 0.8 and 0.7 here).
// 2. The parked car on a 10° slope (tests/test_friction_vehicles.cpp,
//    BrakedCarParkedOnASlopeDoesNotCreep): the chassis' displacement along
//    the slope over 60 s and after the first second (once soft contacts have
//    settled), its final speed, its sink; CPU per simulated second. The closed
//    form is zero: tan 10° = 0.176 < μₛ = 0.9, so static friction holds the car
//    and any motion after settling is creep of the contact model.
//
// Writes DIR/peers_vehicles.md and DIR/peers_vehicles.csv.
#include "mujoco_vehicles.hpp"
#include "skid_steady_state.hpp"
#ifdef PEERS_HAVE_SICONOS
#include "siconos_car.hpp"
#endif

#include <appell/run.hpp>
#include <appell/simulator.hpp>
#include <appell/urdf.hpp>

#include <Eigen/Geometry>

#include <filesystem>
#include <functional>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <numbers>
#include <regex>
#include <sstream>

using namespace peers;

#ifdef PEERS_HAVE_SICONOS
// OpenBLAS (Siconos' BLAS) starts worker threads that spin-wait between calls:
// on a loaded machine they starve the process (measured: 2 % of a core). Set
// to one thread when that library is the one loaded (weak: absent otherwise).
extern "C" void openblas_set_num_threads(int) __attribute__((weak));
#endif

namespace {

// The compiler that built this report (and appell with it).
std::string compilerName() {
#if defined(__clang__)
  return "clang " + std::to_string(__clang_major__);
#elif defined(__GNUC__)
  return "GCC " + std::to_string(__GNUC__);
#else
  return "an unknown compiler";
#endif
}


constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kSlope = 10 * std::numbers::pi / 180;

std::string readText(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string example(const std::string& rel) { return std::string(APPELL_SOURCE_DIR) + "/examples/" + rel; }

/// examples/car with its wheels locked, at rest on the slope — the same
/// rewriting as tests/test_friction_vehicles.cpp's brakedCarOnASlope.
appell::Scene parkedCarScene() {
  std::string text = readText(example("car/car.urdf"));
  text = std::regex_replace(text, std::regex(R"(type="continuous")"), R"(type="fixed")");
  text = std::regex_replace(text, std::regex(R"(\s*<joint name="\w+_joint" position="0" velocity="[0-9.]+"/>)"), "");
  text = std::regex_replace(text, std::regex(R"(velocity="0 0 0  1 0 0")"), R"(velocity="0 0 0  0 0 0")");
  text = std::regex_replace(text, std::regex(R"( mu="0.9")"), R"( mu_static="0.9" mu_kinetic="0.7")");
  std::ostringstream g;
  g.precision(17);
  g << R"(<gravity xyz=")" << 9.81 * std::sin(kSlope) << " 0 " << -9.81 * std::cos(kSlope) << R"("/>)";
  text = std::regex_replace(text, std::regex(R"(<gravity xyz="0 0 -9.81"/>)"), g.str());
  return appell::loadSceneFromString(text, example("car"), "parked_car");
}

/// examples/skid_steer_step, as published, or with one μ for sticking and
/// sliding (`single_mu`: the friction law MuJoCo and time-stepping have).
appell::Scene skidSteerScene(double single_mu = 0) {
  std::string text = readText(example("skid_steer_step/skid_steer_step.urdf"));
  if (single_mu > 0) {
    std::ostringstream mu;
    mu << " mu_static=\"" << single_mu << "\" mu_kinetic=\"" << single_mu << "\"";
    const std::string changed =
        std::regex_replace(text, std::regex(R"( mu_static="[0-9.]+" mu_kinetic="[0-9.]+")"), mu.str());
    if (changed == text) throw std::logic_error("skid_steer_step.urdf: no mu_static/mu_kinetic to replace");
    text = changed;
  }
  return appell::loadSceneFromString(text, example("skid_steer_step"), "skid_steer_step");
}

double totalMass(const appell::Model& m) {
  double s = 0;
  for (const auto& i : m.inertias) s += i.mass;
  return s;
}

ChassisSample appellSample(const appell::Simulator& sim) {
  ChassisSample c;
  const appell::VecX& q = sim.q();
  const appell::VecX& v = sim.v();
  c.t = sim.time();
  c.origin = q.head<3>();
  c.rotation = Eigen::Quaterniond(q[6], q[3], q[4], q[5]).normalized().toRotationMatrix();
  c.omega = c.rotation * v.segment<3>(0);     // body-frame angular velocity
  c.velocity = c.rotation * v.segment<3>(3);  // body-frame velocity of the link origin
  if (v.size() == 10)
    for (int i = 0; i < 4; ++i) c.wheel_rate[i] = v[6 + i];  // the wheel joints, in document order
  return c;
}

/// appell through the run library (as `appell run` builds it: the scene's
/// integrator, tolerance and servos), contacts by `scheme`.
VehicleRun runAppell(const appell::Scene& scene, appell::ContactScheme scheme, double duration,
                     const std::vector<double>& sample_times, const std::string& label, std::string* notes) {
  appell::RunOptions o = appell::runOptions(scene.settings);
  o.duration = duration;
  o.contacts = scheme;
  auto sim = appell::makeSimulator(scene, o);
  VehicleRun r;
  r.engine = "appell";
  r.setting = label;
  r.samples.push_back(appellSample(*sim));
  r.ok = true;
  for (double t : sample_times) {
    const double t0 = cpuSeconds();
    const appell::StepStatus st = sim->advanceTo(t, o.dt);
    r.cpu += cpuSeconds() - t0;
    r.samples.push_back(appellSample(*sim));
    if (!st.ok) {
      r.ok = false;
      r.message = st.message;
      break;
    }
  }
  const auto& k = sim->counters();
  r.steps = k.steps;
  if (notes) {
    std::ostringstream n;
    n << k.steps << " steps (" << k.timestepping_steps << " time-stepping), " << k.windows
      << " time-stepping windows, " << k.events << " contact events, " << k.rejected << " rejected";
    if (k.timestepping_steps > 0)
      n << "; contact problems solved to ≤ " << std::scientific << std::setprecision(1) << k.max_contact_residual
        << " m/s, " << k.unconverged << " unconverged";
    *notes = n.str();
  }
  return r;
}

std::string sci(double x, int digits = 2) {
  if (!std::isfinite(x)) return "—";
  std::ostringstream o;
  o << std::scientific << std::setprecision(digits) << x;
  return o.str();
}
std::string fixed(double x, int digits) {
  if (!std::isfinite(x)) return "—";
  std::ostringstream o;
  o << std::fixed << std::setprecision(digits) << x;
  return o.str();
}

double heading(const ChassisSample& c) { return std::atan2(c.rotation(1, 0), c.rotation(0, 0)); }

/// The sample at time t (the runs sample on a fixed grid).
const ChassisSample* at(const VehicleRun& r, double t) {
  for (const ChassisSample& c : r.samples)
    if (std::abs(c.t - t) < 1e-6) return &c;
  return nullptr;
}

/// Mean yaw rate over [t0, t1] from the heading, unwrapped over the samples.
double meanYawRate(const VehicleRun& r, double t0, double t1) {
  double turned = 0;
  const ChassisSample* prev = nullptr;
  for (const ChassisSample& c : r.samples) {
    if (c.t < t0 - 1e-9 || c.t > t1 + 1e-9) continue;
    if (prev) turned += std::remainder(heading(c) - heading(*prev), 2 * std::numbers::pi);
    prev = &c;
  }
  return turned / (t1 - t0);
}

double meanOver(const VehicleRun& r, double t0, double t1, double (ChassisSample::*f)() const) {
  double s = 0;
  int n = 0;
  for (const ChassisSample& c : r.samples)
    if (c.t >= t0 - 1e-9 && c.t <= t1 + 1e-9) s += (c.*f)(), ++n;
  return n ? s / n : kNaN;
}

struct Row {
  std::string scene, engine, setting, note;
  double mu_slide = kNaN;  ///< the friction coefficient a sliding tyre has
  std::function<VehicleRun(const std::vector<double>&)> run;
  std::vector<double> cpu;
  VehicleRun last;
  double duration = 0;
  double perSimSecond() const { return median(cpu) / duration; }
  double minCpu() const { return *std::min_element(cpu.begin(), cpu.end()) / duration; }
  double maxCpu() const { return *std::max_element(cpu.begin(), cpu.end()) / duration; }
};

std::string loadAverage() {
  std::ifstream f("/proc/loadavg");
  std::string a, b, c;
  f >> a >> b >> c;
  return a + " " + b + " " + c;
}

std::string utcNow() {
  const std::time_t t = std::time(nullptr);
  char buf[64];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M UTC", std::gmtime(&t));
  return buf;
}

}  // namespace


namespace {

std::vector<double> grid(double step, double end) {
  std::vector<double> t;
  for (int k = 1; k * step <= end + 1e-9; ++k) t.push_back(k * step);
  return t;
}

MujocoSettings mj(const std::string& name, double mu, double dt, const std::string& cone) {
  MujocoSettings s;
  s.name = name;
  s.mu = mu;
  s.dt = dt;
  s.cone = cone;
  return s;
}

/// MuJoCo's configurations for the skid-steer: its defaults, then one change
/// at a time from elliptic cones at dt 1 ms (see bench/peers/README.md).
std::vector<MujocoSettings> skidMujoco() {
  std::vector<MujocoSettings> v;
  for (double mu : {0.8, 0.7}) {
    v.push_back(mj("default: pyramidal, dt 2 ms", mu, 2e-3, "pyramidal"));
    v.push_back(mj("elliptic, dt 2 ms", mu, 2e-3, "elliptic"));
    v.push_back(mj("elliptic, dt 1 ms", mu, 1e-3, "elliptic"));
    if (mu != 0.8) continue;
    v.push_back(mj("elliptic, dt 0.5 ms", mu, 5e-4, "elliptic"));
    v.push_back(mj("elliptic, dt 1 ms, impratio 10", mu, 1e-3, "elliptic"));
    v.back().impratio = 10;
    v.push_back(mj("elliptic, dt 1 ms, noslip 10", mu, 1e-3, "elliptic"));
    v.back().noslip = 10;
    v.push_back(mj("elliptic, dt 1 ms, implicit", mu, 1e-3, "elliptic"));
    v.back().integrator = "implicit";
    v.push_back(mj("elliptic, dt 1 ms, cylinder wheels", mu, 1e-3, "elliptic"));
    v.back().wheel_shape = "cylinder";
    v.push_back(mj("elliptic, dt 1 ms, condim 6", mu, 1e-3, "elliptic"));
    v.back().condim = 6;
  }
  return v;
}

/// MuJoCo's configurations for the parked car (μ 0.9): defaults, then the
/// documented remedies for creep one by one, then all of them together.
std::vector<MujocoSettings> carMujoco() {
  std::vector<MujocoSettings> v;
  v.push_back(mj("default: pyramidal, dt 2 ms", 0.9, 2e-3, "pyramidal"));
  v.push_back(mj("elliptic, dt 2 ms", 0.9, 2e-3, "elliptic"));
  v.push_back(mj("elliptic, impratio 100", 0.9, 2e-3, "elliptic"));
  v.back().impratio = 100;
  v.push_back(mj("elliptic, noslip 10", 0.9, 2e-3, "elliptic"));
  v.back().noslip = 10;
  v.push_back(mj("elliptic, dt 1 ms, solref 0.002 1, solimp 0.99 0.999", 0.9, 1e-3, "elliptic"));
  v.back().solref = "0.002 1";
  v.back().solimp = "0.99 0.999 0.001";
  v.push_back(mj("elliptic, dt 1 ms, solref 0.002, solimp 0.99 0.999, impratio 100, noslip 100", 0.9, 1e-3,
                 "elliptic"));
  v.back().solref = "0.002 1";
  v.back().solimp = "0.99 0.999 0.001";
  v.back().impratio = 100;
  v.back().noslip = 100;
  return v;
}

std::vector<Row> makeRows(const appell::Scene& skid, const appell::Scene& skid08, const appell::Scene& car,
                          std::map<std::string, std::string>& notes) {
  const VehicleModel sk = skidSteerStep(), pc = parkedCar(kSlope);
  std::vector<Row> rows;
  auto add = [&](const std::string& scene, const std::string& engine, const std::string& setting, double mu,
                 double duration, std::function<VehicleRun(const std::vector<double>&)> run) {
    Row r;
    r.scene = scene;
    r.engine = engine;
    r.setting = setting;
    r.mu_slide = mu;
    r.duration = duration;
    r.run = std::move(run);
    rows.push_back(std::move(r));
  };
  using appell::ContactScheme;
  auto appellRow = [&](const std::string& scene, const appell::Scene& s, ContactScheme scheme,
                       const std::string& label, double mu, double duration) {
    const std::string key = scene + "/" + label;
    add(scene, "appell", label, mu, duration, [&s, scheme, label, duration, key, &notes](const std::vector<double>& t) {
      return runAppell(s, scheme, duration, t, label, &notes[key]);
    });
  };
  appellRow("skid", skid, ContactScheme::Auto, "auto (default), μₛ 0.8 μₖ 0.7", 0.7, sk.duration);
  appellRow("skid", skid08, ContactScheme::Auto, "auto, one μ 0.8", 0.8, sk.duration);
  // Time-stepping slides a contact that slid at the last step on μₖ
  // (docs/contacts.md §10): the published scene's 0.7, as the events.
  appellRow("skid", skid, ContactScheme::TimeStepping, "timestepping, h 1 ms, μₛ 0.8 μₖ 0.7", 0.7,
            sk.duration);
  for (const MujocoSettings& m : skidMujoco())
    add("skid", "mujoco", m.name, m.mu, sk.duration,
        [m, sk](const std::vector<double>& t) { return runMujocoVehicle(sk, m, t); });
  appellRow("car", car, ContactScheme::Auto, "auto (default)", 0.7, pc.duration);
  appellRow("car", car, ContactScheme::TimeStepping, "timestepping, h 1 ms", 0.9, pc.duration);
  for (const MujocoSettings& m : carMujoco())
    add("car", "mujoco", m.name, m.mu, pc.duration,
        [m, pc](const std::vector<double>& t) { return runMujocoVehicle(pc, m, t); });
#ifdef PEERS_HAVE_SICONOS
  SiconosSettings si;
  si.name = "Moreau–Jean θ 0.5, h 1 ms, NSGS tol 1e-10";
  add("car", "siconos", si.name, 0.9, pc.duration,
      [si, pc](const std::vector<double>& t) { return runSiconosCar(pc, si, t); });
#endif
  return rows;
}

}  // namespace

namespace {

std::string cpuCell(const Row& r) {
  return fixed(1e3 * r.perSimSecond(), 1) + " (" + fixed(1e3 * r.minCpu(), 1) + "–" + fixed(1e3 * r.maxCpu(), 1) + ")";
}

/// The skid-steer's table: steady turn per row against the closed-form
/// steady state at the row's sliding μ (skid_steady_state.hpp).
void skidTable(std::ostringstream& md, const std::vector<Row>& rows, std::ofstream& csv,
               std::vector<std::string>& checks) {
  const VehicleModel sk = skidSteerStep();
  const double track = sk.wheel_pos[0].y() - sk.wheel_pos[1].y(), rw = sk.wheel_radius;
  std::map<double, SkidSteadyState> closed;
  for (double mu : {0.7, 0.8}) closed[mu] = skidSteadyState(sk, mu);
  md << "Closed form (skid_steady_state.hpp: all four tyres sliding, Coulomb, servo torques balancing the tyres, "
        "load transfer by the planar rule; a 7 × 7 Newton solve):\n\n";
  for (const auto& [mu, c] : closed)
    md << "- μ " << mu << ": yaw rate " << fixed(c.yaw_rate, 4) << " rad/s, v_x " << fixed(c.vx, 4) << " m/s, v_y "
       << fixed(c.vy, 4) << " m/s, wheels " << fixed(c.wheel_rate[0], 3) << " " << fixed(c.wheel_rate[1], 3) << " "
       << fixed(c.wheel_rate[2], 3) << " " << fixed(c.wheel_rate[3], 3) << " rad/s (FL FR RL RR); residual "
       << sci(c.residual, 1) << "\n";
  md << "\nWheel rates ω_L, ω_R: means of the front and rear wheel of a side over the samples at 8–10 s. "
        "Yaw rate ÷ r(ω_R − ω_L)/track: how far the tyres slide (1 would be rolling).\n\n"
     << "| engine | setting | μ sliding | yaw rate 8–10 s [rad/s] | yaw rate 6–8 s | forward speed [m/s] | "
        "lateral speed [m/s] | turn radius [m] | ω_L, ω_R [rad/s] | yaw rate ÷ r(ω_R − ω_L)/track | "
        "yaw rate vs closed form | CPU ms per simulated s: median (min–max) | steps | max penetration [m] | "
        "tyres touching, 8–10 s (min–max) | friction ∠ −slip, max over 8–10 s |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Row& r : rows) {
    if (r.scene != "skid") continue;
    const double w = meanYawRate(r.last, 8, 10), w68 = meanYawRate(r.last, 6, 8);
    const double fwd = meanOver(r.last, 8, 10, &ChassisSample::forward);
    const double lat = meanOver(r.last, 8, 10, &ChassisSample::lateral);
    const double ref = closed.at(r.mu_slide).yaw_rate, diff = (w - ref) / ref;
    double wl = 0, wr = 0;  // mean wheel rates of the left (FL, RL) and right (FR, RR) sides
    int n = 0;
    for (const ChassisSample& c : r.last.samples)
      if (c.t >= 8 - 1e-9) wl += (c.wheel_rate[0] + c.wheel_rate[2]) / 2, wr += (c.wheel_rate[1] + c.wheel_rate[3]) / 2, ++n;
    wl /= std::max(n, 1);
    wr /= std::max(n, 1);
    int touching_min = 4, touching_max = 0;
    double angle = 0;
    for (const ChassisSample& c : r.last.samples)
      if (c.t >= 8 - 1e-9 && c.contacts >= 0) {
        touching_min = std::min(touching_min, c.contacts);
        touching_max = std::max(touching_max, c.contacts);
        angle = std::max(angle, c.friction_angle);
      }
    const bool soft = r.engine == "mujoco";
    md << "| " << r.engine << " | " << r.setting << " | " << r.mu_slide << " | " << fixed(w, 4) << " | "
       << fixed(w68, 4) << " | " << fixed(fwd, 4) << " | " << fixed(lat, 4) << " | " << fixed(fwd / w, 3) << " | "
       << fixed(wl, 2) << ", " << fixed(wr, 2) << " | " << fixed(w / (rw * (wr - wl) / track), 3) << " | "
       << fixed(100 * diff, 1) << " % | " << cpuCell(r) << " | " << r.last.steps << " | "
       << (soft ? sci(r.last.max_penetration) : "") << " | "
       << (soft ? std::to_string(touching_min) + "–" + std::to_string(touching_max) : "") << " | "
       << (soft ? fixed(angle * 180 / std::numbers::pi, 0) + "°" : "") << " |"
       << (r.last.ok ? "" : " failed: " + r.last.message) << "\n";
    csv << "skid," << r.engine << ",\"" << r.setting << "\"," << r.mu_slide << "," << w << "," << w68 << "," << fwd
        << "," << lat << ",,,," << 1e3 * r.perSimSecond() << "," << 1e3 * r.minCpu() << "," << 1e3 * r.maxCpu()
        << "," << r.last.steps << "," << (r.last.ok ? 1 : 0) << "\n";
    if (r.engine == "appell")
      checks.push_back(std::string(std::abs(diff) <= 0.01 ? "PASS" : "**FAIL**") + ": appell " + r.setting +
                       ": yaw rate over 8–10 s " + fixed(w, 4) + " rad/s, " + fixed(100 * diff, 2) +
                       " % from the closed form at μ " + fixed(r.mu_slide, 1) + " (bound ±1 %)");
  }
  md << "\n";
}

/// The parked car's table: displacement along the slope (x: downhill) from
/// t = 0 and from t = 1 s, the final speed and the sink into the ground.
void carTable(std::ostringstream& md, const std::vector<Row>& rows, std::ofstream& csv,
              std::vector<std::string>& checks) {
  const double r0 = parkedCar(kSlope).wheel_radius;
  md << "| engine | setting | downhill 0–60 s [m] | downhill 1–60 s (creep) [m] | horizontal displacement 1–60 s [m] | "
        "speed at 60 s [m/s] | sink at 60 s [m] | CPU ms per simulated s: median (min–max) | steps |\n"
     << "|---|---|---|---|---|---|---|---|---|\n";
  for (const Row& r : rows) {
    if (r.scene != "car") continue;
    const ChassisSample *s0 = &r.last.samples.front(), *s1 = at(r.last, 1.0), *s60 = at(r.last, 60.0);
    if (!s1 || !s60) {
      md << "| " << r.engine << " | " << r.setting << " | failed: " << r.last.message << " |\n";
      continue;
    }
    const double d0 = s60->origin.x() - s0->origin.x(), d1 = s60->origin.x() - s1->origin.x();
    const double h1 = (s60->origin - s1->origin).head<2>().norm();
    const double sink = r0 - s60->origin.z();
    md << "| " << r.engine << " | " << r.setting << " | " << sci(d0) << " | " << sci(d1) << " | " << sci(h1)
       << " | " << sci(s60->velocity.norm()) << " | " << sci(sink) << " | " << cpuCell(r) << " | " << r.last.steps
       << " |" << (r.last.ok ? "" : " failed: " + r.last.message) << "\n";
    csv << "car," << r.engine << ",\"" << r.setting << "\"," << r.mu_slide << ",,,,," << d0 << "," << d1 << ","
        << s60->velocity.norm() << "," << 1e3 * r.perSimSecond() << "," << 1e3 * r.minCpu() << ","
        << 1e3 * r.maxCpu() << "," << r.last.steps << "," << (r.last.ok ? 1 : 0) << "\n";
    if (r.engine == "appell") {
      const double moved = (s60->origin - s0->origin).norm();
      checks.push_back(std::string(moved <= 1e-12 ? "PASS" : "**FAIL**") + ": appell " + r.setting +
                       ": the chassis moved " + sci(moved) + " m in 60 s (closed form 0; the test's bound 1e-12 m)");
    }
  }
  md << "\n";
}

}  // namespace

namespace {

/// The numbers the peers are built from must be the scene files' numbers.
void checkModels(const appell::Scene& skid, const appell::Scene& car) {
  const VehicleModel sk = skidSteerStep(), pc = parkedCar(kSlope);
  for (const auto& [name, scene, model] : {std::tuple{"skid-steer", &skid, sk}, std::tuple{"parked car", &car, pc}}) {
    const double a = totalMass(scene->model), m = mujocoTotalMass(model, MujocoSettings{});
    if (std::abs(a - model.totalMass()) > 1e-9 || std::abs(m - model.totalMass()) > 1e-9)
      throw std::logic_error(std::string(name) + ": total mass differs (appell " + std::to_string(a) +
                             ", MuJoCo " + std::to_string(m) + ", numbers " + std::to_string(model.totalMass()) + ")");
  }
  const auto& jn = skid.model.joint_names;
  const char* wheels[] = {"front_left_joint", "front_right_joint", "rear_left_joint", "rear_right_joint"};
  for (int i = 0; i < 4; ++i) {
    const auto it = std::find(jn.begin(), jn.end(), wheels[i]);
    if (it == jn.end()) throw std::logic_error(std::string("skid-steer: no joint ") + wheels[i]);
    const appell::Vec3 p = skid.model.placement[it - jn.begin()].p;
    if ((p - sk.wheel_pos[i]).norm() > 1e-12) throw std::logic_error(std::string("skid-steer: ") + wheels[i] + " moved");
  }
}

void header(std::ostringstream& md, int repeats, const std::string& out_dir, const std::string& started,
            const std::string& load_before, const std::string& load_after) {
  md << "# appell against MuJoCo 2.2.2 and Siconos 4.4: a skid-steer turning and a car parked on a slope\n\n"
     << "Written by `bench/peers/report_peers_vehicles.cpp` (what is compared and how: "
     << "[`bench/peers/README.md`](../peers/README.md#vehicles-report_peers_vehicles)). Command (Release build, "
     << "`-O3`, peers installed by `scripts/install-peers.sh`):\n\n"
     << "    build/bench/peers/report_peers_vehicles --repeats " << repeats << " --out " << out_dir << "\n\n"
     << "Run " << started << "; load average " << load_before << " before, " << load_after
     << " after (2 cores shared with other builds: the CPU times are process CPU time, "
        "`CLOCK_PROCESS_CPUTIME_ID`, but cache and memory contention still spread them). Median and range over "
     << repeats << " interleaved repeats (each repeat runs every row once, in table order); the physics columns are "
        "the last repeat's (every engine is deterministic).\n\n"
     << "Libraries: appell from this tree (`-O3 -DNDEBUG`, " << compilerName()
     << "); MuJoCo 2.2.2 = Debian `libmujoco-dev` "
        "2.2.2-3 and Siconos 4.4.0 = Debian `libsiconos-kernel-dev` 4.4.0+dfsg-2, both as Debian built them "
        "(its default `dpkg-buildflags`, `-O2`; the packages do not record their exact flags); Siconos linked to "
        "OpenBLAS, run with one BLAS thread. Sampling the chassis "
        "(every 0.1 s / 1 s) is outside the timed region; appell's adaptive steps end on those times (≈ 100 of its ≈ 2 300 steps on the skid-steer).\n\n";
}

/// Every sample of every row (peers_vehicles_trace.csv), and the MJCF of the
/// elliptic rows as built.
void writeTraceAndModels(const std::vector<Row>& rows, const std::string& out_dir) {
  std::ofstream trace(out_dir + "/peers_vehicles_trace.csv");
  trace << std::setprecision(9) << "scene,engine,setting,t,x,y,z,heading,yaw_rate,forward,lateral,w_fl,w_fr,w_rl,w_rr\n";
  for (const Row& r : rows)
    for (const ChassisSample& c : r.last.samples) {
      trace << r.scene << "," << r.engine << ",\"" << r.setting << "\"," << c.t << "," << c.origin.x() << ","
            << c.origin.y() << "," << c.origin.z() << "," << heading(c) << "," << c.omega.z() << "," << c.forward()
            << "," << c.lateral();
      for (double w : c.wheel_rate) trace << "," << w;
      trace << "\n";
    }
  std::ofstream(out_dir + "/peers_vehicles_skid.xml")
      << mujocoModelXml(skidSteerStep(), mj("elliptic, dt 1 ms", 0.8, 1e-3, "elliptic"));
  std::ofstream(out_dir + "/peers_vehicles_car.xml")
      << mujocoModelXml(parkedCar(kSlope), mj("elliptic, dt 2 ms", 0.9, 2e-3, "elliptic"));
}

}  // namespace

int main(int argc, char** argv) {
  int repeats = 3;
  std::string out_dir = "bench/results";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--repeats" && i + 1 < argc) repeats = std::max(1, std::atoi(argv[++i]));
    else if (a == "--out" && i + 1 < argc) out_dir = argv[++i];
    else {
      std::cerr << "usage: report_peers_vehicles [--repeats N] [--out DIR]\n";
      return 2;
    }
  }
#ifdef PEERS_HAVE_SICONOS
  if (openblas_set_num_threads) openblas_set_num_threads(1);
#endif
  const std::string started = utcNow(), load_before = loadAverage();
  std::map<std::string, std::string> notes;
  std::vector<Row> rows;
  appell::Scene skid, skid08, car;
  try {
    skid = skidSteerScene();
    skid08 = skidSteerScene(0.8);
    car = parkedCarScene();
    checkModels(skid, car);
    rows = makeRows(skid, skid08, car, notes);
  } catch (const std::exception& e) {
    std::cerr << "report_peers_vehicles: " << e.what() << "\n";
    return 1;
  }
  for (int rep = 0; rep < repeats; ++rep) {
    for (Row& r : rows) {
      r.last = r.run(grid(r.scene == "skid" ? 0.1 : 1.0, r.duration));
      r.cpu.push_back(r.last.cpu);
      std::cout << "  " << r.scene << " " << r.engine << " " << r.setting << ": " << r.last.cpu << " s CPU"
                << (r.last.ok ? "" : " FAILED: " + r.last.message) << "\n";
    }
    std::cout << "repeat " << rep + 1 << "/" << repeats << " done\n";
  }
  const std::string load_after = loadAverage();

  std::filesystem::create_directories(out_dir);
  std::ofstream csv(out_dir + "/peers_vehicles.csv");
  csv << std::setprecision(8)
      << "scene,engine,setting,mu_slide,yaw_rate_8_10,yaw_rate_6_8,forward,lateral,downhill_0_60,downhill_1_60,"
         "speed_60,cpu_ms_per_sim_s,cpu_min,cpu_max,steps,ok\n";
  std::ostringstream md;
  header(md, repeats, out_dir, started, load_before, load_after);
  md << "## 1. Skid-steer, step command (examples/skid_steer_step, 10 s)\n\n";
  std::vector<std::string> checks;
  skidTable(md, rows, csv, checks);
  for (const Row& r : rows)
    if (r.scene == "skid" && r.engine == "appell") md << "- appell " << r.setting << ": " << notes[r.scene + "/" + r.setting] << "\n";
  md << "\n## 2. Car parked on a 10° slope, wheels locked (60 s)\n\n";
  carTable(md, rows, csv, checks);
  for (const Row& r : rows)
    if (r.scene == "car" && r.engine == "appell") md << "- appell " << r.setting << ": " << notes[r.scene + "/" + r.setting] << "\n";
  md << "\nChecks:\n\n";
  for (const std::string& c : checks) md << "- " << c << "\n";
  md << "\n";
  writeTraceAndModels(rows, out_dir);
  md << "MJCF as built (elliptic rows): `peers_vehicles_skid.xml`, `peers_vehicles_car.xml`; raw numbers: "
        "`peers_vehicles.csv`; the chassis and wheel rates at every sample of every row: "
        "`peers_vehicles_trace.csv`.\n";
  std::ofstream(out_dir + "/peers_vehicles.md") << md.str();
  std::cout << md.str();
  return 0;
}
