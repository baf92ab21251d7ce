// appell view: a self-contained HTML page that replays a run in 3-D.
//
// The page draws what appell computed, not a re-derivation of it: for every
// CSV sample the command runs forward kinematics on the sample's q (body poses
// oMi) and evaluates each constraint at (q, v, t) for its rows; the reaction
// force on the contact body is f = Σ_r λ_r d_r, with λ_r from the CSV and d_r
// the linear part of row r's world covector W_r = [p × d_r; d_r] (the row
// constrains d_r · v_p, so λ_r is the force along d_r — constraint.hpp).
// Without a trajectory the page shows the initial state, with λ from the
// dynamics solved there.
#include "commands.hpp"

#include <appell/appell.hpp>
#include <appell/output.hpp>
#include <appell/simulator.hpp>
#include <appell/trajectory_reader.hpp>
#include <appell_viewer/assets.hpp>

#include <charconv>
#include <cmath>
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

/// The page's data as JSON, written by hand: numbers in the shortest form that
/// reads back to the same double, so the page shows the CSV's values.
class Json {
 public:
  Json& num(double x) {
    sep();
    if (!std::isfinite(x)) {
      s_ += "null";
      return *this;
    }
    char buf[32];
    s_.append(buf, std::to_chars(buf, buf + sizeof buf, x).ptr);
    return *this;
  }
  Json& str(const std::string& t) {
    sep();
    s_ += '"';
    for (const char c : t) {
      if (c == '"' || c == '\\') s_ += '\\', s_ += c;
      else if (c == '<') s_ += "\\u003c";  // never "</script>" inside the page's <script>
      else if (static_cast<unsigned char>(c) < 0x20) {
        char buf[8];
        std::snprintf(buf, sizeof buf, "\\u%04x", c);
        s_ += buf;
      } else s_ += c;
    }
    s_ += '"';
    return *this;
  }
  Json& key(const std::string& k) {
    str(k);
    s_ += ':';
    first_ = true;
    return *this;
  }
  Json& open(char c) {
    sep();
    s_ += c;
    first_ = true;
    return *this;
  }
  Json& close(char c) {
    s_ += c;
    first_ = false;
    return *this;
  }
  Json& raw(const char* t) {
    sep();
    s_ += t;
    return *this;
  }
  template <class V>
  Json& vec(const V& v) {
    open('[');
    for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(v.size()); ++i) num(v[i]);
    return close(']');
  }
  const std::string& text() const { return s_; }

 private:
  void sep() {
    if (!first_) s_ += ',';
    first_ = false;
  }
  std::string s_;
  bool first_ = true;
};

/// The URDF material colour of a visual, when it has one: "rgba": [r, g, b, a]
/// (sRGB components in [0, 1], as RViz reads them).
void writeColour(Json& j, const Geometry& g) {
  if (!g.rgba) return;
  j.key("rgba").open('[');
  for (const double c : *g.rgba) j.num(c);
  j.close(']');
}

void writeGeometry(Json& j, const Geometry& g) {
  j.open('{').key("type");
  const Quat q(g.origin.R);
  switch (g.type) {
    case GeometryType::Box: j.str("box").key("size").vec(g.box_size); break;
    case GeometryType::Sphere: j.str("sphere").key("radius").num(g.radius); break;
    case GeometryType::Cylinder:
      j.str("cylinder").key("radius").num(g.radius).key("length").num(g.length);
      break;
    case GeometryType::Mesh: {
      j.str("mesh").key("vertices").open('[');
      for (const Vec3& v : g.mesh->vertices) j.num(v.x()).num(v.y()).num(v.z());
      j.close(']').key("triangles").open('[');
      for (const auto& t : g.mesh->triangles) j.num(t[0]).num(t[1]).num(t[2]);
      j.close(']');
      break;
    }
  }
  j.key("p").vec(g.origin.p).key("q").open('[').num(q.x()).num(q.y()).num(q.z()).num(q.w());
  j.close(']');
  writeColour(j, g);
  j.close('}');
}

