// Writes the examples' meshes, then reads each back through appell::loadMesh
// (assimp) as a check:
//   diff_drive/meshes/wheel.stl  the differential drive's wheel, binary STL
//   diff_drive/meshes/wheel.dae  the same triangles, Collada 1.4.1
//   biped/meshes/sole.stl        the mesh-footed biped's sole, binary STL
//
// The wheel is a solid of revolution about the y axis (the axle, as in the
// diff_drive URDF: no visual rotation needed), radius 0.1 m, width 0.04 m: a
// tyre that is the outer half of a torus (tube radius 0.02 m, centre circle
// 0.08 m) closed by two flat side discs. Its profile in the (r, y) half-plane
// is revolved in `kSegments` steps. The solid is convex, so each triangle is
// oriented with its normal pointing away from the wheel centre.
//
// The sole is what a CAD exporter writes for a foot: a flat-bottomed prism,
// 0.22 × 0.12 m in plan with 0.03 m corner fillets (kFilletSegments facets
// each), 0.04 m thick and centred on its origin like the box sole of
// examples/biped, in single precision as binary STL stores it — so the
// fillets' coordinates carry float rounding.
//
// usage: example_make_meshes [EXAMPLES_DIR]   (default examples, relative to
//        the current folder: run it from the repository root)
#include <appell/urdf.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

namespace {

using P3 = std::array<double, 3>;
using Tri = std::array<int, 3>;

constexpr double kRadius = 0.1;      // outer radius of the tyre
constexpr double kTube = 0.02;       // tyre tube radius = half the width
constexpr int kSegments = 64;        // around the axle
constexpr int kArc = 16;             // intervals along the tyre's half circle
constexpr double kSoleLength = 0.22, kSoleWidth = 0.12, kSoleThickness = 0.04;
constexpr double kFillet = 0.03;     // the sole's corner radius in plan
constexpr int kFilletSegments = 6;   // facets per corner fillet

struct Mesh {
  std::vector<P3> v;
  std::vector<Tri> t;
};

P3 sub(const P3& a, const P3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
P3 cross(const P3& a, const P3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const P3& a, const P3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Adds a triangle, flipped if needed so its normal points away from the origin
// (the wheel's or the sole's centre): valid because both solids are convex.
void addOutward(Mesh& m, int a, int b, int c) {
  const P3 n = cross(sub(m.v[b], m.v[a]), sub(m.v[c], m.v[a]));
  const P3 g = {(m.v[a][0] + m.v[b][0] + m.v[c][0]) / 3, (m.v[a][1] + m.v[b][1] + m.v[c][1]) / 3,
                (m.v[a][2] + m.v[b][2] + m.v[c][2]) / 3};
  if (dot(n, g) >= 0)
    m.t.push_back({a, b, c});
  else
    m.t.push_back({a, c, b});
}

Mesh wheel() {
  // Profile (r, y): axis point, tyre half circle, axis point.
  std::vector<std::array<double, 2>> profile;
  for (int k = 0; k <= kArc; ++k) {
    const double beta = -std::numbers::pi / 2 + std::numbers::pi * k / kArc;
    profile.push_back({kRadius - kTube + kTube * std::cos(beta), kTube * std::sin(beta)});
  }
  Mesh m;
  const int left_pole = 0;
  m.v.push_back({0, -kTube, 0});
  const int first_ring = 1;
  for (const auto& [r, y] : profile)
    for (int s = 0; s < kSegments; ++s) {
      const double th = 2 * std::numbers::pi * s / kSegments;
      m.v.push_back({r * std::cos(th), y, r * std::sin(th)});
    }
  const int right_pole = static_cast<int>(m.v.size());
  m.v.push_back({0, kTube, 0});
  auto ring = [&](int k, int s) { return first_ring + k * kSegments + (s % kSegments); };
  const int rings = static_cast<int>(profile.size());
  for (int s = 0; s < kSegments; ++s) {
    addOutward(m, left_pole, ring(0, s), ring(0, s + 1));
    for (int k = 0; k + 1 < rings; ++k) {
      addOutward(m, ring(k, s), ring(k + 1, s), ring(k + 1, s + 1));
      addOutward(m, ring(k, s), ring(k + 1, s + 1), ring(k, s + 1));
    }
    addOutward(m, right_pole, ring(rings - 1, s + 1), ring(rings - 1, s));
  }
  return m;
}

Mesh sole() {
  // The outline in plan, counter-clockwise: four quarter circles.
  std::vector<std::array<double, 2>> outline;
  const double cx = kSoleLength / 2 - kFillet, cy = kSoleWidth / 2 - kFillet;
  const double corner[4][2] = {{cx, cy}, {-cx, cy}, {-cx, -cy}, {cx, -cy}};
  for (int c = 0; c < 4; ++c)
    for (int k = 0; k <= kFilletSegments; ++k) {
      const double a = std::numbers::pi / 2 * (c + static_cast<double>(k) / kFilletSegments);
      outline.push_back({corner[c][0] + kFillet * std::cos(a), corner[c][1] + kFillet * std::sin(a)});
    }
  const int n = static_cast<int>(outline.size());
  Mesh m;
  for (const double z : {-kSoleThickness / 2, kSoleThickness / 2})
    for (const auto& [x, y] : outline) m.v.push_back({x, y, z});
  for (int i = 0; i < n; ++i) {  // the side wall
    const int j = (i + 1) % n;
    addOutward(m, i, j, n + j);
    addOutward(m, i, n + j, n + i);
  }
  for (int i = 1; i + 1 < n; ++i) {  // bottom and top: fans of the convex outline
    addOutward(m, 0, i, i + 1);
    addOutward(m, n, n + i, n + i + 1);
  }
  return m;
}

void writeStl(const Mesh& m, const std::string& path, const char* what) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw std::runtime_error("cannot write " + path);
  char header[80] = {};
  std::snprintf(header, sizeof header, "appell %s (examples/make_meshes.cpp)", what);
  out.write(header, 80);
  const std::uint32_t n = static_cast<std::uint32_t>(m.t.size());
  out.write(reinterpret_cast<const char*>(&n), 4);  // STL is little-endian, as is x86
  for (const Tri& t : m.t) {
    P3 nrm = cross(sub(m.v[t[1]], m.v[t[0]]), sub(m.v[t[2]], m.v[t[0]]));
    const double len = std::sqrt(dot(nrm, nrm));
    float f[12];
    for (int i = 0; i < 3; ++i) f[i] = static_cast<float>(len > 0 ? nrm[i] / len : 0);
    for (int c = 0; c < 3; ++c)
      for (int i = 0; i < 3; ++i) f[3 + 3 * c + i] = static_cast<float>(m.v[t[c]][i]);
    out.write(reinterpret_cast<const char*>(f), sizeof f);
    const std::uint16_t attr = 0;
    out.write(reinterpret_cast<const char*>(&attr), 2);
  }
}

void writeDae(const Mesh& m, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  out << R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset>
    <contributor><authoring_tool>appell examples/make_meshes.cpp</authoring_tool></contributor>
    <unit name="meter" meter="1"/>
    <up_axis>Z_UP</up_axis>
  </asset>
  <library_geometries>
    <geometry id="wheel-mesh" name="wheel">
      <mesh>
        <source id="wheel-positions">
          <float_array id="wheel-positions-array" count=")"
      << 3 * m.v.size() << "\">";
  char buf[64];
  for (const P3& p : m.v) {
    std::snprintf(buf, sizeof buf, "%.6g %.6g %.6g ", p[0], p[1], p[2]);
    out << buf;
  }
  out << R"(</float_array>
          <technique_common>
            <accessor source="#wheel-positions-array" count=")"
      << m.v.size() << R"(" stride="3">
              <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
            </accessor>
          </technique_common>
        </source>
        <vertices id="wheel-vertices"><input semantic="POSITION" source="#wheel-positions"/></vertices>
        <triangles count=")"
      << m.t.size() << R"(">
          <input semantic="VERTEX" source="#wheel-vertices" offset="0"/>
          <p>)";
  for (const Tri& t : m.t) out << t[0] << ' ' << t[1] << ' ' << t[2] << ' ';
  out << R"(</p>
        </triangles>
      </mesh>
    </geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="Scene" name="Scene">
      <node id="wheel" name="wheel" type="NODE">
        <instance_geometry url="#wheel-mesh"/>
      </node>
    </visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#Scene"/></scene>
</COLLADA>
)";
}

