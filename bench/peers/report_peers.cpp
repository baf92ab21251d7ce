// appell against its peers (Simbody 3.7, MuJoCo 2.2.2) on the rolling disk of
// disk_problem.hpp, in one interleaved run (every repeat runs every engine and
// setting once, so load changes hit all of them alike). CPU time only.
//
//   build/bench/peers/report_peers [--repeats N] [--out DIR]
//
// Two cases, both tilted by θ = 0.3 rad with the contact point at the origin:
//   spin    spinning 5 rad/s about the axle, no turn rate, no lean rate;
//   steady  steady circular rolling, centre on a circle of radius ρ = 2 m.
// Steady motion. With lean-frame rates u₁ = θ̇, u₂ = ω·a (about the axle),
// u₃ = ω·u (about the in-plane "up" direction u = (c − P)/R), the thin disk obeys
//   u̇₁ = (6 u₂ u₃ R − u₃² R tan θ + 4 g sin θ)/(5R)
// (Kane's equations of the rolling disc: Kane & Levinson, Dynamics: Theory and
// Applications, 1985; reproduced by SymPy's sympy.physics.mechanics rolling-disc
// test). A turn at rate Ω about the vertical has
// u₃ = Ω cos θ; rolling gives the centre the velocity v_c = ω × (c − P) = −R u₂ t
// (t the travel direction), and a uniform turn about a vertical axis at
// distance ρ from the centre needs |v_c| = Ω ρ, so u₂ = −Ω ρ/R with the axis on
// the side the disk leans to. u̇₁ = 0 then reads
//   −6 Ω² ρ cos θ − Ω² R sin θ cos θ + 4 g sin θ = 0  ⇔  Ω² = 4 g tan θ/(6ρ + R sin θ),
// and the exact path is the centre turning uniformly about that axis:
//   c(t) = O + Rz(Ω t)(c₀ − O),  O = c₀ + (e_z × v_c₀)/Ω.
// The program checks this Ω, u₂ against the scene library's independent
// angular-momentum balance (steadyDiskAxleRate, tests/fixtures/rolling_disk.hpp).
// The spin case has no closed form: its reference is appell's Dormand–Prince at
// tol 1e-14 with the dense multiplier (KKT) formulation — a different solver
// from the tree solver the measured appell runs use — and the report states how
// far the next-tightest run and Simbody's tightest run are from it.
//
// Writes DIR/peers.csv, DIR/peers.md and, with gnuplot, DIR/peers.gp + peers.png.
#include "peer_engines.hpp"
#include "rolling_disk.hpp"

#include <appell/appell.hpp>
#include <appell/simulator.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <sstream>

using namespace peers;
namespace sc = appell::scenes;
using appell::Formulation;
using appell::IntegratorType;

