// Ensembles (`rbx ensemble`): many copies of one scene, each moving body nudged by a tiny random
// amount, run through every dynamics backend, to measure how far the outcome spreads, how many
// contact sequences the copies take, and whether the outcomes split into clusters. With the step
// test, the same copies at a ten times smaller step tell the physics' sensitivity (a spread that
// stays) from the engine's (a spread that shrinks). Method and its reasons: docs/ensemble.md.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "comparisons/eval/harness.h"
#include "comparisons/eval/json_io.h"
#include "comparisons/eval/parallel.h"
#include "comparisons/scene/scene.h"

namespace rbx {

/// The standard deviations of the independent Gaussian nudges given to every component of each
/// moving body's state (the `--perturb KEY=SCALE` keys are the field names).
struct Nudge {
  double position = 1e-6;          // m, of the body's position
  double orientation = 1e-6;       // rad, of each component of a small rotation vector
  double velocity = 1e-6;          // m/s
  double angular_velocity = 1e-6;  // rad/s
};

/// What an ensemble runs.
struct EnsembleSettings {
  long count = 50;         // copies
  uint64_t seed = 1;       // copy k of seed s depends on (s, k) only
  Nudge nudge;             // nudge scales
  bool step_test = false;  // also run every copy at a ten times smaller step
};

/// Copy `index` of `scene`, every moving body nudged: a function of (seed, index) alone.
Scene nudged_copy(const Scene& scene, const Nudge& nudge, uint64_t seed, uint64_t index);

/// How far a set of copies' states spread, the largest over the moving bodies. Each spread is
/// the root mean square distance of the copies from their mean (orientation: the angle from
/// their mean orientation); each range is the widest 5-95 % range of one coordinate (for the
/// orientation, of that angle).
struct StateSpread {
  double position = 0.0;                // m
  double orientation = 0.0;             // rad
  double velocity = 0.0;                // m/s
  double angular_velocity = 0.0;        // rad/s
  double position_range = 0.0;          // m
  double orientation_range = 0.0;       // rad
  double velocity_range = 0.0;          // m/s
  double angular_velocity_range = 0.0;  // rad/s
};

/// The states of the copies of one run: per copy, every body's state in scene order.
using CopyStates = std::vector<std::vector<BodyFinal>>;

/// The spread of the moving bodies (is_static false in `scene`) over `copies`; `only` >= 0: of
/// that body alone.
StateSpread state_spread(const Scene& scene, const CopyStates& copies, int only = -1);

/// The number of clusters among the copies' final positions (every moving body's, one vector
/// per copy): single linkage, copies joined when closer than five times the median distance of
/// a copy to its nearest neighbour; a group counts as a cluster when it holds at least a tenth
/// of the copies (and at least two), the rest are outliers.
int cluster_count(const Scene& scene, const CopyStates& copies);

/// One backend's ensemble.
struct BackendEnsemble {
  std::string backend;
  long runs = 0;                        // copies that ran to the end
  long failed = 0;                      // copies that ended in error or timeout
  std::string first_failure;            // the first failed copy's message
  StateSpread spread;                   // of the final states
  double amplification = 0.0;           // final position spread / input position spread
  double velocity_amplification = 0.0;  // final velocity spread / input velocity spread
  // Distinct contact sequences, most frequent first (ties: the sequence text): which pairs
  // touch in which order, with the feature each backend names, and how many copies took each.
  std::vector<std::pair<std::string, long>> sequences;
  int clusters = 0;  // cluster_count of the final positions
  // The copies' final positions of the moving body whose position spreads most (m, world).
  std::string scatter_body;
  std::vector<Vec3> scatter;
  // The step test (EnsembleSettings::step_test): the same copies at dt / 10.
  bool step_tested = false;
  StateSpread fine_spread;
  double step_ratio = 0.0;  // fine position spread / position spread
  std::string verdict;      // "physics" (ratio in [0.5, 2]: the spread stays) | "engine" | "none"
};

/// A whole ensemble.
struct EnsembleResult {
  std::string scene, file;
  EnsembleSettings settings;
  double dt = 0.0;        // s, the scene's step
  double duration = 0.0;  // s, how long each copy ran
  StateSpread input;      // of the nudged initial states
  std::vector<BackendEnsemble> backends;
};

/// Runs `settings.count` nudged copies of `scene` through each backend named (each run isolated
/// as everywhere, spread over the ranks and threads of `par`); the result is the same for any
/// split. Filled on rank 0 only.
EnsembleResult run_ensemble(const Scene& scene, const std::vector<std::string>& backends,
                            const EnsembleSettings& settings, const ParallelRun& par);

/// The same ensemble with every nudge scale multiplied by each of `factors` (no step test): how
/// the spread grows with the nudge.
std::vector<EnsembleResult> scaled_ensembles(const Scene& scene,
                                             const std::vector<std::string>& backends,
                                             const EnsembleSettings& settings,
                                             const std::vector<double>& factors,
                                             const ParallelRun& par);

/// The ensemble as JSON (docs/contract.md, `rbx ensemble --json`); `sizes`, when given, adds
/// `nudge_sizes`: each scaled ensemble's input spread and every backend's position spread.
Json ensemble_json(const EnsembleResult& r, const std::vector<EnsembleResult>& sizes = {});

/// A scene as its [ensemble] table runs it (nothing changes without one): the table's count
/// (unless `keep_count`), its step test (added to the one `settings` asks for) and its duration
/// (on the scene).
void apply_ensemble_table(Scene& scene, EnsembleSettings& settings, bool keep_count);

/// The report's ensembles (its Predictability section): every scene with an [ensemble] table
/// runs its copies (the table's count, step test and duration, the default nudges and seed) through
/// the dynamics backends it runs (`backends`: --backends, "" for the scene's own), and its
/// evaluation gets the result as `ensemble` (ensemble_json). Collective over the ranks of `par`;
/// `evs` is filled on rank 0.
void run_scene_ensembles(const std::vector<Scene>& scenes, const std::string& backends,
                         std::vector<SceneEvaluation>& evs, const ParallelRun& par);

/// The contact sequence of a run's events: each distinct (pair, feature) in the order of its
/// first event, as "A-B:face > B-C:edge" ("none" without events).
std::string contact_sequence(const std::vector<CollisionEvent>& events);

}  // namespace rbx
