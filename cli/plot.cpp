// The plots of a run (plot.hpp): data files from the trajectory CSV, gnuplot
// scripts beside them, and the PNGs gnuplot draws from them.
#include "plot.hpp"

#include <appell/constraint.hpp>
#include <appell/output.hpp>
#include <appell/trajectory_reader.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <charconv>
#include <cmath>
#include <filesystem>
#include <cstdio>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace appell::cli {

namespace fs = std::filesystem;

namespace {

/// A single-quoted gnuplot string ('' is a quote inside it).
std::string quoted(const std::string& s) {
  std::string out = "'";
  for (const char c : s) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

/// Writes columns of numbers, shortest round-trip form; NaN as gnuplot's missing "NaN".
void writeData(const fs::path& path, const std::vector<std::string>& names,
               const std::vector<std::vector<double>>& columns) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write '" + path.string() + "'");
  out << "#";
  for (const std::string& n : names) out << " " << n;
  out << "\n";
  char buf[32];
  for (size_t r = 0; r < columns.at(0).size(); ++r) {
    for (size_t c = 0; c < columns.size(); ++c) {
      if (c) out << ' ';
      const double x = columns[c][r];
      if (std::isnan(x)) out << "NaN";
      else out.write(buf, std::to_chars(buf, buf + sizeof buf, x).ptr - buf);
    }
    out << '\n';
  }
  if (!out.flush()) throw std::runtime_error("error writing '" + path.string() + "'");
}

std::string header(const std::string& png, const std::string& title, int plots) {
  std::ostringstream gp;
  gp << "# Written by appell plot; redraw with: gnuplot " << fs::path(png).stem().string() << ".gp\n"
     << "set encoding utf8\nset terminal pngcairo size 960," << (plots > 2 ? 960 : plots > 1 ? 760 : 560)
     << " noenhanced font 'sans,10'\nset output " << quoted(png) << "\nset grid\nset key outside right\nset lmargin 13\nset rmargin 24\n"
     << "set xlabel 't [s]'\n";
  if (plots > 1) gp << "set multiplot layout " << plots << ",1 title " << quoted(title) << "\n";
  else gp << "set title " << quoted(title) << "\n";
  return gp.str();
}

void runGnuplot(const fs::path& dir, const std::string& script) {
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("cannot start gnuplot (fork failed)");
  if (pid == 0) {
    if (chdir(dir.c_str()) != 0) _exit(126);
    execlp("gnuplot", "gnuplot", script.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code == 127)
    throw std::runtime_error("gnuplot not found: install Debian's gnuplot-nox (scripts/install-deps.sh)");
  if (code != 0)
    throw std::runtime_error("gnuplot failed on " + (dir / script).string() + " (exit " +
                             std::to_string(code) + ")");
}

/// Colour of curve k of n as gnuplot's "rgb '#rrggbb'", all n distinct. Up
/// to 8 curves: Okabe & Ito's (2008, "Color Universal Design") colour-blind
/// safe set, less its yellow, plus a grey; beyond 8 (gnuplot's own cycle
/// repeats after 8): n hues evenly spaced round the HSV wheel, neighbours
/// alternating between a bright and a dark shade. Distinct in 8-bit RGB
/// while the hue step 1/n exceeds one 8-bit level of a channel (n < 1530).
std::string seriesColour(size_t k, size_t n) {
  static const char* kFew[] = {"#0072b2", "#d55e00", "#009e73", "#cc79a7",
                               "#e69f00", "#56b4e9", "#000000", "#8a8a8a"};
  if (n <= 8) return std::string("rgb '") + kFew[k] + "'";
  const double h = 6.0 * static_cast<double>(k) / static_cast<double>(n), v = k % 2 ? 0.6 : 0.92;
  const double f = h - std::floor(h), s = 0.85;
  const double p = v * (1 - s), q = v * (1 - s * f), u = v * (1 - s * (1 - f));
  double rgb[3];
  switch (static_cast<int>(h) % 6) {
    case 0: rgb[0] = v, rgb[1] = u, rgb[2] = p; break;
    case 1: rgb[0] = q, rgb[1] = v, rgb[2] = p; break;
    case 2: rgb[0] = p, rgb[1] = v, rgb[2] = u; break;
    case 3: rgb[0] = p, rgb[1] = q, rgb[2] = v; break;
    case 4: rgb[0] = u, rgb[1] = p, rgb[2] = v; break;
    default: rgb[0] = v, rgb[1] = p, rgb[2] = q; break;
  }
  char hex[16];
  std::snprintf(hex, sizeof hex, "#%02x%02x%02x", static_cast<int>(std::lround(255 * rgb[0])),
                static_cast<int>(std::lround(255 * rgb[1])), static_cast<int>(std::lround(255 * rgb[2])));
  return std::string("rgb '") + hex + "'";
}

struct ContactColumns {
  std::string name;
  int normal = -1;
  std::vector<int> tangential;
  int px = -1, py = -1;
};

/// Contacts in CSV order: each "point:<c>.x" column opens one; its rows are
/// the "lambda:<c>.<label>" columns (output.hpp). A file read back has only
/// the labels; they are the row kinds' names (toString(RowKind)), so the
/// normal and friction rows are found through that one table.
std::vector<ContactColumns> contactColumns(const TrajectoryTable& table) {
  std::vector<ContactColumns> out;
  for (size_t i = 0; i < table.columns.size(); ++i) {
    const std::string& col = table.columns[i];
    if (col.rfind("point:", 0) == 0 && col.size() > 8 && col.compare(col.size() - 2, 2, ".x") == 0) {
      ContactColumns c;
      c.name = col.substr(6, col.size() - 8);
      c.px = static_cast<int>(i);
      c.py = table.find("point:" + c.name + ".y");
      c.normal = table.find("lambda:" + c.name + "." + toString(RowKind::Normal));
      for (RowKind kind : {RowKind::Tangent1, RowKind::Tangent2, RowKind::Lateral}) {
        const int k = table.find("lambda:" + c.name + "." + toString(kind));
        if (k >= 0) c.tangential.push_back(k);
      }
      out.push_back(c);
    }
  }
  return out;
}

/// The one-degree-of-freedom joints (revolute, continuous, prismatic): a
/// "q:<joint>" column with a "v:<joint>" of the same name (planar and
/// floating joints have suffixed coordinates, drawn on path.png).
std::vector<std::string> scalarJoints(const TrajectoryTable& table) {
  std::vector<std::string> joints;
  for (const std::string& col : table.columns)
    if (col.rfind("q:", 0) == 0 && table.find("v:" + col.substr(2)) >= 0) joints.push_back(col.substr(2));
  return joints;
}

/// τ of each joint at every sample: the scene's constant efforts plus its
/// servos (Scene::jointForces) evaluated at the sample's (t, q, v); the
/// trajectory must be the scene's (all its q and v columns).
std::vector<std::vector<double>> jointEfforts(const TrajectoryTable& table, const Scene& scene,
                                              const std::vector<std::string>& joints) {
  const Model& m = scene.model;
  std::vector<int> qcol, vcol, slot;
  for (const std::string& n : coordinateNames(m, false)) qcol.push_back(table.require("q:" + n));
  for (const std::string& n : coordinateNames(m, true)) vcol.push_back(table.require("v:" + n));
  for (const std::string& j : joints) {
    const int b = m.jointIndex(j);
    if (b < 0) throw std::runtime_error(table.source + ": joint '" + j + "' is not in the scene " + scene.source);
    slot.push_back(m.joints[b].idx_v);
  }
  const Simulator::JointForces forces = scene.jointForces();
  std::vector<std::vector<double>> tau(joints.size(), std::vector<double>(table.rows.size()));
  VecX q(m.nq), v(m.nv), out(m.nv);
  for (size_t i = 0; i < table.rows.size(); ++i) {
    for (int k = 0; k < m.nq; ++k) q[k] = table.rows[i][qcol[k]];
    for (int k = 0; k < m.nv; ++k) v[k] = table.rows[i][vcol[k]];
    out.setZero();
    forces(table.rows[i][0], q, v, out);
    for (size_t j = 0; j < joints.size(); ++j) tau[j][i] = out[slot[j]];
  }
  return tau;
}

/// joints.dat and the script of joints.png: q and v of every one-degree-of-
/// freedom joint, and its applied force τ when the scene is known and drives
/// joints; nothing when the model has no such joint.
std::optional<std::string> jointPlot(const TrajectoryTable& table, const fs::path& dir, const std::string& run,
                                     const Scene* scene) {
  const std::vector<std::string> joints = scalarJoints(table);
  if (joints.empty()) return std::nullopt;
  const bool efforts = scene && scene->driven();
  std::vector<std::string> names = {"t"};
  std::vector<std::vector<double>> cols = {table.column(0)};
  for (const std::string& j : joints) {
    names.insert(names.end(), {"q:" + j, "v:" + j});
    cols.push_back(table.column(table.require("q:" + j)));
    cols.push_back(table.column(table.require("v:" + j)));
  }
  if (efforts)
    for (std::vector<double>& tau : jointEfforts(table, *scene, joints)) cols.push_back(std::move(tau));
  for (size_t j = 0; efforts && j < joints.size(); ++j) names.push_back("tau:" + joints[j]);
  writeData(dir / "joints.dat", names, cols);
  const size_t n = joints.size(), stride = 2;
  auto panel = [&](const std::string& ylabel, auto column) {
    std::string p = "set ylabel " + quoted(ylabel) + "\nplot ";
    for (size_t k = 0; k < n; ++k)
      p += std::string(k ? ", " : "") + "'joints.dat' using 1:" + std::to_string(column(k)) +
           " with lines lw 2 lc " + seriesColour(k, n) + " title " + quoted(joints[k]);
    return p + "\n";
  };
  std::string script = header("joints.png", "joints — " + run, efforts ? 3 : 2);
  script += panel("q [rad or m]", [&](size_t k) { return 2 + stride * k; });
  script += panel("v [rad/s or m/s]", [&](size_t k) { return 3 + stride * k; });
  if (efforts) script += panel("τ [N·m or N]", [&](size_t k) { return 2 + stride * n + k; });
  return script + "unset multiplot\n";
}

}  // namespace

std::string defaultPlotDir(const std::string& csv) {
  const fs::path p(csv);
  return (p.parent_path() / (p.stem().string() + "_plots")).string();
}

std::vector<std::string> writePlots(const std::string& csv, const std::string& dir_name,
                                    const Scene* scene) {
  const TrajectoryTable table = readTrajectory(csv);
  const fs::path dir(dir_name);
  fs::create_directories(dir);
  const std::string run = fs::path(csv).filename().string();
  const std::vector<double> t = table.column(0);
  const size_t n = t.size();
  std::vector<std::string> pngs;
  auto draw = [&](const std::string& name, const std::string& script) {
    std::ofstream(dir / (name + ".gp")) << script;
    runGnuplot(dir, name + ".gp");
    pngs.push_back((dir / (name + ".png")).string());
  };

  // Energy and its drift from the first sample.
  {
    const std::vector<double> E = table.column(table.require("energy"));
    std::vector<double> dE(n);
    for (size_t i = 0; i < n; ++i) dE[i] = E[i] - E[0];
    writeData(dir / "energy.dat", {"t", "E", "E-E0"}, {t, E, dE});
    draw("energy", header("energy.png", "energy — " + run, 2) +
                       "set ylabel 'E [J]'\nset format y '%.12g'\nplot 'energy.dat' using 1:2 with lines lw 2 title 'E'\n"
                       "set ylabel 'E − E(0) [J]'\nset format y '%.2g'\n"
                       "plot 'energy.dat' using 1:3 with lines lw 2 lc rgb '#c02030' title 'E − E(0)'\n"
                       "unset multiplot\n");
  }
  // Constraint residuals (zeros are left out of the log scale).
  {
    writeData(dir / "residuals.dat", {"t", "residual"}, {t, table.column(table.require("residual"))});
    draw("residuals", header("residuals.png", "constraint residuals — " + run, 1) +
                          "set logscale y\nset format y '%.0e'\nset ylabel 'max(|Av+b|, |gap|)'\n"
                          "plot 'residuals.dat' using 1:($2 > 0 ? $2 : NaN) with lines lw 2 "
                          "title 'residual'\n");
  }
  // Per contact: normal load and friction demand against μ.
  const std::vector<ContactColumns> contacts = contactColumns(table);
  std::vector<ContactColumns> loaded;
  for (const ContactColumns& c : contacts)
    if (c.normal >= 0) loaded.push_back(c);
  if (!loaded.empty()) {
    std::vector<std::string> names = {"t"};
    std::vector<std::vector<double>> cols = {t};
    std::string load_plot = "plot ", demand_plot = "plot ";
    for (size_t k = 0; k < loaded.size(); ++k) {
      const ContactColumns& c = loaded[k];
      std::vector<double> fn = table.column(c.normal), demand(n);
      for (size_t i = 0; i < n; ++i) {
        double ft2 = 0;
        for (int r : c.tangential) ft2 += table.rows[i][r] * table.rows[i][r];
        demand[i] = fn[i] > 0 ? std::sqrt(ft2) / fn[i] : std::nan("");
      }
      names.push_back(c.name + ":normal");
      names.push_back(c.name + ":demand");
      cols.push_back(fn);
      cols.push_back(demand);
      const std::string sep = k ? ", " : "";
      const std::string lc = seriesColour(k, loaded.size());
      load_plot += sep + "'contacts.dat' using 1:" + std::to_string(2 + 2 * k) +
                   " with lines lw 2 lc " + lc + " title " + quoted(c.name);
      demand_plot += sep + "'contacts.dat' using 1:" + std::to_string(3 + 2 * k) +
                     " with lines lw 2 lc " + lc + " title " + quoted(c.name);
      const int ci = scene ? scene->contactIndex(c.name) : -1;
      if (ci >= 0 && std::isfinite(scene->contacts[ci]->mu())) {
        char mu[32];
        *std::to_chars(mu, mu + sizeof mu - 1, scene->contacts[ci]->mu()).ptr = 0;
        demand_plot += ", " + std::string(mu) + " with lines dt 2 lw 2 lc " + lc +
                       " title " + quoted("μ " + c.name + " = " + mu);
      }
    }
    writeData(dir / "contacts.dat", names, cols);
    draw("contacts", header("contacts.png", "contacts — " + run, 2) +
                         "set ylabel 'normal load [N]'\n" + load_plot + "\n" +
                         "set ylabel '|f_t| / f_n'\nset yrange [0:*]\nset offsets 0, 0, graph 0.08, 0\n" + demand_plot +
                         "\nunset multiplot\n");
  }
  // Paths from above: joint origins with an x and a y, and contact points.
  {
    struct Path { std::string label; int x, y; const char* style; };
    std::vector<Path> paths;
    for (size_t i = 0; i < table.columns.size(); ++i) {
      const std::string& col = table.columns[i];
      if (col.rfind("q:", 0) == 0 && col.size() > 4 && col.compare(col.size() - 2, 2, ".x") == 0) {
        const std::string joint = col.substr(2, col.size() - 4);
        paths.push_back({joint, static_cast<int>(i), table.find("q:" + joint + ".y"), "lw 2"});
      }
    }
    for (const ContactColumns& c : contacts) paths.push_back({"contact " + c.name, c.px, c.py, "lw 1 dt 3"});
    std::erase_if(paths, [](const Path& p) { return p.x < 0 || p.y < 0; });
    std::vector<std::string> names = {"t"};
    std::vector<std::vector<double>> cols = {t};
    std::string plot;
    for (size_t k = 0; k < paths.size(); ++k) {
      const Path& p = paths[k];  // const: std::quoted(string&) would be a better match by ADL
      names.push_back(p.label + ".x");
      names.push_back(p.label + ".y");
      cols.push_back(table.column(p.x));
      cols.push_back(table.column(p.y));
      plot += std::string(k ? ", " : "plot ") + "'path.dat' using " + std::to_string(2 * k + 2) + ":" +
              std::to_string(2 * k + 3) + " with lines " + p.style + " lc " + seriesColour(k, paths.size()) +
              " title " + quoted(p.label);
    }
    if (!plot.empty()) {
      writeData(dir / "path.dat", names, cols);
      draw("path", header("path.png", "path seen from above — " + run, 1) +
                       "set size ratio -1\nset xlabel 'x [m]'\nset ylabel 'y [m]'\n" + plot + "\n");
    }
  }
  if (std::optional<std::string> script = jointPlot(table, dir, run, scene)) draw("joints", *script);
  return pngs;
}

}  // namespace appell::cli

namespace appell::cli {

void writeStabilityPlot(const std::string& png, const std::string& parameter,
                        const std::vector<double>& values, const std::vector<double>& max_real) {
  const fs::path path = fs::absolute(png);
  const fs::path dir = path.parent_path();
  fs::create_directories(dir);
  const std::string stem = path.stem().string();
  writeData(dir / (stem + ".dat"), {parameter, "max_real"}, {values, max_real});
  std::ofstream gp(dir / (stem + ".gp"));
  gp << header(path.filename().string(), "stability diagram: largest real part of the eigenvalues", 1)
     << "set xlabel " << quoted(parameter) << "\nset ylabel 'max Re(mu) [1/s]'\n"
     << "plot " << quoted(stem + ".dat") << " using 1:2 with linespoints title 'largest Re', 0 with lines dt 2 lc 'black' title 'zero'\n";
  if (!gp.flush()) throw std::runtime_error("cannot write '" + (dir / (stem + ".gp")).string() + "'");
  gp.close();
  runGnuplot(dir, stem + ".gp");
}

}  // namespace appell::cli
