// Writes the URDF of an N-trailer: a tractor pulling N trailers, every body on
// a knife-edge axle, each trailer hitched to the body in front of it.
//
// usage: example_make_ntrailer N [FILE]      (FILE: default standard output)
//   e.g. example_make_ntrailer 3 examples/ntrailer/ntrailer3.urdf
//
// The model (all lengths in m, masses in kg):
//  - tractor: floating base (no world link), origin at its axle's contact
//    point on the ground, x forward. A Chaplygin sleigh: knife edge at the
//    origin (blade along x), two frictionless sliding feet ahead at
//    (0.6, ±0.25, 0), centre of mass (0.3, 0, 0.1), 2 kg.
//  - hitch k (k = 1…N): a yaw joint (continuous, axis z) at 0.2 behind the
//    front body's axle and 0.1 above the ground, then a pitch joint
//    (continuous, axis y) through a massless link: a ball-like hitch that
//    leaves the trailer free to pitch, so each trailer's weight is shared by
//    its axle and its hitch and no normal row is redundant.
//  - trailer k: 1 kg, frame origin at its hitch, x along the drawbar; centre
//    of mass halfway to the axle; knife edge at (−L, 0, −0.1) with L = 0.8
//    (on the ground), blade along x.
// Rows: tractor 2 + 1 + 1, each trailer 2: 4 + 2N rows on nv = 6 + 2N, rank
// 4 + 2N: two degrees of freedom (the tractor's speed and turn rate) — the
// classical N-trailer is a kinematic car with 2 inputs.
//
// Initial state: at rest, the hitch angles alternating 0.4, −0.3, 0.2, −0.1,
// … (then ±0.1), and a constant forward push of 2 N on the tractor along its
// blade (an <effort> on the floating joint, body frame). Expected motion: the
// train accelerates forward and the trailers fall in line behind the tractor
// (the hitch angles decay with the distance travelled, like θ' = −sin θ / L
// for a trailer behind a straight-running hitch).
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