namespace {

constexpr double kMass = 1.0, kRadius = 0.5, kGravity = 9.81, kLean = 0.3, kDuration = 10.0;
constexpr double kHalfThickness = 1e-3;  // MuJoCo's cylinder
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

DiskState stateOf(const appell::VecX& q, const appell::VecX& v) {
  DiskState s;
  s.centre = q.segment<3>(0);
  s.rotation = Eigen::Quaterniond(q[6], q[3], q[4], q[5]).normalized().toRotationMatrix();
  s.omega = s.rotation * v.segment<3>(0);
  s.velocity = s.rotation * v.segment<3>(3);
  return s;
}

void setState(const DiskState& s, appell::VecX& q, appell::VecX& v) {
  sc::setFloatingPose(q, 0, s.centre, s.rotation);
  v = sc::floatingVelocity(s.rotation, s.omega, s.velocity);
}

/// The same body resting on the rim of its face at −h along the axle: a rigid
/// cylinder of half-thickness h. Same orientation, angular velocity and contact
/// point as `thin`; the centre sits h higher along the axle, and its velocity
/// follows from rolling, v_c = ω × (c − P).
sc::BuiltScene cylinderScene(const sc::BuiltScene& thin, double h) {
  sc::BuiltScene s = thin;
  s.name = "rolling_cylinder";
  s.constraints.clear();
  s.constraints.push_back(appell::makeContact(
      appell::ContactKind::Rolling, 0, appell::Disk{kRadius, appell::Vec3(0, 0, -h), appell::Vec3::UnitZ()},
      appell::Support{appell::Plane{}, appell::StaticMotion{}, "ground"},
      appell::ContactOptions{"rim", appell::Vec3::Zero(), {}}));
  DiskState st = stateOf(thin.q0, thin.v0);
  const V3 a = st.rotation.col(2);
  if (!(a.z() > 0)) throw std::logic_error("cylinderScene: the face at −h must be the lower one");
  st.centre += h * a;
  st.velocity += st.omega.cross(h * a);
  setState(st, s.q0, s.v0);
  sc::closeGaps(s.model, s.constraints, s.q0);
  sc::projectVelocity(s.model, s.constraints, s.q0, s.v0);
  return s;
}

/// appell run with the public API (Simulator, makeSolver); `min_axle_z`, if
/// given, tracks the smallest vertical component of the axle on a 0.05 s grid
/// (the cylinder's reference must keep resting on the same face).
// One constrained evaluation of appell's disk at its initial state, as an
// integrator's stage does it: the rows (evaluateConstraintRows) and the tree
// solve for v̇ — median over n batches of 2000 calls (CPU s per call).
double appellEvaluationSeconds(const sc::BuiltScene& s, int n) {
  appell::ConstraintData cd(s.model, s.constraints, appell::DenseRows::None);
  appell::Data data(s.model);
  const auto solver = appell::makeSolver(Formulation::Tree, s.model, s.constraints);
  const appell::VecX tau = appell::VecX::Zero(s.model.nv);
  appell::ConstrainedResult res;
  std::vector<double> batches;
  const int per = 2000;
  for (int k = 0; k < n; ++k) {
    const double t0 = cpuSeconds();
    for (int i = 0; i < per; ++i) {
      // As at a new state: the rows' forward kinematics always run; the tree
      // solver must not reuse the previous call's factor either.
      if (auto* tree = dynamic_cast<appell::TreeSolver*>(solver.get())) tree->forgetFactor();
      appell::evaluateConstraintRows(s.model, data, s.constraints, cd, 0.0, s.q0, s.v0);
      solver->solve(s.model, data, s.constraints, cd, s.q0, s.v0, tau, res,
                    appell::SolveOutputs::Accelerations);
    }
    batches.push_back((cpuSeconds() - t0) / per);
  }
  return median(batches);
}

PeerRun runAppell(const sc::BuiltScene& s, IntegratorType type, const std::string& method, double setting,
                  Formulation form = Formulation::Tree, double* min_axle_z = nullptr) {
  const bool adaptive = adaptiveIntegrator(type);
  appell::IntegratorOptions io;
  io.rtol = adaptive ? setting : 1e-8;
  io.atol = io.rtol * 1e-2;
  io.h_max = 1.0;  // the tolerance, not a cap, sets the adaptive steps
  appell::SimulatorOptions so;
  so.evaluate_end_state = false;
  appell::Simulator sim(s.model, s.constraints, appell::makeSolver(form, s.model, s.constraints), type, io, so);
  sim.setState(0, s.q0, s.v0);
  const double h = adaptive ? 1e-3 : setting;
  PeerRun r;
  r.engine = "appell";
  r.method = method;
  r.setting = setting;
  appell::StepStatus st;
  if (min_axle_z) {
    *min_axle_z = 1;
    for (int k = 1; k <= static_cast<int>(std::lround(kDuration / 0.05)) && st.ok; ++k) {
      st = sim.advanceTo(0.05 * k, h);
      const DiskState d = stateOf(sim.q(), sim.v());
      *min_axle_z = std::min(*min_axle_z, d.rotation(2, 2));
      if (k == 20) r.at1 = d;
    }
  } else {
    const double t0 = cpuSeconds();
    st = sim.advanceTo(1.0, h);
    const double t1 = cpuSeconds();
    r.at1 = stateOf(sim.q(), sim.v());
    const double t2 = cpuSeconds();
    if (st.ok) st = sim.advanceTo(kDuration, h);
    r.cpu = (t1 - t0) + (cpuSeconds() - t2);
  }
  r.ok = st.ok;
  r.message = st.message;
  r.at10 = stateOf(sim.q(), sim.v());
  r.steps = sim.counters().steps;
  r.evaluations = sim.counters().evaluations;
  return r;
}

/// One case: the thin disk (appell, Simbody) and the 1 mm cylinder (MuJoCo),
/// with the reference centre positions at 1 s and 10 s for each.
struct Case {
  std::string name;
  sc::BuiltScene disk, cylinder;
  DiskProblem thin, cyl;
  V3 ref1, ref10, cref1, cref10;
  std::vector<std::string> notes;
};

DiskProblem problemOf(const sc::BuiltScene& s, double h) {
  DiskProblem p;
  p.mass = kMass;
  p.radius = kRadius;
  p.gravity = kGravity;
  p.half_thickness = h;
  p.duration = kDuration;
  p.initial = stateOf(s.q0, s.v0);
  return p;
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

Case makeCase(const std::string& name) {
  sc::RollingDiskParams p;
  p.radius = kRadius;
  p.mass = kMass;
  p.lean = kLean;
  p.duration = kDuration;
  Case c;
  c.name = name;
  const double A = kMass * kRadius * kRadius / 4, C = kMass * kRadius * kRadius / 2;
  double Omega = 0, rho = 2.0;
  if (name == "spin") {
    p.axle_rate = 5.0;
    p.precession = 0.0;
  } else {
    Omega = std::sqrt(4 * kGravity * std::tan(kLean) / (6 * rho + kRadius * std::sin(kLean)));
    p.precession = Omega;
    p.axle_rate = -Omega * rho / kRadius;
    const double check = sc::steadyDiskAxleRate(kMass, kRadius, A, C, kGravity, kLean, Omega);
    if (std::abs(check - p.axle_rate) > 1e-12 * std::abs(check))
      throw std::logic_error("steady motion: Ω² = 4 g tan θ/(6ρ + R sin θ) disagrees with the "
                             "angular-momentum balance");
    std::ostringstream o;
    o << std::setprecision(12) << "Ω = " << Omega << " rad/s, u₂ = −Ωρ/R = " << p.axle_rate
      << " rad/s (angular-momentum balance: " << check << ")";
    c.notes.push_back(o.str());
  }
  c.disk = sc::rollingDisk(p);
  c.cylinder = cylinderScene(c.disk, kHalfThickness);
  c.thin = problemOf(c.disk, 0);
  c.cyl = problemOf(c.cylinder, kHalfThickness);

  double min_az = 0, min_az_cyl = 0;
  const PeerRun ref = runAppell(c.disk, IntegratorType::DormandPrince54, "ref", 1e-14, Formulation::Multipliers,
                                &min_az);
  const PeerRun cref = runAppell(c.cylinder, IntegratorType::DormandPrince54, "ref", 1e-14,
                                 Formulation::Multipliers, &min_az_cyl);
  if (!ref.ok || !cref.ok) throw std::runtime_error("reference run failed: " + ref.message + cref.message);
  c.cref1 = cref.at1.centre;
  c.cref10 = cref.at10.centre;
  std::ostringstream o;
  o << "cylinder reference (appell dopri5 tol 1e-14, KKT, offset rim): axle z-component ≥ " << min_az_cyl
    << " over the run, so the cylinder rests on the same face throughout";
  c.notes.push_back(o.str());
  if (name == "spin") {
    c.ref1 = ref.at1.centre;
    c.ref10 = ref.at10.centre;
    c.notes.push_back("thin-disk reference: appell dopri5 tol 1e-14, KKT formulation, " +
                      std::to_string(ref.steps) + " steps");
  } else {
    // Closed form: the centre turns about the vertical axis through O at rate Ω.
    const DiskState& s0 = c.thin.initial;
    const V3 O = s0.centre + V3::UnitZ().cross(s0.velocity) / Omega;
    const V3 d0 = s0.centre - O;
    auto at = [&](double t) {
      return V3(O + Eigen::AngleAxisd(Omega * t, V3::UnitZ()).toRotationMatrix() * d0);
    };
    c.ref1 = at(1.0);
    c.ref10 = at(kDuration);
    std::ostringstream e;
    e << "thin-disk reference: the exact circle (radius " << std::setprecision(15) << std::hypot(d0.x(), d0.y())
      << " m about (" << O.x() << ", " << O.y() << "), height " << s0.centre.z()
      << " m); appell dopri5 tol 1e-14 (KKT) ends " << sci((ref.at10.centre - c.ref10).norm())
      << " m from it at 10 s";
    c.notes.push_back(e.str());
  }
  std::ostringstream t;
  t << "the 1 mm thickness alone: the thin disk's and the cylinder's exact centres are "
    << sci((c.ref1 - c.cref1).norm()) << " m apart at 1 s and " << sci((c.ref10 - c.cref10).norm())
    << " m at 10 s";
  c.notes.push_back(t.str());
  return c;
}

/// MuJoCo's noslip iterations for a row's method name.
[[maybe_unused]] int mujocoNoslip(const std::string& method) { return method == "euler-noslip" ? 10 : 0; }

struct Row {
  std::string case_name, engine, method;
  double setting = 0;
  bool cylinder = false;  // measured against the cylinder reference
  std::vector<double> cpu;
  PeerRun last;
  double err1 = kNaN, err10 = kNaN, drift = kNaN;
  double cpuMedian() const { return median(cpu); }
  double perSimSecond() const { return cpuMedian() / kDuration; }
  std::string label() const { return engine + "-" + method; }
};

/// CPU per simulated second needed to reach error E at 10 s: the cheapest run
/// with error ≤ E, interpolated log–log with the next cheaper run (which misses E).
double costAtError(std::vector<const Row*> rows, double E) {
  std::sort(rows.begin(), rows.end(), [](const Row* a, const Row* b) { return a->perSimSecond() < b->perSimSecond(); });
  for (size_t i = 0; i < rows.size(); ++i) {
    if (!(rows[i]->err10 <= E)) continue;
    if (i == 0) return rows[0]->perSimSecond();
    const double x0 = std::log(rows[i - 1]->perSimSecond()), x1 = std::log(rows[i]->perSimSecond());
    const double y0 = std::log(rows[i - 1]->err10), y1 = std::log(rows[i]->err10);
    if (!(y0 > y1)) return rows[i]->perSimSecond();
    return std::exp(x0 + (std::log(E) - y0) * (x1 - x0) / (y1 - y0));
  }
  return kNaN;
}

/// Error at 10 s for a CPU budget per simulated second: log–log between the
/// runs bracketing it (the end values outside their range).
double errorAtCost(std::vector<const Row*> rows, double cost) {
  std::sort(rows.begin(), rows.end(), [](const Row* a, const Row* b) { return a->perSimSecond() < b->perSimSecond(); });
  if (rows.empty()) return kNaN;
  if (cost <= rows.front()->perSimSecond()) return rows.front()->err10;
  for (size_t i = 1; i < rows.size(); ++i) {
    if (cost > rows[i]->perSimSecond()) continue;
    const double x0 = std::log(rows[i - 1]->perSimSecond()), x1 = std::log(rows[i]->perSimSecond());
    const double y0 = std::log(rows[i - 1]->err10), y1 = std::log(rows[i]->err10);
    return std::exp(y0 + (std::log(cost) - x0) * (y1 - y0) / (x1 - x0));
  }
  return rows.back()->err10;
}

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

int main(int argc, char** argv) {
  int repeats = 3;
  std::string out_dir = "bench/results";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--repeats" && i + 1 < argc) repeats = std::max(1, std::atoi(argv[++i]));
    else if (a == "--out" && i + 1 < argc) out_dir = argv[++i];
    else {
      std::cerr << "usage: report_peers [--repeats N] [--out DIR]\n";
      return 2;
    }
  }
  const std::string started = utcNow(), load_before = loadAverage();
  std::vector<Case> cases;
  try {
    for (const char* n : {"spin", "steady"}) {
      cases.push_back(makeCase(n));
      std::cout << "case " << n << ": references done\n";
    }
  } catch (const std::exception& e) {
    std::cerr << "report_peers: " << e.what() << "\n";
    return 1;
  }

  // Every configuration of every engine, in the order they run in each repeat.
  std::vector<Row> rows;
  for (const Case& c : cases) {
    auto add = [&](const std::string& engine, const std::string& method, double s, bool cyl) {
      Row r;
      r.case_name = c.name;
      r.engine = engine;
      r.method = method;
      r.setting = s;
      r.cylinder = cyl;
      rows.push_back(r);
    };
    for (double tol : {1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12}) add("appell", "dopri5", tol, false);
    for (double tol : {1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12}) add("appell", "dop853", tol, false);
    for (double dt : {2e-2, 1e-2, 5e-3, 2e-3, 1e-3}) add("appell", "rk4", dt, false);
    for (double tol : {1e-5, 1e-7, 1e-9}) add("appell", "dopri5-cylinder", tol, true);
#ifdef PEERS_HAVE_SIMBODY
    for (double acc : {1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10}) add("simbody", "merson", acc, false);
    for (double acc : {1e-3, 1e-4, 1e-5, 1e-6, 1e-7}) add("simbody", "rk3", acc, false);
#endif
#ifdef PEERS_HAVE_MUJOCO
    for (double dt : {2e-3, 1e-3, 5e-4, 2.5e-4, 1e-4}) add("mujoco", "euler", dt, true);
    for (double dt : {1e-3, 2.5e-4}) add("mujoco", "euler-noslip", dt, true);
#endif
  }
  std::map<std::string, const Case*> by_name;
  for (const Case& c : cases) by_name[c.name] = &c;

  std::vector<double> appell_eval, simbody_eval, mujoco_eval;
  for (int rep = 0; rep < repeats; ++rep) {
    for (Row& r : rows) {
      const Case& c = *by_name[r.case_name];
      PeerRun run;
      if (r.engine == "appell") {
        const IntegratorType type = r.method == "rk4"      ? IntegratorType::RK4
                                    : r.method == "dop853" ? IntegratorType::DormandPrince853
                                                           : IntegratorType::DormandPrince54;
        run = runAppell(r.cylinder ? c.cylinder : c.disk, type, r.method, r.setting);
      }
#ifdef PEERS_HAVE_SIMBODY
      if (r.engine == "simbody") run = runSimbody(c.thin, r.method, r.setting);
#endif
#ifdef PEERS_HAVE_MUJOCO
      if (r.engine == "mujoco") run = runMujoco(c.cyl, r.setting, mujocoNoslip(r.method), false);
#endif
      r.cpu.push_back(run.cpu);
      r.last = run;
    }
    appell_eval.push_back(appellEvaluationSeconds(cases[0].disk, 5));
#ifdef PEERS_HAVE_SIMBODY
    simbody_eval.push_back(simbodyEvaluationSeconds(cases[0].thin, 5));
#endif
#ifdef PEERS_HAVE_MUJOCO
    mujoco_eval.push_back(mujocoForwardSeconds(cases[0].cyl, 1e-3, 5));
#endif
    std::cout << "repeat " << rep + 1 << "/" << repeats << " done\n";
  }
  const std::string load_after = loadAverage();

  // Errors, energy, and (untimed) MuJoCo diagnostics.
  for (Row& r : rows) {
    const Case& c = *by_name[r.case_name];
    const DiskProblem& p = r.cylinder ? c.cyl : c.thin;
    if (r.last.ok) {
      r.err1 = (r.last.at1.centre - (r.cylinder ? c.cref1 : c.ref1)).norm();
      r.err10 = (r.last.at10.centre - (r.cylinder ? c.cref10 : c.ref10)).norm();
      const double E0 = energy(p, p.initial);
      r.drift = std::abs(energy(p, r.last.at10) - E0) / std::abs(E0);
    }
#ifdef PEERS_HAVE_MUJOCO
    if (r.engine == "mujoco") {
      const PeerRun d = runMujoco(p, r.setting, mujocoNoslip(r.method), true);
      r.last.max_slip = d.max_slip;
      r.last.mean_slip = d.mean_slip;
      r.last.max_penetration = d.max_penetration;
    }
#endif
  }

  std::filesystem::create_directories(out_dir);
  {
    std::ofstream csv(out_dir + "/peers.csv");
    csv << "case,engine,method,setting,steps,evaluations,cpu_per_step_us,cpu_per_sim_second_ms,"
           "cpu_per_evaluation_us,error_1s,error_10s,energy_drift,max_slip,mean_slip,max_penetration,ok\n";
    csv << std::setprecision(6);
    for (const Row& r : rows) {
      const double cpu = r.cpuMedian();
      csv << r.case_name << "," << r.engine << "," << r.method << "," << r.setting << "," << r.last.steps << ","
          << r.last.evaluations << "," << 1e6 * cpu / std::max(1L, r.last.steps) << "," << 1e3 * r.perSimSecond()
          << "," << 1e6 * cpu / std::max(1L, r.last.evaluations) << "," << r.err1 << "," << r.err10 << ","
          << r.drift << "," << r.last.max_slip << "," << r.last.mean_slip << "," << r.last.max_penetration << ","
          << (r.last.ok ? 1 : 0) << "\n";
    }
  }

  std::ostringstream md;
  md << "# appell against Simbody 3.7 and MuJoCo 2.2.2: the rolling disk\n\n"
     << "Written by `bench/peers/report_peers.cpp` (what is compared and how: "
     << "[`bench/peers/README.md`](../peers/README.md)). Command (Release build, both peers installed by "
     << "`scripts/install-peers.sh`):\n\n"
     << "    build/bench/peers/report_peers --repeats " << repeats << " --out " << out_dir << "\n\n"
     << "Run " << started << "; load average " << load_before << " before, " << load_after
     << " after (2 cores). CPU time of the process (`CLOCK_PROCESS_CPUTIME_ID`), median of " << repeats
     << " interleaved repeats (each repeat runs every row once, in table order).\n\n"
     << "Disk: m = 1 kg, R = 0.5 m, inertia (mR²/4, mR²/4, mR²/2), g = 9.81, tilt 0.3 rad, 10 s, "
     << "the same initial state (centre, rotation, ω, v_c in world coordinates) for every engine. "
     << "MuJoCo's disk is a cylinder of half-height 1 mm with the same inertia (solref 2·dt, friction 1, "
     << "elliptic cone, Euler); its rows (and appell's `dopri5-cylinder`) are measured against the exact "
     << "rigid motion of that cylinder: the same body rolling on the rim of its lower face, a disk rim offset "
     << "1 mm along the axle, same orientation, ω and contact point as the thin disk. Simbody is Debian's "
     << "`libsimbody` as packaged: `-O2` but built without `NDEBUG` (its internal debug checks run), so the CPU "
     << "ratios against it hold for that library.\n\n";
  md << "Error: distance of the centre of mass from the reference at 1 s and 10 s (m). Energy drift: "
     << "|E(10 s) − E(0)|/E(0). Per evaluation: CPU of the run ÷ dynamics evaluations (appell: solves by the "
     << "integrator; Simbody: `getNumRealizations()`; MuJoCo: one forward pass per Euler step). "
     << "Slip: horizontal speed of the body's material point at the cylinder's lowest point, max and mean over "
     << "the steps; penetration: max −`contact.dist` (both from a separate untimed run).\n\n";
  for (const Case& c : cases) {
    md << "## Case `" << c.name << "`\n\n";
    for (const std::string& n : c.notes) md << "- " << n << "\n";
    md << "\n| engine | method | accuracy / tol / dt | steps | evaluations | µs per step | ms per simulated s | "
          "µs per evaluation | error at 1 s [m] | error at 10 s [m] | energy drift | max slip [m/s] | "
          "mean slip [m/s] | max penetration [m] |\n"
       << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const Row& r : rows) {
      if (r.case_name != c.name) continue;
      const double cpu = r.cpuMedian();
      const bool mj = r.engine == "mujoco";
      md << "| " << r.engine << " | " << r.method << " | " << r.setting << " | " << r.last.steps << " | "
         << r.last.evaluations << " | " << fixed(1e6 * cpu / std::max(1L, r.last.steps), 2) << " | "
         << fixed(1e3 * r.perSimSecond(), 3) << " | " << fixed(1e6 * cpu / std::max(1L, r.last.evaluations), 2)
         << " | " << sci(r.err1) << " | " << sci(r.err10) << " | " << sci(r.drift, 1) << " | "
         << (mj ? sci(r.last.max_slip) : "") << " | " << (mj ? sci(r.last.mean_slip) : "") << " | "
         << (mj ? sci(r.last.max_penetration) : "") << " |" << (r.last.ok ? "" : " failed: " + r.last.message)
         << "\n";
    }
    // Checks a reader needs to trust the table: how close the independent
    // engine gets to the reference, and MuJoCo's order of convergence.
    const Row* best_simbody = nullptr;
    const Row *mj1 = nullptr, *mj5 = nullptr;
    for (const Row& r : rows) {
      if (r.case_name != c.name) continue;
      if (r.engine == "simbody" && r.err10 > 0 && (!best_simbody || r.err10 < best_simbody->err10))
        best_simbody = &r;
      if (r.engine == "mujoco" && r.method == "euler" && r.setting == 1e-3) mj1 = &r;
      if (r.engine == "mujoco" && r.method == "euler" && r.setting == 5e-4) mj5 = &r;
    }
    if (best_simbody)
      md << "- Simbody's closest run (" << best_simbody->method << ", accuracy " << best_simbody->setting
         << ") ends " << sci(best_simbody->err10) << " m from the reference at 10 s.\n";
    if (mj1 && mj5)
      md << "- MuJoCo's error at 10 s falls by " << fixed(mj1->err10 / mj5->err10, 2)
         << "× from dt 1e-3 to 5e-4 (first order, towards the rigid cylinder's motion).\n";
    md << "\n";
  }