/// A terrain support's triangles, in its support frame (the page places the
/// frame per sample, as for the other supports): "vertices" x,y,z flat,
/// "triangles" three indices each, in the mesh's winding (normals up).
void writeTerrain(Json& j, const TerrainMesh& terrain) {
  j.key("vertices").open('[');
  for (const Vec3& v : terrain.vertices) j.num(v.x()).num(v.y()).num(v.z());
  j.close(']').key("triangles").open('[');
  for (const auto& t : terrain.triangles) j.num(t[0]).num(t[1]).num(t[2]);
  j.close(']');
}

/// Radius of a ball about the body origin holding the geometry (frames the camera).
double reach(const Geometry& g) {
  double r = 0;
  switch (g.type) {
    case GeometryType::Box: r = 0.5 * g.box_size.norm(); break;
    case GeometryType::Sphere: r = g.radius; break;
    case GeometryType::Cylinder: r = std::hypot(g.radius, 0.5 * g.length); break;
    case GeometryType::Mesh:
      for (const Vec3& v : g.mesh->vertices) r = std::max(r, v.norm());
      break;
  }
  return r + g.origin.p.norm();
}

/// One sample of what the page shows.
struct Frame {
  double t;
  std::vector<double> poses, points, forces;  // 7 per body, 3 per constraint, 3 per constraint
  std::vector<double> supports;                // 7 per support: its frame in the world
  std::vector<double> closed;                  // 1 per constraint: 1 closed, 0 open (lifted off)
  std::vector<std::pair<int, int>> events;     // (constraint, 1 + ContactEventKind) at this time
};

void appendPose(std::vector<double>& out, const SE3& X) {
  const Quat r(X.R);
  out.insert(out.end(), {X.p.x(), X.p.y(), X.p.z(), r.x(), r.y(), r.z(), r.w()});
}

Frame frameAt(const Scene& scene, Data& data, std::vector<RowBlock>& blocks, double t,
              const VecX& q, const VecX& v, const VecX& lambda) {
  const Model& m = scene.model;
  Frame f{t, {}, {}, {}, {}, std::vector<double>(scene.constraints.size(), 1.0), {}};
  forwardKinematics(m, data, q, v);
  for (int b = 0; b < m.nbodies; ++b) appendPose(f.poses, data.oMi[b]);
  // A support frame moves as its motion says, or rides on its body (supports.hpp).
  for (const Support& s : scene.supports)
    appendPose(f.supports, s.body >= 0 ? data.oMi[s.body] * std::get<StaticMotion>(s.motion).pose
                                       : supportState(s.motion, t).pose);
  int row = 0;
  for (size_t c = 0; c < scene.constraints.size(); ++c) {
    const Constraint& con = *scene.constraints[c];
    con.evaluate(m, data, t, q, v, blocks[c]);
    Vec3 force = Vec3::Zero();
    if (!con.jointSpace())
      for (int r = 0; r < con.rows(); ++r) force += lambda[row + r] * blocks[c].Wa.row(r).tail<3>().transpose();
    row += con.rows();
    const Vec3& p = blocks[c].frame.point;
    f.points.insert(f.points.end(), {p.x(), p.y(), p.z()});
    f.forces.insert(f.forces.end(), {force.x(), force.y(), force.z()});
  }
  return f;
}

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