// Reads a written mesh back the way scenes load it and prints its extent.
void report(const std::string& path) {
  const appell::TriangleMesh t = appell::loadMesh(path);
  appell::Vec3 lo = t.vertices.front(), hi = lo;
  for (const appell::Vec3& p : t.vertices) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  std::cout << path << ": " << t.vertices.size() << " vertices, " << t.triangles.size()
            << " triangles, extent " << (hi - lo).transpose() << " m, "
            << std::filesystem::file_size(path) << " bytes\n";
}

}  // namespace

int main(int argc, char** argv) {
  const std::filesystem::path root = argc > 1 ? argv[1] : "examples";
  try {
    const std::filesystem::path wheels = root / "diff_drive" / "meshes", soles = root / "biped" / "meshes";
    std::filesystem::create_directories(wheels);
    std::filesystem::create_directories(soles);
    char what[64];
    std::snprintf(what, sizeof what, "wheel r=%.3f w=%.3f", kRadius, 2 * kTube);
    const Mesh w = wheel();
    writeStl(w, (wheels / "wheel.stl").string(), what);
    writeDae(w, (wheels / "wheel.dae").string());
    std::snprintf(what, sizeof what, "sole %.2fx%.2fx%.2f fillet %.2f", kSoleLength, kSoleWidth,
                  kSoleThickness, kFillet);
    writeStl(sole(), (soles / "sole.stl").string(), what);
    for (const auto& path : {wheels / "wheel.stl", wheels / "wheel.dae", soles / "sole.stl"}) report(path.string());
  } catch (const std::exception& e) {
    std::cerr << "make_meshes: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