namespace {

constexpr double kDrawbar = 0.8;     // hitch to axle, L
constexpr double kHitchBack = 0.2;   // hitch behind the front body's axle
constexpr double kHitchHeight = 0.1; // hitch above the ground

double initialHitchAngle(int k) {
  static const double angles[] = {0.4, -0.3, 0.2, -0.1};
  return k <= 4 ? angles[k - 1] : (k % 2 ? 0.1 : -0.1);
}

std::string ntrailer(int n) {
  std::ostringstream o;
  o.precision(17);
  o << "<?xml version=\"1.0\"?>\n"
    << "<!-- An N-trailer with N = " << n
    << ", written by examples/make_ntrailer.cpp (do not edit: regenerate with\n"
    << "     `example_make_ntrailer " << n << " FILE`).\n"
    << "     A tractor (a Chaplygin sleigh: knife-edge axle at its origin, two\n"
    << "     frictionless sliding feet ahead, 2 kg) pulls " << n
    << " trailers (1 kg each, drawbar\n"
    << "     L = " << kDrawbar << " m from hitch to knife-edge axle). Each hitch is a yaw joint\n"
    << "     (axis z) and a pitch joint (axis y) through a massless link, " << kHitchBack
    << " m behind\n"
    << "     the front body's axle and " << kHitchHeight << " m above the ground.\n"
    << "     Rows: 4 + 2N = " << 4 + 2 * n << " on nv = 6 + 2N = " << 6 + 2 * n
    << ", all independent: 2 degrees of\n"
    << "     freedom (tractor speed and turn rate), as for the kinematic N-trailer.\n"
    << "     Start: at rest, hitch angles alternating in sign, a constant forward push\n"
    << "     of 2 N on the tractor along its blade. Expected motion: the train speeds\n"
    << "     up and the trailers fall in line behind the tractor. -->\n"
    << "<robot name=\"ntrailer" << n << "\">\n"
    << "  <link name=\"tractor\">\n"
    << "    <inertial>\n"
    << "      <origin xyz=\"0.3 0 0.1\" rpy=\"0 0 0\"/>\n"
    << "      <mass value=\"2\"/>\n"
    << "      <inertia ixx=\"0.05\" ixy=\"0\" ixz=\"0\" iyy=\"0.12\" iyz=\"0\" izz=\"0.15\"/>\n"
    << "    </inertial>\n"
    << "    <visual>\n"
    << "      <origin xyz=\"0.3 0 0.1\" rpy=\"0 0 0\"/>\n"
    << "      <geometry><box size=\"0.9 0.5 0.1\"/></geometry>\n"
    << "    </visual>\n"
    << "  </link>\n";
  // Trailer inertia: a 0.8 x 0.4 x 0.1 box of 1 kg about its centre.
  const double m = 1.0, a = kDrawbar, b = 0.4, c = 0.1;
  const double ixx = m / 12 * (b * b + c * c), iyy = m / 12 * (a * a + c * c),
               izz = m / 12 * (a * a + b * b);
  for (int k = 1; k <= n; ++k) {
    const std::string front = k == 1 ? "tractor" : "trailer" + std::to_string(k - 1);
    const double hx = k == 1 ? -kHitchBack : -kDrawbar - kHitchBack;
    const double hz = k == 1 ? kHitchHeight : 0.0;  // trailer frames sit at hitch height
    o << "  <link name=\"hitch" << k << "\"/>\n"
      << "  <link name=\"trailer" << k << "\">\n"
      << "    <inertial>\n"
      << "      <origin xyz=\"" << -kDrawbar / 2 << " 0 0\" rpy=\"0 0 0\"/>\n"
      << "      <mass value=\"" << m << "\"/>\n"
      << "      <inertia ixx=\"" << ixx << "\" ixy=\"0\" ixz=\"0\" iyy=\"" << iyy
      << "\" iyz=\"0\" izz=\"" << izz << "\"/>\n"
      << "    </inertial>\n"
      << "    <visual>\n"
      << "      <origin xyz=\"" << -kDrawbar / 2 << " 0 0\" rpy=\"0 0 0\"/>\n"
      << "      <geometry><box size=\"" << a << " " << b << " " << c << "\"/></geometry>\n"
      << "    </visual>\n"
      << "  </link>\n"
      << "  <joint name=\"hitch" << k << "_yaw\" type=\"continuous\">\n"
      << "    <parent link=\"" << front << "\"/>\n"
      << "    <child link=\"hitch" << k << "\"/>\n"
      << "    <origin xyz=\"" << hx << " 0 " << hz << "\" rpy=\"0 0 0\"/>\n"
      << "    <axis xyz=\"0 0 1\"/>\n"
      << "  </joint>\n"
      << "  <joint name=\"hitch" << k << "_pitch\" type=\"continuous\">\n"
      << "    <parent link=\"hitch" << k << "\"/>\n"
      << "    <child link=\"trailer" << k << "\"/>\n"
      << "    <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>\n"
      << "    <axis xyz=\"0 1 0\"/>\n"
      << "  </joint>\n";
  }
  o << "  <appell>\n"
    << "    <gravity xyz=\"0 0 -9.81\"/>\n"
    << "    <support name=\"ground\" type=\"plane\" normal=\"0 0 1\" offset=\"0\"/>\n"
    << "    <contact name=\"tractor_axle\" link=\"tractor\" kind=\"knife_edge\" support=\"ground\""
       " point=\"0 0 0\" direction=\"1 0 0\"/>\n"
    << "    <contact name=\"tractor_foot_left\" link=\"tractor\" kind=\"sliding\" support=\"ground\""
       " point=\"0.6 0.25 0\"/>\n"
    << "    <contact name=\"tractor_foot_right\" link=\"tractor\" kind=\"sliding\" support=\"ground\""
       " point=\"0.6 -0.25 0\"/>\n";
  for (int k = 1; k <= n; ++k)
    o << "    <contact name=\"trailer" << k << "_axle\" link=\"trailer" << k
      << "\" kind=\"knife_edge\" support=\"ground\" point=\"" << -kDrawbar << " 0 "
      << -kHitchHeight << "\" direction=\"1 0 0\"/>\n";
  o << "    <initial>\n"
    << "      <joint name=\"root_joint\" xyz=\"0 0 0\" rpy=\"0 0 0\"/>\n";
  for (int k = 1; k <= n; ++k)
    o << "      <joint name=\"hitch" << k << "_yaw\" position=\"" << initialHitchAngle(k) << "\"/>\n";
  o << "    </initial>\n"
    << "    <!-- body-frame torque, then force: a push along the tractor's blade -->\n"
    << "    <effort joint=\"root_joint\" value=\"0 0 0  2 0 0\"/>\n"
    << "    <simulation integrator=\"dopri5\" dt=\"0.01\" tol=\"1e-9\" duration=\"6\""
       " formulation=\"tree\"/>\n"
    << "  </appell>\n"
    << "</robot>\n";
  return o.str();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3) {
    std::cerr << "usage: example_make_ntrailer N [FILE]\n";
    return 2;
  }
  char* end = nullptr;
  const long n = std::strtol(argv[1], &end, 10);
  if (*end != '\0' || n < 1 || n > 1000) {
    std::cerr << "make_ntrailer: N must be an integer from 1 to 1000, got '" << argv[1] << "'\n";
    return 2;
  }
  const std::string urdf = ntrailer(static_cast<int>(n));
  if (argc == 3) {
    std::ofstream out(argv[2]);
    if (!(out << urdf)) {
      std::cerr << "make_ntrailer: cannot write '" << argv[2] << "'\n";
      return 1;
    }
  } else {
    std::cout << urdf;
  }
  return 0;
}