  md << "## Ratios (from this run)\n\n"
     << "Cost at an error: the cheapest run reaching it, interpolated log–log with the next cheaper run "
     << "(appell: `dopri5`, and `dop853`, on the thin disk). Error at a cost: log–log between the bracketing "
     << "runs of that method.\n\n"
     << "| case | comparison | peer | appell | ratio |\n|---|---|---|---|---|\n";
  for (const Case& c : cases) {
    std::vector<const Row*> ap, ap8, merson, mujoco;
    for (const Row& r : rows) {
      if (r.case_name != c.name) continue;
      if (r.engine == "appell" && r.method == "dopri5") ap.push_back(&r);
      if (r.engine == "appell" && r.method == "dop853") ap8.push_back(&r);
      if (r.engine == "simbody" && r.method == "merson") merson.push_back(&r);
      if (r.engine == "mujoco") mujoco.push_back(&r);
    }
    for (const auto& [method, mine] : {std::pair{"dopri5", &ap}, std::pair{"dop853", &ap8}}) {
      for (double E : {4e-5, 8e-9}) {
        if (merson.empty()) break;
        const double cs = costAtError(merson, E), ca = costAtError(*mine, E);
        md << "| " << c.name << " | CPU per simulated s at error " << sci(E, 0) << " m at 10 s | Simbody Merson "
           << fixed(1e3 * cs, 3) << " ms | " << method << " " << fixed(1e3 * ca, 3) << " ms | " << fixed(cs / ca, 1)
           << "× less CPU |\n";
      }
      for (const Row* m : mujoco) {
        if (m->setting != 1e-3) continue;
        const double ea = errorAtCost(*mine, m->perSimSecond());
        md << "| " << c.name << " | error at 10 s at MuJoCo's cost (" << m->method << ", dt 1e-3, " << fixed(1e3 * m->perSimSecond(), 3)
           << " ms per simulated s) | MuJoCo " << sci(m->err10) << " m | " << method << " " << sci(ea) << " m | "
           << sci(m->err10 / ea, 1) << "× smaller error |\n";
      }
    }
  }
  md << "\n";
  {
    md << "One evaluation at the spin case's initial state, median over the repeats of batched calls: "
       << "appell's rows and tree solve for v̇ (what an integrator stage does): "
       << fixed(1e6 * median(appell_eval), 3) << " µs; ";
    if (!simbody_eval.empty())
      md << "Simbody `realize(Acceleration)` after a change of q: " << fixed(1e6 * median(simbody_eval), 2)
         << " µs; ";
    if (!mujoco_eval.empty())
      md << "MuJoCo `mj_forward`: " << fixed(1e6 * median(mujoco_eval), 3) << " µs (appell ÷ MuJoCo "
         << fixed(median(appell_eval) / median(mujoco_eval), 2) << ")";
    md << ". (appell's per-evaluation column above includes its step's share of projection and integrator "
          "work.)\n\n";
  }

