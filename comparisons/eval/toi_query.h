// `rbx toi`: every backend's time-of-impact query on every pair of a scene, the bodies moving
// from their t = 0 poses at their velocities over an interval, each against the `exact` oracle
// (docs/time_of_impact.md). Typed rows; toi_json writes them.
#pragma once

#include <string>
#include <vector>

#include "comparisons/eval/json_io.h"
#include "comparisons/eval/stated_check.h"
#include "comparisons/eval/timing.h"
#include "comparisons/scene/scene.h"
#include "reference/backend.h"

namespace rbx {

/// A time of impact further than kToiDisagree of the interval from the oracle's disagrees (the
/// threshold rbx explore marks by); further than kToiDeviate, it deviates. The oracle's own time
/// is exact to round-off in translation and within 1e-12 of the pair's size of a touch with
/// rotation (reference/exact.h), both far below.
constexpr double kToiDisagree = 1e-6;
constexpr double kToiDeviate = 1e-9;
/// A time is also right, whatever its distance from the oracle's, where the pair at that time is
/// within kToiTouchBand of the pair's size (the sum of the bodies' bounding radii) of touching:
/// apart by at most that, or overlapping by at most that. A grazing touch closes so slowly that
/// a distance of round-off spans a long time (a touch within 3e-11 m at 4e-6 m/s is 7.6e-6 of the
/// interval early); which instant is "the" touch is then the stopping tolerance's choice, not an
/// error. 1e-9 is the band the contact kind takes as touching (explore.h).
constexpr double kToiTouchBand = 1e-9;

/// How one backend's answer on one pair stands against the oracle's.
struct ToiVerdict {
  bool comparable = false;  // both answered (status ok) and both hit
  double time_err = 0.0;    // |fraction - fraction*|, of the interval
  /// Where both give a contact: the angle (degrees) between the normals, and how far the point
  /// is from either body at the oracle's time, over the pair's size. Shown, not marked: at an
  /// edge or a corner many normals are right.
  bool located = false;
  double normal_err_deg = 0.0;
  double point_err_rel = 0.0;
  /// Where the time disagrees: how the pair stands at the answer's instant, exactly (m): apart
  /// by this much (positive: the answer stops short of the touch) or overlapping by minus this
  /// (negative: it passes the touch). What a reader checks a library's stopping rule against.
  double separation_m = 0.0;
  std::string mark;  // "" | "deviates" | "disagrees"
  std::string why;   // the mark's reason, one line
};

/// One row's query: a backend's, or a variant's ("backend/variant"), and whether it is a
/// library's (isolated under a deadline).
struct ToiSubject {
  std::string name;
  ToiFn fn;
  bool library = true;
};

/// The rows `names` (registry backends) give: each backend's own query, then its variants'
/// (the other queries, as Bullet's casts; not a set-up variant such as "prebuilt", whose answers
/// are the backend's). A backend without one is a row that answers `unsupported`.
std::vector<ToiSubject> toi_subjects(const std::vector<std::string>& names);

/// `s`'s query on (a, b) over `dt`; a library's call runs isolated under its deadline.
/// `cold_s`, when given, gets its run time.
ToiResult run_toi(const ToiSubject& s, const RigidBody& a, const RigidBody& b, double dt,
                  double* cold_s = nullptr);

/// The verdict on `answer` for the pair (a, b) over `dt` whose exact answer is `truth`.
ToiVerdict judge_toi(const ToiResult& answer, const ToiResult& truth, const RigidBody& a,
                     const RigidBody& b, double dt);

/// One row's answer on one pair.
struct ToiRow {
  std::string backend;  // a backend's name, or "backend/variant"
  ToiResult result;
  ToiVerdict verdict;
  Timing timing;  // as DistanceRow's
};

/// One pair of bodies (not both static).
struct ToiPair {
  std::string a, b;
  ToiResult truth;
  std::vector<ToiRow> rows;
};

/// Every pair's queries over one interval.
struct ToiComparison {
  std::string scene, file;
  double interval = 0.0;  // s
  std::vector<ToiPair> pairs;
  StatedCheck expect;  // the first pair against the scene's [expect.toi]
};

/// Queries every pair of bodies (not both static) over `interval` (s) with every row of
/// toi_subjects(names) and the oracle, each timed as compare_distances does.
ToiComparison compare_tois(const Scene& scene, const std::vector<std::string>& names,
                           double interval, double budget_s = 0.01);

/// The document `rbx toi --json` writes (docs/contract.md, "rbx toi").
Json toi_json(const ToiComparison& c);

}  // namespace rbx
