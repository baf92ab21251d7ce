// The one writer of the replay page's data (replay.hpp): a JSON object in
// the order the page reads it.
#include <appell/replay.hpp>

#include <appell/supports.hpp>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace appell {

namespace {

/// A JSON text built in order: numbers in the shortest form that reads back
/// to the same double, so the page shows the CSV's values.
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

}  // namespace

std::string replayJson(const Scene& scene, const std::vector<ReplayFrame>& frames) {
  Json j;
  j.open('{').key("title").str(std::filesystem::path(scene.source).filename().string());
  double size = 0;
  j.key("bodies").open('[');
  for (int b = 0; b < scene.model.nbodies; ++b) {
    bool moves = false;
    for (const ReplayFrame& f : frames)
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
  for (const ReplayFrame& f : frames) j.num(f.t);
  j.close(']');
  // Contact events for the time line: [t, contact, kind name].
  j.key("events").open('[');
  for (const ReplayFrame& f : frames)
    for (const auto& [c, code] : f.events)
      j.open('[').num(f.t).num(c).str(toString(static_cast<ContactEventKind>(code - 1))).close(']');
  j.close(']');
  for (const auto member : {&ReplayFrame::poses, &ReplayFrame::points, &ReplayFrame::forces, &ReplayFrame::supports, &ReplayFrame::closed}) {
    j.key(member == &ReplayFrame::poses    ? "poses"
          : member == &ReplayFrame::points ? "points"
          : member == &ReplayFrame::forces ? "forces"
          : member == &ReplayFrame::closed ? "closed"
                                     : "supportPoses")
        .open('[');
    for (const ReplayFrame& f : frames) j.vec(f.*member);
    j.close(']');
  }
  return j.close('}').text();
}

}  // namespace appell
