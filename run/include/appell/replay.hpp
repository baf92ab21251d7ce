// The replay data `appell view` embeds in its page: for every sample of a
// trajectory (or the initial state alone) the body poses from forward
// kinematics on the sample's q, each constraint's contact point and reaction
// force f = Σ_r λ_r d_r (λ_r from the CSV, d_r the linear part of row r's
// world covector W_r = [p × d_r; d_r]: the row constrains d_r · v_p, so λ_r
// is the force along d_r — constraint.hpp), the supports' frames, the
// contacts' modes and events. replayJson() is the one writer of the page's
// data (its schema: docs/architecture.md, "The replay data"; tested against
// the keys viewer/src/main.js reads).
#pragma once

#include <appell/scene.hpp>
#include <appell/trajectory_reader.hpp>

#include <string>
#include <utility>
#include <vector>

namespace appell {

/// One sample of what the page shows.
struct ReplayFrame {
  double t = 0;
  std::vector<double> poses;     ///< 7 per body: x, y, z, qx, qy, qz, qw (world)
  std::vector<double> points;    ///< 3 per constraint: its contact point (world)
  std::vector<double> forces;    ///< 3 per constraint: its reaction force (world)
  std::vector<double> supports;  ///< 7 per support: its frame in the world
  std::vector<double> closed;    ///< 1 per constraint: 1 closed, 0 open (lifted off)
  std::vector<std::pair<int, int>> events;  ///< (constraint, 1 + ContactEventKind) at t
};

/// The frames of a trajectory `appell run --out` wrote for this scene (its
/// q, v and λ columns required by name; closed:/event: columns when present).
std::vector<ReplayFrame> replayFrames(const Scene& scene, const TrajectoryTable& table);

/// The initial state alone, with λ from the dynamics solved there.
std::vector<ReplayFrame> initialReplayFrame(const Scene& scene);

/// The page's data as one JSON object: title, bodies (name, moves, visual
/// geometry), contacts, vertexGroups, supports, size, ground, times, events,
/// and per frame poses, points, forces, closed, supportPoses. Numbers in the
/// shortest form that reads back to the same double (non-finite: null);
/// '<' escaped, so the text is safe inside the page's <script>.
std::string replayJson(const Scene& scene, const std::vector<ReplayFrame>& frames);

}  // namespace appell
