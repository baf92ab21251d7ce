// Speed against error: every integrator over a range of steps / tolerances on
// example scenes, against a reference solution at a tolerance 1000× tighter
// than the tightest tested. Wall times are medians over repeats.
//
//   build/bench/report_speed_error [--repeats N] [--out DIR] [SCENE.urdf …]
//
// Writes DIR/speed_error.csv (one row per scene × method × setting) and, when
// gnuplot is installed, DIR/speed_error.png (error against time per simulated
// second, log–log, one panel per scene).
#include <appell/appell.hpp>
#include <appell/simulator.hpp>
#include <appell/urdf.hpp>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

using namespace appell;

namespace {

struct Run {
  VecX q, v;
  double wall = 0, energy_drift = 0, residual = 0;
  long steps = 0;
  bool ok = true;
};

Run simulate(const Scene& scene, IntegratorType type, double dt, double tol, double T,
             Formulation form, bool project) {
  IntegratorOptions io;
  io.rtol = tol;
  io.atol = tol * 1e-2;
  io.h_max = 0.1;
  SimulatorOptions so;
  so.project_positions = so.project_velocities = project;
  so.evaluate_end_state = false;
  Simulator sim(scene.model, scene.constraints, makeSolver(form, scene.model, scene.constraints),
                type, io, so);
  sim.setState(0, scene.q0, scene.v0);
  if (scene.tau.size() == scene.model.nv) {
    const VecX tau = scene.tau;
    sim.setJointForces([tau](double, const VecX&, const VecX&, VecX& out) { out = tau; });
  }
  const double E0 = sim.energy();
  Run r;
  const auto t0 = std::chrono::steady_clock::now();
  const StepStatus st = sim.advanceTo(T, dt);
  r.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.ok = st.ok;
  r.q = sim.q();
  r.v = sim.v();
  r.steps = sim.counters().steps;
  // energy() is that of the last evaluated state; evaluate_end_state is off for
  // speed, so compute it here, outside the timed region.
  Data data(scene.model);
  r.energy_drift = std::abs(kineticEnergy(scene.model, data, r.q, r.v) +
                            potentialEnergy(scene.model, data, r.q) - E0) /
                   std::max(1e-12, std::abs(E0));
  ConstraintData cd(scene.model, scene.constraints, DenseRows::None);
  evaluateConstraintRows(scene.model, data, scene.constraints, cd, T, r.q, r.v);
  r.residual = std::max(velocityResidual(data, scene.constraints, cd, r.v), gapResidual(cd));
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  int repeats = 5;
  std::string out_dir = "bench/results";
  std::vector<std::string> scenes;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--repeats" && i + 1 < argc) repeats = std::max(1, std::atoi(argv[++i]));
    else if (a == "--out" && i + 1 < argc) out_dir = argv[++i];
    else scenes.push_back(a);
  }
  if (scenes.empty()) scenes = {"examples/rolling_disk/rolling_disk.urdf"};
  std::filesystem::create_directories(out_dir);
  std::ofstream csv(out_dir + "/speed_error.csv");
  csv << "scene,method,setting,steps,wall_per_sim_second,state_error,energy_drift,residual\n";

  const double T = 2.0;
  std::string scene_names;
  for (const std::string& path : scenes) {
    Scene scene;
    try {
      scene = loadScene(path);
    } catch (const std::exception& e) {
      std::cerr << e.what() << "\n";
      return 1;
    }
    const std::string name = std::filesystem::path(path).stem();
    scene_names += (scene_names.empty() ? "" : " ") + name;
    const Run ref = simulate(scene, IntegratorType::DormandPrince54, 1e-3, 1e-14, T,
                             Formulation::Multipliers, true);
    std::cout << name << ": reference dopri5 tol 1e-14, " << ref.steps << " steps\n";
    struct Case {
      IntegratorType type;
      std::string method;
      std::vector<double> settings;
    };
    const std::vector<Case> cases = {
        {IntegratorType::SymplecticEuler, "euler", {4e-3, 2e-3, 1e-3, 5e-4, 2.5e-4}},
        {IntegratorType::RK4, "rk4", {2e-2, 1e-2, 5e-3, 2.5e-3, 1.25e-3}},
        {IntegratorType::DormandPrince54, "dopri5", {1e-4, 1e-6, 1e-8, 1e-10, 1e-12}},
        {IntegratorType::DormandPrince853, "dop853", {1e-6, 1e-8, 1e-10, 1e-12}}};
    VecX dq(scene.model.nv);
    for (const Case& c : cases) {
      for (double s : c.settings) {
        const bool adaptive = adaptiveIntegrator(c.type);
        std::vector<double> walls;
        Run r;
        for (int k = 0; k < repeats; ++k) {
          r = simulate(scene, c.type, adaptive ? 1e-3 : s, adaptive ? s : 1e-8, T,
                       Formulation::Tree, true);
          walls.push_back(r.wall);
        }
        std::nth_element(walls.begin(), walls.begin() + walls.size() / 2, walls.end());
        difference(scene.model, ref.q, r.q, dq);
        const double err = r.ok ? std::max(dq.lpNorm<Eigen::Infinity>(),
                                           (r.v - ref.v).lpNorm<Eigen::Infinity>())
                                : std::numeric_limits<double>::quiet_NaN();
        csv << name << "," << c.method << "," << s << "," << r.steps << ","
            << walls[walls.size() / 2] / T << "," << err << "," << r.energy_drift << ","
            << r.residual << "\n";
        std::cout << "  " << c.method << (adaptive ? " tol " : " dt ") << s << ": " << r.steps
                  << " steps, " << 1e3 * walls[walls.size() / 2] / T << " ms per simulated s, error "
                  << err << ", energy drift " << r.energy_drift << ", residual " << r.residual
                  << "\n";
      }
    }
  }
  csv.close();
  if (std::system("command -v gnuplot > /dev/null 2>&1") == 0) {
    const std::string plot = out_dir + "/speed_error.gp";
    std::ofstream gp(plot);
    gp << "# speed_error.png, made by bench/report_speed_error (its data: speed_error.csv):\n#  ";
    for (int i = 0; i < argc; ++i) gp << " " << argv[i];
    gp << "\nset datafile separator ','\nset terminal pngcairo size 1100,600 noenhanced\n"
       << "set output '" << out_dir << "/speed_error.png'\n"
       << "set logscale xy\nset format y '1e%L'\nset format x '1e%L'\n"
       << "set xlabel 'wall time per simulated second [s]'\n"
       << "set ylabel 'max state error at t = 2 s'\nset key outside right\nset grid\n"
       << "set title 'appell: speed against error (tree solver, projection on)'\n"
       << "scenes = '" << scene_names << "'\nmethods = 'euler rk4 dopri5 dop853'\n"
       << "plot for [i=1:words(scenes)*4] '" << out_dir << "/speed_error.csv' using "
       << "((strcol(1) eq word(scenes, (i-1)/4+1) && strcol(2) eq word(methods, (i-1)%4+1)) ? $5 : 1/0):6 "
       << "with linespoints lc (i-1)%4+1 pt (i-1)/4+4 "
       << "title word(methods, (i-1)%4+1).' / '.word(scenes, (i-1)/4+1)\n";
    gp.close();
    if (std::system(("gnuplot " + plot).c_str()) == 0)
      std::cout << "figure: " << out_dir << "/speed_error.png\n";
  }
  return 0;
}
