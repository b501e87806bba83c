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

/// Key-frame tolerance: a frame is dropped when interpolating its neighbours (positions linearly,
/// quaternions by normalised lerp, as the replay page does) reproduces every moving body within
/// kKeyFrameTolerance of the trajectory's extent (largest |coordinate|) and within
/// kKeyFrameTolerance in each quaternion component: 0.1 pixel of a 1000-pixel view.
constexpr double kKeyFrameTolerance = 1e-4;

/// A run's samples thinned to at most `max_frames` evenly spaced frames, the first and the last
/// kept, then to the key frames (see kKeyFrameTolerance): free flight between two events needs
/// two frames, not a hundred. {"time": [s...], "bodies": {NAME: [[x, y, z, qw, qx, qy, qz] per
/// frame]}}. Positions are the centres of mass (m, world), on a decimal grid of 1e-4..1e-5 of the
/// extent; quaternions body to world, on a grid of 1e-5. Static bodies are left out (their pose
/// is the scene's). Empty object when there are no samples.
Json trajectory_json(const std::vector<StateSample>& samples, const std::vector<RigidBody>& inputs,
                     size_t max_frames);

/// Events kept per backend in results.json: a resting stack reports a contact every step
/// (16 000 for Bullet), which made results.json 27.8 MB; the count is kept as `contacts_total`.
/// The first 10 show how each backend's contacts begin (20 outgrew the file's budget once the
/// resting family came); `rbx run SCENE --json` writes every event.
constexpr size_t kResultsMaxEvents = 10;

/// The mass properties a body entry may carry (bodies.NAME.*, docs/contract.md).
inline constexpr const char* kMassProperties[] = {"mass", "static", "center_of_mass", "inertia"};

/// A scene's result object for results.json, the report's data, kept within its size budget
/// without losing a number:
/// - `metrics` and `error_vs_runtime` are left out: metrics.csv and error_vs_runtime.csv hold every
/// one of them;
/// - the scene's `bodies` holds each body's mass properties as most backends report them (ties:
///   the first backend's), and a backend's body entry keeps only the properties that differ
///   from them (its `final` state always);
/// - each backend's `contacts` are cut to the first kResultsMaxEvents (with `contacts_total`,
///   and `contacts_truncated` when cut).
Json results_scene_json(const Json& scene_result);

}  // namespace rbx
