// appell plot: PNG plots of a run's trajectory CSV with gnuplot (plot.hpp).
#include "commands.hpp"
#include "plot.hpp"

#include <iostream>

namespace appell::cli {

namespace {

const char* kPlotHelp = R"(usage: appell plot RUN.csv [options]

Plots a trajectory that `appell run --out RUN.csv` wrote, with gnuplot:
  energy.png      E(t) and E(t) − E(0)
  residuals.png   constraint residual per sample (log scale)
  contacts.png    normal load and friction demand |f_t|/f_n per contact (and μ)
  path.png        the paths of the joints' origins and of the contacts, from above
  joints.png      q and v of each revolute, continuous and prismatic joint, and
                  its applied force τ (efforts and servos; needs --scene)
The .dat files gnuplot reads and its .gp scripts are written beside them.

  --out DIR             folder for the plots (default: RUN_plots beside RUN.csv)
  --scene SCENE.urdf    the run's scene: draws each contact's μ on contacts.png
                        and the joints' applied forces τ on joints.png
  --package-path DIRS   colon/comma-separated folders for the scene's package:// meshes
)";

}  // namespace

int plot(int argc, char** argv) {
  Args args(argc, argv, 2, {"out", "scene", "package-path"}, {"help"});
  if (args.has("help")) {
    std::cout << kPlotHelp;
    return 0;
  }
  if (args.positional().size() != 1) throw UsageError("expected exactly one RUN.csv argument");
  const std::string csv = args.positional()[0];
  Scene scene;
  if (args.has("scene")) {
    LoadOptions opt;
    for (const std::string& p : args.list("package-path")) opt.package_paths.push_back(p);
    opt.check_initial_state = false;
    scene = loadScene(args.text("scene"), opt);
  }
  const std::string dir = args.text("out", defaultPlotDir(csv));
  for (const std::string& png : writePlots(csv, dir, args.has("scene") ? &scene : nullptr))
    std::cout << "plot         " << png << "\n";
  return 0;
}

}  // namespace appell::cli