std::vector<Frame> framesFromTrajectory(const Scene& scene, const TrajectoryTable& table) {
  const Model& m = scene.model;
  const std::vector<std::string> names = trajectoryColumns(m, scene.constraints);
  // Columns in the writer's order: time, q (nq), v (nv), energy, residual, then per constraint.
  std::vector<int> qcol, vcol, lcol;
  for (int i = 0; i < m.nq; ++i) qcol.push_back(table.require(names[1 + i]));
  for (int i = 0; i < m.nv; ++i) vcol.push_back(table.require(names[1 + m.nq + i]));
  for (const std::string& n : names)
    if (n.rfind("lambda:", 0) == 0) lcol.push_back(table.require(n));
  // Contact modes and events (unilateral contacts; absent in older files).
  std::vector<int> closed_col(scene.constraints.size(), -1), event_col(scene.constraints.size(), -1);
  for (size_t c = 0; c < scene.constraints.size(); ++c) {
    closed_col[c] = table.find("closed:" + scene.constraints[c]->name());
    event_col[c] = table.find("event:" + scene.constraints[c]->name());
  }
  Data data(m);
  std::vector<RowBlock> blocks(scene.constraints.size());
  for (size_t c = 0; c < blocks.size(); ++c) scene.constraints[c]->reserve(m, blocks[c]);
  VecX q(m.nq), v(m.nv), lambda(lcol.size());
  std::vector<Frame> frames;
  for (const auto& row : table.rows) {
    for (int i = 0; i < m.nq; ++i) q[i] = row[qcol[i]];
    for (int i = 0; i < m.nv; ++i) v[i] = row[vcol[i]];
    for (size_t i = 0; i < lcol.size(); ++i) lambda[i] = row[lcol[i]];
    frames.push_back(frameAt(scene, data, blocks, row[0], q, v, lambda));
    for (size_t c = 0; c < scene.constraints.size(); ++c) {
      if (closed_col[c] >= 0) frames.back().closed[c] = row[closed_col[c]];
      if (event_col[c] >= 0 && row[event_col[c]] != 0)
        frames.back().events.emplace_back(static_cast<int>(c), static_cast<int>(row[event_col[c]]));
    }
  }
  return frames;
}

std::vector<Frame> initialFrame(const Scene& scene) {
  Simulator sim(scene.model, scene.constraints,
                makeSolver(formulationFromString(scene.settings.formulation), scene.model,
                           scene.constraints),
                IntegratorType::RK4);
  if (scene.tau.size() == scene.model.nv) {
    const VecX tau = scene.tau;
    sim.setJointForces([tau](double, const VecX&, const VecX&, VecX& out) { out = tau; });
  }
  sim.setState(0.0, scene.q0, scene.v0);
  Data data(scene.model);
  std::vector<RowBlock> blocks(scene.constraints.size());
  for (size_t c = 0; c < blocks.size(); ++c) scene.constraints[c]->reserve(scene.model, blocks[c]);
  return {frameAt(scene, data, blocks, 0.0, scene.q0, scene.v0, sim.lambda())};
}

/// The contacts that are one declaration's vertices (a sole's corners), so the
/// overlay lists the declaration once: "vertexGroups": [{name, first, count}],
/// contacts[first, first + count) (Scene::vertex_groups).
void writeVertexGroups(Json& j, const Scene& scene) {
  j.key("vertexGroups").open('[');
  for (const VertexGroup& g : scene.vertex_groups)
    j.open('{').key("name").str(g.name).key("first").num(g.first).key("count").num(g.count).close('}');
  j.close(']');
}

/// Height of the first world-fixed horizontal plane (the grid goes there), NaN if none.
double groundHeight(const Scene& scene) {
  for (const Support& s : scene.supports) {
    const Plane* plane = std::get_if<Plane>(&s.surface);
    if (!plane || s.body >= 0 || isMoving(s.motion)) continue;
    const SE3 X = supportState(s.motion, 0.0).pose;
    if ((X.R * plane->normal).z() > 1 - 1e-12) return X.apply(plane->point).z();
  }
  return std::nan("");
}

