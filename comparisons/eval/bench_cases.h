// `rbx bench`'s cases, as a table: Box2D lists its benchmarks as { name, create, step, count };
// here each family (narrow phase, broad phase, whole step) builds its cases from the plan, and
// each case is a name, an untimed warm-up and set-up, and a timed body. Backends are reached
// through the registry (reference/backend.h), timing-only variants through query_variants().
// The shape and pose builders are shared with tests/comparisons/bench_cases_test.cpp.
#pragma once

#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "comparisons/eval/timing.h"
#include "engine/body.h"
#include "engine/broadphase.h"
#include "engine/polyhedron.h"
#include "reference/backend.h"

namespace rbx {

/// A pose kind and its offset from the touching distance along the placement direction, as a
/// fraction of the shape size (1 m): touching = 0.5% of the size deep (within 1%), deep = 20%
/// deep, separated = a 5% gap.
struct PoseKind {
  const char* name;
  double offset;      // fraction of the size; negative: penetrating
  double turn = 0.0;  // time of impact: B's turn over the interval (rad), about a fixed axis
};
inline constexpr PoseKind kPoseKinds[] = {
    {"touching", -0.005}, {"deep", -0.2}, {"separated", 0.05}};

/// Distinct poses per shape and pose kind, queried in turn across iterations: a cycle this long
/// is not one a branch predictor learns, as it learns a handful of poses repeated.
constexpr int kBenchPoseCycle = 256;

/// Size (m) of every benchmark shape: the unit box and hulls of points on a sphere of radius 0.5.
constexpr double kBenchShapeSize = 1.0;

/// The broad-phase methods timed, in table order.
inline constexpr BroadPhaseMethod kBenchBroadPhaseMethods[] = {
    BroadPhaseMethod::AllPairs, BroadPhaseMethod::SweepAndPrune, BroadPhaseMethod::Tree};

/// What a run measures: sizes, caps and times for the full and the quick run.
struct BenchPlan {
  bool quick = false;
  std::vector<int> hull_sizes;              // vertices of the hulls (the box is always included)
  int poses = 3;                            // distinct poses per kind, queried in turn
  int poses_per_iteration = 3;              // consecutive poses of the cycle in one iteration
  double min_time = 0.2;                    // s, minimum timed time per case (rounds: 7)
  std::vector<int> crowd_sizes;             // bodies in the broad-phase crowds
  double crowd_min_time = 0.2;              // s
  std::vector<long> steps_100, steps_1000;  // step counts of the two runs per scene
  double step_min_time = 0.1;               // s
  int step_rounds = 7;                      // rounds of every whole-step run, at least
  int explore_samples = 2000;               // samples drawn per call of the explore case
  double explore_min_time = 3.0;            // s
};

/// The full plan, or the quick one (--quick).
BenchPlan bench_plan(bool quick);

/// One contact backend as benchmarked: a row of the narrow-phase table.
struct NarrowBackend {
  std::string backend;  // registry name
  std::string variant;  // "faithful" (the detector) for custom; "prebuilt" for fcl; "boxes" for
                        // fcl on box bodies (fcl::Box); "default" otherwise
  ContactFn contact;
  int max_vertices_full;   // largest hull size timed in the full run
  int max_vertices_quick;  // in the quick run
  bool boxes_only = false;
};

/// Every contact backend with the sizes it is timed at.
std::vector<NarrowBackend> narrow_backends();

/// The gaps the distance queries are timed at, as fractions of the shape size (the pose kinds'
/// convention: B placed that far beyond touching along the placement direction).
inline constexpr PoseKind kGapKinds[] = {{"gap 1%", 0.01}, {"gap 20%", 0.2}};
/// The time-of-impact family's: the gaps in translation, and the wider one with B turning by a
/// radian on its way (where the translation-only casts answer `unsupported`).
inline constexpr PoseKind kToiKinds[] = {
    {"gap 1%", 0.01}, {"gap 20%", 0.2}, {"gap 20%, turning", 0.2, 1.0}};

/// One distance query as benchmarked: a row of the distance table.
struct DistanceBackend {
  std::string backend;  // registry name
  std::string variant;  // "default", or the query variant's ("prebuilt" for fcl)
  DistanceFn distance;
  int max_vertices_full;   // largest hull size timed in the full run
  int max_vertices_quick;  // in the quick run
};
/// Every distance query timed: the registry backends with one whose contact query is timed
/// (`exact` left out: its distance is a check over every feature pair, not a query; a library's
/// plain row, which builds its shapes on every call, up to N = 2,048), and the query variants
/// with one, at their contact rows' sizes.
std::vector<DistanceBackend> distance_backends();

/// One time-of-impact query as benchmarked: a row of the time-of-impact table.
struct ToiBackend {
  std::string backend;  // registry name
  std::string variant;  // "default", or the query variant's ("gjk-cast")
  ToiFn toi;
  int max_vertices_full;   // largest hull size timed in the full run
  int max_vertices_quick;  // in the quick run
};
/// Every time-of-impact query timed, on the distance queries' poses with B moving onto A (its
/// velocity the centres' offset, over an interval of 1 s): custom at its contact rows' sizes,
/// the libraries' rows and variants (which build their shapes on every call) up to N = 2,048
/// (512 quick); `exact` left out (a check, not a query).
std::vector<ToiBackend> toi_backends();

// ---- Scene builders ------------------------------------------------------------------------

/// The hull of n random points on the sphere of radius 0.5 (all of them are hull vertices).
ConvexPolyhedron sphere_hull(int n, std::mt19937_64& rng);

/// One pair of bodies at several poses of one kind.
struct PosedPair {
  RigidBody a, b;
  std::vector<Pose> poses_a, poses_b;
};

/// Poses of one kind for a pair of copies of `shape`: random orientations and a random
/// direction d; the touching distance t* along d is found by bisection with libccd (MPR,
/// tolerance 1e-10 m), and B is placed at t* + offset * size along d from A.
PosedPair make_poses(const ConvexPolyhedron& shape, bool box, const PoseKind& kind, int count,
                     std::mt19937_64& rng);

/// A crowd of n cubes of 0.2 m at uniformly random points and orientations, one per 0.125 m^3
/// (the grid spacing of scenes/many/many_100), so each cube has about the same number of
/// neighbours at any n.
std::vector<RigidBody> cube_crowd(int n, std::mt19937_64& rng);

// ---- Cases and results ---------------------------------------------------------------------

/// One timed case: a name, an untimed warm-up and set-up, and a timed body. The warm-up runs
/// once, timed alone: the case's cold pass, reported apart. Then rounds of body calls are timed
/// (comparisons/eval/timing.h), with set_up before every call, outside the clock.
struct BenchCase {
  std::string name;               // family/backend/variant/size/kind
  std::function<void()> warm_up;  // once, first: caches, hierarchies, page faults
  std::function<void()> set_up;   // untimed, before every call; empty: none
  std::function<void()> body;     // the timed work of one call
};

/// Cases timed together, round by round in turns (the backends on one shape size and pose kind,
/// the broad-phase methods on one crowd, the engines on one scene): a passing load of the machine
/// falls on all of them alike, and the ratio between two is taken round by round.
struct BenchGroup {
  std::string name;
  TimingPlan plan;
  std::vector<BenchCase> cases;
};

/// A timed quantity in its row's unit (ns per query, ns per step, µs per body-step): the median
/// over rounds, their 25-75 % range, the counts, the cold pass, and every round's value in the
/// order run, so that two rows of one group give a ratio round by round.
struct BenchTime {
  double median = NAN, q25 = NAN, q75 = NAN;
  int rounds = 0;
  long calls = 0;
  double cold = NAN;  // the warm-up pass, timed alone (for the whole step: the short run's)
  std::vector<double> per_round;
};

/// The per-round values' median and quartiles as a BenchTime (counts and cold left to fill).
BenchTime bench_time(std::vector<double> per_round);

/// The ratio a / b of two rows timed in one group, round by round.
RatioSpread bench_ratio(const BenchTime& a, const BenchTime& b);

/// A narrow-phase result row.
struct NarrowRow {
  std::string backend, variant, pose, status;
  int vertices = 0;       // nominal: 8 for the box, else the hull's point count
  int hull_vertices = 0;  // as built
  BenchTime ns_per_query;
};

/// A broad-phase result row.
struct BroadRow {
  std::string method;
  int bodies = 0;
  BenchTime ns_per_step;
  double pairs_per_step = 0.0;
};

/// A whole-step result row.
struct StepRow {
  std::string backend, variant, scene;
  int bodies = 0;              // moving bodies
  int total_bodies = 0;        // including static walls
  BenchTime us_per_body_step;  // per round: (long run - short run) / (extra steps x bodies)
  std::string status;
};

/// An explore-throughput row: contact samples of `rbx explore` per minute on one core.
struct ExploreRow {
  std::string backends;  // what each sample runs through
  int samples = 0;       // samples timed (a block, each under 100 points)
  BenchTime samples_per_minute;
};

/// Everything a run measured.
struct BenchResults {
  int cpus = 0;  // as the process sees the machine
  double mhz = 0.0;
  std::size_t cases = 0;
  std::vector<NarrowRow> narrow;
  std::vector<NarrowRow> distance;  // the distance queries, `pose` naming the gap kind
  std::vector<NarrowRow> toi;       // the time-of-impact queries, likewise
  std::vector<BroadRow> broad;
  std::vector<StepRow> step;
  std::vector<ExploreRow> explore;
  // The growth exponent of time against size of each series (fit_exponent; NaN where a series
  // has fewer than two sizes): the narrow phase's by "backend/variant/pose kind"
  // (series_exponent), the broad phase's by method. Filled from the rows (fill_exponents).
  std::map<std::string, double> narrow_exponents, broad_exponents;
};

/// Builds every family's groups of cases, times each group interleaved and returns the rows
/// with their exponents.
BenchResults run_bench(const BenchPlan& plan);

/// Least-squares slope of log(time) against log(size): the exponent of time against size.
double fit_exponent(const std::vector<std::pair<double, double>>& points);

/// The least-squares exponent of one narrow-phase series (hull sizes only, the box excluded).
double series_exponent(const std::vector<NarrowRow>& rows, const std::string& backend,
                       const std::string& variant, const std::string& pose);

/// The key of a narrow-phase series in BenchResults::narrow_exponents.
std::string narrow_series(const std::string& backend, const std::string& variant,
                          const std::string& pose);

/// Fills the results' exponents from their rows: every narrow_backends() series of every pose
/// kind, every broad-phase method of kBenchBroadPhaseMethods.
void fill_exponents(BenchResults& results);

}  // namespace rbx