  const bool have_gnuplot = std::system("command -v gnuplot > /dev/null 2>&1") == 0;
  if (have_gnuplot) {
    const std::string plot = out_dir + "/peers.gp";
    std::ofstream gp(plot);
    gp << "# Work–precision figure of bench/results/peers.md; made by bench/peers/report_peers:\n"
       << "#   build/bench/peers/report_peers --repeats " << repeats << " --out " << out_dir << "\n"
       << "set datafile separator ','\nset terminal pngcairo size 1500,560 noenhanced\n"
       << "set output '" << out_dir << "/peers.png'\n"
       << "set logscale xy\nset format y '1e%L'\nset format x '1e%L'\nset grid\n"
       << "set xlabel 'CPU time per simulated second [s]'\nset ylabel 'centre position error at t = 10 s [m]'\n"
       << "set key outside right\n"
       << "methods = 'appell/dopri5 appell/dop853 appell/rk4 appell/dopri5-cylinder simbody/merson simbody/rk3 mujoco/euler mujoco/euler-noslip'\n"
       << "eng(i) = substr(word(methods,i), 1, strstrt(word(methods,i),'/')-1)\n"
       << "met(i) = substr(word(methods,i), strstrt(word(methods,i),'/')+1, strlen(word(methods,i)))\n"
       << "set multiplot layout 1,2\n";
    for (const Case& c : cases) {
      gp << (&c == &cases.back() ? "set key\n" : "unset key\n");  // one legend, right of the last panel
      gp << "set title 'rolling disk, case " << c.name << "'\n"
         << "plot for [i=1:words(methods)] '" << out_dir << "/peers.csv' using "
         << "((strcol(1) eq '" << c.name << "' && strcol(2) eq eng(i) && strcol(3) eq met(i) && $11 > 0) ? $8/1000 : 1/0):11 "
         << "with linespoints lw 2 pt i title word(methods,i)\n";
    }
    gp << "unset multiplot\n";
    gp.close();
    if (std::system(("gnuplot " + plot).c_str()) == 0) {
      std::cout << "figure: " << out_dir << "/peers.png\n";
      md << "![work–precision: error at 10 s against CPU per simulated second](peers.png)\n\n"
         << "Figure: `peers.png`, made by `peers.gp` (written by the same command); raw numbers: `peers.csv`.\n";
    }
  }
  std::ofstream(out_dir + "/peers.md") << md.str();
  std::cout << md.str();
  return 0;
}
