// appell view: a self-contained HTML page that replays a run in 3-D.
//
// The page draws what appell computed, not a re-derivation of it: the
// replay data (run/'s replay.hpp: body poses, contact points and reaction
// forces per CSV sample, or the initial state alone) written by its one
// serializer into the page template with the viewer's script.
#include "commands.hpp"

#include <appell/appell.hpp>
#include <appell/replay.hpp>
#include <appell/trajectory_reader.hpp>
#include <appell_viewer/assets.hpp>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>

namespace appell::cli {

namespace {

const char* kViewHelp = R"(usage: appell view SCENE.urdf [options]

Writes one HTML file that replays the motion in 3-D (three.js, embedded: the
page loads nothing). Open it in a browser: play/pause, scrub, orbit with the mouse.

  --trajectory RUN.csv  the motion, as `appell run --out` wrote it
                        (default: the initial state only)
  --out PAGE.html       where to write the page (default: SCENE name + .html)
  --package-path DIRS   colon/comma-separated folders for package:// meshes
  --project-initial     project an initial state that violates the constraints
)" APPELL_INERTIA_HELP R"(  --no-joint-limits     leave out the URDF joint limits (as `run` does with it);
                        a trajectory without the limits' columns (a run with
                        --no-joint-limits) is shown without them in any case

Page URL options (after #): t=2.5 (show that time), view=top (orthographic from
above), center=x,y and span=S (top view framing, metres), play=1, contacts=0.
)";

/// A run with --no-joint-limits writes no columns for the limits. When the
/// trajectory has none of them, the limits are left out of `scene` (as
/// --no-joint-limits would) with a note, so `view` takes every CSV `run`
/// writes; a file with some of the limits' columns but not all is refused
/// later, naming the first missing column.
void matchJointLimits(Scene& scene, const TrajectoryTable& table) {
  if (scene.joint_limits.empty()) return;
  for (const auto& limit : scene.joint_limits)
    for (const std::string& c : table.columns)
      if (c.rfind("lambda:" + limit->name() + ".", 0) == 0 || c == "closed:" + limit->name()) return;
  std::set<const Constraint*> limits;
  for (const auto& limit : scene.joint_limits) limits.insert(limit.get());
  std::erase_if(scene.constraints, [&](const auto& c) { return limits.count(c.get()) > 0; });
  std::cerr << "appell view: note: " << table.source << " has no columns for the scene's "
            << scene.joint_limits.size() << " joint limits (a run with --no-joint-limits): "
            << "shown without them\n";
  scene.joint_limits.clear();
}

std::string fill(std::string_view page, const std::string& title, const std::string& data,
                 std::string_view script) {
  std::string out;
  size_t at = 0;
  while (true) {
    const size_t k = page.find('@', at);
    if (k == std::string_view::npos) break;
    out.append(page.substr(at, k - at));
    if (page.substr(k, 7) == "@TITLE@") out += title, at = k + 7;
    else if (page.substr(k, 6) == "@DATA@") out += data, at = k + 6;
    else if (page.substr(k, 8) == "@SCRIPT@") out.append(script), at = k + 8;
    else out += '@', at = k + 1;
  }
  out.append(page.substr(at));
  return out;
}

}  // namespace

int view(int argc, char** argv) {
  std::set<std::string> valued = kLoadOptions;
  valued.insert({"trajectory", "out"});
  Args args(argc, argv, 2, valued, kLoadFlags);
  if (args.has("help")) {
    std::cout << kViewHelp;
    return 0;
  }
  if (viewer::script().empty())
    throw std::runtime_error(
        "this appell was built without the viewer's three.js (viewer/node_modules is missing): "
        "run scripts/install-viewer-deps.sh, then rebuild");
  Scene scene = loadFromArgs(args, !args.has("trajectory"));
  std::vector<ReplayFrame> frames;
  if (args.has("trajectory")) {
    const TrajectoryTable table = readTrajectory(args.text("trajectory"));
    matchJointLimits(scene, table);
    frames = replayFrames(scene, table);
  } else {
    frames = initialReplayFrame(scene);
  }
  const std::string stem = std::filesystem::path(scene.source).stem().string();
  const std::string out = args.text("out", stem + ".html");
  refuseOverwritingInputs("out", out, scene,
                          args.has("trajectory") ? std::vector<std::string>{args.text("trajectory")}
                                                 : std::vector<std::string>{});
  std::ofstream page(out, std::ios::binary);
  if (!page) throw std::runtime_error("cannot write '" + out + "'");
  page << fill(viewer::pageTemplate(), stem, replayJson(scene, frames), viewer::script());
  if (!page.flush()) throw std::runtime_error("error writing '" + out + "'");
  std::cout << "page         " << out << " (" << frames.size() << " samples, t = " << frames.front().t
            << " … " << frames.back().t << " s)\n";
  return 0;
}

}  // namespace appell::cli
