// What a replay page draws of a scene's evaluation, typed: each backend's sampled trajectory and
// its first events, read once from the scene's result (the trajectory check's "trajectory" and
// "contacts"), so that the page (comparisons/output/view_page.h) renders fields, not keys.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "comparisons/eval/json_io.h"

namespace rbx {

/// One body's pose at one frame: the centre of mass x, y, z (m, world), then the orientation's
/// quaternion w, x, y, z (body to world).
using ReplayPose = std::array<double, 7>;

/// One moving body's poses, a pose per frame of its run (static bodies stay at the scene's).
struct ReplayTrack {
  std::string body;
  std::vector<ReplayPose> poses;
};

/// A contact a run reported: the pair, when, where, along which normal (from B toward A), how
/// deep. A field the result left null (a non-finite number) reads as NaN.
struct ReplayEvent {
  double time = 0.0;  // s; 0 for a contact query
  std::string body_a, body_b;
  Vec3 point = Vec3::Zero(), normal = Vec3::Zero();
  double depth = 0.0;
};

/// A sampled motion: the frame times (s) and every moving body's track.
struct ReplayMotion {
  std::vector<double> time;
  std::vector<ReplayTrack> tracks;
};

/// One backend's run as the page draws it.
struct ReplayRun {
  std::string backend, status, message;
  ReplayMotion motion;              // empty where the run recorded no trajectory
  std::vector<ReplayEvent> events;  // the first `max_events` (read_replay)
  size_t events_total = 0;          // every event the result listed
};

/// A scene's runs, in the result's order, and a measured motion drawn faintly beside them (a
/// measured toss's; read_replay leaves it empty).
struct Replay {
  std::vector<ReplayRun> runs;
  std::optional<ReplayMotion> ghost;
  std::string ghost_label;  // what the ghost is ("the measured cube (motion capture)")

  /// The run of `backend`; nullptr when it did not run.
  const ReplayRun* run_of(const std::string& backend) const;
};

/// The replay of a scene's result object (SceneEvaluation::json), keeping each run's first
/// `max_events` events. A result with no "backends" gives no runs.
Replay read_replay(const Json& scene_result, size_t max_events);

}  // namespace rbx
