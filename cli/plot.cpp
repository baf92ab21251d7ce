#include "plot.hpp"

#include <appell/constraint.hpp>
#include <appell/trajectory_reader.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
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
     << "set encoding utf8\nset terminal pngcairo size 960," << (plots > 1 ? 760 : 560)
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
      const int lc = static_cast<int>(k) + 1;
      load_plot += sep + "'contacts.dat' using 1:" + std::to_string(2 + 2 * k) +
                   " with lines lw 2 lc " + std::to_string(lc) + " title " + quoted(c.name);
      demand_plot += sep + "'contacts.dat' using 1:" + std::to_string(3 + 2 * k) +
                     " with lines lw 2 lc " + std::to_string(lc) + " title " + quoted(c.name);
      const int ci = scene ? scene->contactIndex(c.name) : -1;
      if (ci >= 0 && std::isfinite(scene->contacts[ci]->mu())) {
        char mu[32];
        *std::to_chars(mu, mu + sizeof mu - 1, scene->contacts[ci]->mu()).ptr = 0;
        demand_plot += ", " + std::string(mu) + " with lines dt 2 lw 2 lc " + std::to_string(lc) +
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
    std::vector<std::string> names = {"t"};
    std::vector<std::vector<double>> cols = {t};
    std::string plot;
    auto add = [&](const std::string& label, int x, int y, const std::string& style) {
      if (x < 0 || y < 0) return;
      names.push_back(label + ".x");
      names.push_back(label + ".y");
      cols.push_back(table.column(x));
      cols.push_back(table.column(y));
      const size_t k = cols.size() - 2;
      plot += std::string(plot.empty() ? "plot " : ", ") + "'path.dat' using " +
              std::to_string(k + 1) + ":" + std::to_string(k + 2) + " with lines " + style +
              " title " + quoted(label);
    };
    for (size_t i = 0; i < table.columns.size(); ++i) {
      const std::string& col = table.columns[i];
      if (col.rfind("q:", 0) == 0 && col.size() > 4 && col.compare(col.size() - 2, 2, ".x") == 0) {
        const std::string joint = col.substr(2, col.size() - 4);
        add(joint, static_cast<int>(i), table.find("q:" + joint + ".y"), "lw 2");
      }
    }
    for (const ContactColumns& c : contacts) add("contact " + c.name, c.px, c.py, "lw 1 dt 3");
    if (!plot.empty()) {
      writeData(dir / "path.dat", names, cols);
      draw("path", header("path.png", "path seen from above — " + run, 1) +
                       "set size ratio -1\nset xlabel 'x [m]'\nset ylabel 'y [m]'\n" + plot + "\n");
    }
  }
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
