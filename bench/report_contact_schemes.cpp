// What each contact scheme costs (docs/contacts.md §10): wall time per
// simulated second, median and spread over repeats, of
//   - the skid-steer robot turning on a step command
//     (examples/skid_steer_step, 57 kg, μ 0.8, no creep) under auto and
//     under time-stepping, 10 s;
//   - the Ackermann CAD car (examples/cad_car: one rear wheel 0.2 mm out of
//     line, a steering step at t = 2 s that makes every tyre slip) under
//     auto and under time-stepping, 10 s;
//   - a box on four corners pushed to sliding by F = k t (μ 0.5, k 30 N/s,
//     0.7 s) under time-stepping (h = 1 ms), under events (dopri5, tol
//     1e-10) and under auto, with the steps each takes;
//   - the other scenes of issue 37's done-when under auto, their own
//     settings: the 12-DoF biped with box soles, servos and joint limits
//     landing from 2 cm and standing (examples/biped, 5 s), and the servo
//     differential drive at μ 1 on its step set-point (examples/diff_drive/
//     diff_drive_servo, 8 s).
// Each line also gives the work balance's error relative to the energy that
// moved, and the Gauss–Seidel sweeps per contact problem (time-stepping).
// Usage: report_contact_schemes [--repeats N | N]   (default 5)
#include <appell/appell.hpp>
#include <appell/run.hpp>
#include <appell/urdf.hpp>
#include <appell/vertex_contacts.hpp>

#include "scene.hpp"  // (the tests' fixtures: principalInertia, floating poses)

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

using namespace appell;
using namespace appell::scenes;

namespace {

struct Measured {
  std::vector<double> wall_per_sim;
  long steps = 0, windows = 0, ts_steps = 0, sweeps = 0;
  double sim_time = 0, balance = 0;
  bool ok = true;
  std::string failure;
};

void print(const char* scene, const char* scheme, const Measured& m) {
  std::vector<double> w = m.wall_per_sim;
  std::sort(w.begin(), w.end());
  const double median = w[w.size() / 2];
  const double sweeps = m.ts_steps > 0 ? static_cast<double>(m.sweeps) / m.ts_steps : 0.0;
  std::printf("%-34s %-13s %6.2f s %8ld %5ld  %9.4f  [%.4f, %.4f]  %8.2e %7.1f%s%s\n", scene,
              scheme, m.sim_time, m.steps, m.windows, median, w.front(), w.back(), m.balance, sweeps,
              m.ok ? "" : "  FAILED: ", m.ok ? "" : m.failure.c_str());
}

// An example scene for `duration` s under `scheme`, its own settings otherwise.
Measured example(const char* path, double duration, ContactScheme scheme, int repeats) {
  const Scene scene = loadScene(std::string(APPELL_SOURCE_DIR) + path);
  Measured m;
  for (int r = 0; r < repeats; ++r) {
    RunOptions o = runOptions(scene.settings);
    o.contacts = scheme;
    o.duration = duration;
    const RunSummary s = runScene(scene, o, RunObserver{});
    m.wall_per_sim.push_back(s.wall_seconds / std::max(s.time, 1e-12));
    m.steps = s.counters.steps;
    m.windows = s.counters.windows;
    m.ts_steps = s.counters.timestepping_steps;
    m.sweeps = s.counters.contact_sweeps;
    m.balance = s.relativeEnergyDeviation();
    m.sim_time = s.time;
    m.ok = s.ok;
    m.failure = s.failure;
  }
  return m;
}

Measured pushedBox(ContactScheme scheme, int repeats) {
  const Vec3 half(0.2, 0.1, 0.05);
  const double mass = 2, mu = 0.5, k = 30, T = 0.7;
  ModelBuilder b;
  const Vec3 d = 2 * half;
  const Vec3 I = mass / 12 * Vec3(d.y() * d.y() + d.z() * d.z(), d.x() * d.x() + d.z() * d.z(),
                                  d.x() * d.x() + d.y() * d.y());
  b.addBody("box", -1, SE3::Identity(), JointType::Floating, Vec3::UnitZ(),
            principalInertia(mass, I), "free");
  const Model model = b.build();
  ContactSpec spec;
  spec.kind = ContactKind::Rolling;
  spec.body = 0;
  spec.shape = Box{half, SE3::Identity()};
  spec.support = Support{Plane{}, StaticMotion{}, "ground"};
  spec.mu = mu;
  spec.options.name = "box";
  ConstraintList constraints;
  for (auto& c : makeVertexContacts(spec)) constraints.push_back(c);
  VecX q0 = neutralConfiguration(model);
  setFloatingPose(q0, 0, Vec3(0, 0, half.z()), Mat3::Identity());
  Measured m;
  for (int r = 0; r < repeats; ++r) {
    SimulatorOptions so;
    so.scheme = scheme;
    IntegratorOptions io;
    io.rtol = io.atol = 1e-10;
    io.h_max = 0.01;
    Simulator sim(model, constraints, makeSolver(Formulation::Tree, model, constraints),
                  IntegratorType::DormandPrince54, io, so);
    sim.setJointForces([&](double t, const VecX& q, const VecX&, VecX& tau) {
      tau.tail<3>() = floatingRotation(q, 0).transpose() * Vec3(k * t, 0, 0);
    });
    sim.setState(0, q0, VecX::Zero(model.nv));
    const auto start = std::chrono::steady_clock::now();
    const StepStatus st = sim.advanceTo(T, 1e-3);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    m.wall_per_sim.push_back(wall / std::max(sim.time(), 1e-12));
    m.steps = sim.counters().steps;
    m.windows = sim.counters().windows;
    m.ts_steps = sim.counters().timestepping_steps;
    m.sweeps = sim.counters().contact_sweeps;
    m.sim_time = sim.time();
    m.ok = st.ok;
    m.failure = st.message;
  }
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  int repeats = 5;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--repeats" && i + 1 < argc) repeats = std::atoi(argv[++i]);
    else repeats = std::atoi(argv[i]);
  }
  repeats = std::max(1, repeats);
  std::printf("%-34s %-13s %8s %8s %5s  %9s  %-18s  %8s %7s\n", "scene", "scheme", "sim", "steps",
              "wins", "wall/sim", "[min, max]", "balance", "sweeps");
  print("box on 4 corners pushed (0.7 s)", "timestepping", pushedBox(ContactScheme::TimeStepping, repeats));
  print("box on 4 corners pushed (0.7 s)", "events", pushedBox(ContactScheme::Events, repeats));
  print("box on 4 corners pushed (0.7 s)", "auto", pushedBox(ContactScheme::Auto, repeats));
  const char* skid = "/examples/skid_steer_step/skid_steer_step.urdf";
  print("skid_steer_step (10 s)", "auto", example(skid, 10, ContactScheme::Auto, repeats));
  print("skid_steer_step (10 s)", "timestepping", example(skid, 10, ContactScheme::TimeStepping, repeats));
  const char* car = "/examples/cad_car/cad_car.urdf";
  print("cad_car (10 s)", "auto", example(car, 10, ContactScheme::Auto, repeats));
  print("cad_car (10 s)", "timestepping", example(car, 10, ContactScheme::TimeStepping, repeats));
  print("biped landing (5 s)", "auto",
        example("/examples/biped/biped.urdf", 5, ContactScheme::Auto, repeats));
  print("diff_drive_servo (8 s)", "auto",
        example("/examples/diff_drive/diff_drive_servo.urdf", 8, ContactScheme::Auto, repeats));
  return 0;
}
