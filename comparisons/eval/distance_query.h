// `rbx distance`: every backend's distance query on every pair of a scene at the t = 0 poses,
// each against the `exact` oracle (docs/distance.md). Typed rows; distance_json writes them.
#pragma once

#include <string>
#include <vector>

#include "comparisons/eval/json_io.h"
#include "comparisons/eval/stated_check.h"
#include "comparisons/eval/timing.h"
#include "comparisons/scene/scene.h"
#include "reference/backend.h"

namespace rbx {

/// A distance answer's errors against the oracle's are relative to the true distance, floored at
/// kDistanceFloorRel of the pair's extent (how far its farthest vertex is from the world origin):
/// every answer, the oracle's own included, carries round-off of the world coordinates, a few
/// 1e-16 of their magnitude, which over a gap of 1e-8 of it is 1e-7 relative, a tenth of the
/// disagreement threshold. (Of the smaller body's size it is not: a body a thousandth the size of
/// its neighbour, a metre from the origin, carries the round-off of metres.) Over
/// kDistanceDisagreeRel the answer disagrees: the threshold rbx explore marks distance samples
/// by. Over kDistanceDeviateRel, and beyond kDistanceRoundOffRel of the extent in absolute terms
/// (ten times the round-off measured), it deviates.
constexpr double kDistanceDisagreeRel = 1e-6;
constexpr double kDistanceDeviateRel = 1e-9;
constexpr double kDistanceFloorRel = 1e-8;
constexpr double kDistanceRoundOffRel = 1e-14;

/// How one backend's answer on one pair stands against the oracle's.
struct DistanceVerdict {
  bool comparable = false;    // both answered with a distance (status ok, neither overlapping)
  double distance_err = 0.0;  // |d - d*| / scale
  /// How far the witness points are from being a closest pair, over the same scale: the larger
  /// of A's point's distance from A, B's point's from B, and | |p_a - p_b| - d* |. Closest
  /// points need not be unique (parallel faces): any pair on the bodies at the true distance is
  /// right, so they are checked against the bodies, not against the oracle's pair.
  double witness_err = 0.0;
  double scale = 0.0;  // m: max(d*, kDistanceFloorRel x the pair's extent)
  std::string mark;    // "" | "deviates" | "disagrees"
  std::string why;     // the mark's reason, one line
};

/// Backend `b`'s distance query on (a, bb): `unsupported` without one; a library's call runs
/// isolated under its deadline (reference/isolate.h). `cold_s`, when given, gets its run time.
DistanceResult run_distance(const Backend& b, const RigidBody& a, const RigidBody& bb,
                            double* cold_s = nullptr);

/// The verdict on `answer` for the pair (a, b) whose exact answer is `truth`.
DistanceVerdict judge_distance(const DistanceResult& answer, const DistanceResult& truth,
                               const RigidBody& a, const RigidBody& b);

/// One backend's answer on one pair.
struct DistanceRow {
  std::string backend;
  DistanceResult result;
  DistanceVerdict verdict;
  Timing timing;  // the median over interleaved rounds, the cold call apart (rounds 0: untimed)
};

/// One pair of bodies (not both static).
struct DistancePair {
  std::string a, b;
  DistanceResult truth;  // the oracle's answer
  std::vector<DistanceRow> rows;
};

/// Every pair's queries.
struct DistanceComparison {
  std::string scene, file;
  std::vector<DistancePair> pairs;
  StatedCheck expect;  // the first pair against the scene's [expect.distance]
};

/// Queries every pair of bodies (not both static) with every backend in `names` (a backend
/// without a distance query answers `unsupported`) and the oracle; a library's call runs
/// isolated under its deadline. Every query is timed (at least `budget_s` each, interleaved;
/// 0: untimed), its cold first call apart.
DistanceComparison compare_distances(const Scene& scene, const std::vector<std::string>& names,
                                     double budget_s = 0.01);

/// The document `rbx distance --json` writes (docs/contract.md, "rbx distance").
Json distance_json(const DistanceComparison& c);

}  // namespace rbx