std::string pageJson(const Scene& scene, const std::vector<Frame>& frames) {
  Json j;
  j.open('{').key("title").str(std::filesystem::path(scene.source).filename().string());
  double size = 0;
  j.key("bodies").open('[');
  for (int b = 0; b < scene.model.nbodies; ++b) {
    bool moves = false;
    for (const Frame& f : frames)
      for (int k = 0; k < 3; ++k) moves |= f.poses[7 * b + k] != frames[0].poses[7 * b + k];
    j.open('{').key("name").str(scene.model.body_names[b]).key("moves").raw(moves ? "true" : "false");
    j.key("geometry").open('[');
    if (b < static_cast<int>(scene.geometry.size()))
      for (const Geometry& g : scene.geometry[b].visual) {
        if (g.type == GeometryType::Mesh && !g.mesh) continue;
        writeGeometry(j, g);
        size = std::max(size, reach(g));
      }
    j.close(']').close('}');
  }
  j.close(']').key("contacts").open('[');
  for (const auto& c : scene.constraints) j.open('{').key("name").str(c->name()).close('}');
  j.close(']');
  writeVertexGroups(j, scene);
  // Supports other than the ground (the grid stands for that one): planes, spheres, terrains.
  const double ground = groundHeight(scene);
  j.key("supports").open('[');
  for (const Support& s : scene.supports) {
    j.open('{').key("name").str(s.name).key("type");
    if (const Plane* p = std::get_if<Plane>(&s.surface)) {
      const SE3 X = supportState(s.motion, 0).pose;
      const bool is_ground = s.body < 0 && !isMoving(s.motion) &&
                             (X.R * p->normal).z() > 1 - 1e-12 && X.apply(p->point).z() == ground;
      j.str(is_ground ? "ground" : "plane").key("point").vec(p->point).key("normal").vec(p->normal);
    } else if (const SphereSurface* sp = std::get_if<SphereSurface>(&s.surface)) {
      j.str("sphere").key("centre").vec(sp->centre).key("radius").num(sp->radius);
      j.key("inside").raw(sp->side == SphereSurface::Side::Inside ? "true" : "false");
    } else {
      writeTerrain(j.str("terrain"), std::get<TerrainMesh>(s.surface));
    }
    j.close('}');
  }
  j.close(']').key("size").num(std::max(size, 1e-3)).key("ground").num(ground);
  j.key("times").open('[');
  for (const Frame& f : frames) j.num(f.t);
  j.close(']');
  // Contact events for the time line: [t, contact, kind name].
  j.key("events").open('[');
  for (const Frame& f : frames)
    for (const auto& [c, code] : f.events)
      j.open('[').num(f.t).num(c).str(toString(static_cast<ContactEventKind>(code - 1))).close(']');
  j.close(']');
  for (const auto member : {&Frame::poses, &Frame::points, &Frame::forces, &Frame::supports, &Frame::closed}) {
    j.key(member == &Frame::poses    ? "poses"
          : member == &Frame::points ? "points"
          : member == &Frame::forces ? "forces"
          : member == &Frame::closed ? "closed"
                                     : "supportPoses")
        .open('[');
    for (const Frame& f : frames) j.vec(f.*member);
    j.close(']');
  }
  return j.close('}').text();
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
  std::vector<Frame> frames;
  if (args.has("trajectory")) {
    const TrajectoryTable table = readTrajectory(args.text("trajectory"));
    matchJointLimits(scene, table);
    frames = framesFromTrajectory(scene, table);
  } else {
    frames = initialFrame(scene);
  }
  const std::string stem = std::filesystem::path(scene.source).stem().string();
  const std::string out = args.text("out", stem + ".html");
  refuseOverwritingInputs("out", out, scene,
                          args.has("trajectory") ? std::vector<std::string>{args.text("trajectory")}
                                                 : std::vector<std::string>{});
  std::ofstream page(out, std::ios::binary);
  if (!page) throw std::runtime_error("cannot write '" + out + "'");
  page << fill(viewer::pageTemplate(), stem, pageJson(scene, frames), viewer::script());
  if (!page.flush()) throw std::runtime_error("error writing '" + out + "'");
  std::cout << "page         " << out << " (" << frames.size() << " samples, t = " << frames.front().t
            << " … " << frames.back().t << " s)\n";
  return 0;
}

}  // namespace appell::cli
