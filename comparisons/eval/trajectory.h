// Sampled trajectories for results.json and the 3-D replay (`rbx view`): a run's state samples
// thinned to a frame budget and rounded, so that a page and the results stay small.
#pragma once

#include <vector>

#include "comparisons/eval/json_io.h"
#include "reference/backend.h"

namespace rbx {

/// Numbers per body and frame budget of one backend's trajectory: at most kMaxFrames frames, and
/// no more than kFrameNumberBudget numbers (7 per moving body and frame) per backend, at least 2
/// frames. 100 frames replay a 1 s impact at 10 ms resolution; 10^4 numbers of ~8 characters
/// keep a backend under 100 kB, so a page of 8 backends stays under 2 MB with three.js inlined.
constexpr size_t kMaxFrames = 100;
constexpr size_t kFrameNumberBudget = 10000;

/// The frame count for `moving_bodies` bodies: min(kMaxFrames, budget / (7 bodies)), at least 2.
size_t frame_budget(size_t moving_bodies);

/// Rounds to 5 significant digits (a replay needs no more; it keeps the JSON short).
double round_sig5(double x);

/// A run's samples thinned to at most `max_frames` evenly spaced frames, the first and the last
/// kept: {"time": [s...], "bodies": {NAME: [[x, y, z, qw, qx, qy, qz] per frame]}}. Positions
/// are the centres of mass (m, world); quaternions body to world. Static bodies are left out
/// (their pose is the scene's). Empty object when there are no samples.
Json trajectory_json(const std::vector<StateSample>& samples, const std::vector<RigidBody>& inputs,
                     size_t max_frames);

/// Events kept per backend in results.json: a resting stack reports a contact every step
/// (16 000 for Bullet), which made results.json 27.8 MB; the count is kept as `contacts_total`.
constexpr size_t kResultsMaxEvents = 100;

/// A scene's result object for results.json: each backend's `contacts` cut to the first
/// kResultsMaxEvents (with `contacts_total`, and `contacts_truncated` when cut).
Json results_scene_json(const Json& scene_result);

}  // namespace rbx
