#include "comparisons/eval/bench_goals.h"

#include <cmath>

#include "engine/format.h"

namespace rbx {

namespace {

std::string goal_num(double x, int digits = 3) {
  NumberFormat f;
  f.digits = digits;
  f.non_finite = "—";
  return format_number(x, f);
}

const NarrowRow* find_row(const std::vector<NarrowRow>& rows, const std::string& backend,
                          const std::string& variant, const std::string& pose, int vertices) {
  for (const NarrowRow& r : rows)
    if (r.backend == backend && r.variant == variant && r.pose == pose && r.vertices == vertices)
      return &r;
  return nullptr;
}

const StepRow* find_step(const std::vector<StepRow>& rows, const std::string& scene,
                         const std::string& backend, const std::string& variant) {
  for (const StepRow& r : rows)
    if (r.scene == scene && r.backend == backend && r.variant == variant) return &r;
  return nullptr;
}

// "0.83 (0.80-0.86 over 7 rounds)": a ratio as judged, with its spread.
std::string ratio_text(const RatioSpread& r, int digits = 3) {
  if (r.rounds == 0) return "not measured";
  // The range at the median's precision: at two digits 1.06 reads "1.1", above a median of 1.08.
  return goal_num(r.median, digits) + " (" + goal_num(r.q25, digits) + "-" +
         goal_num(r.q75, digits) + " over " + std::to_string(r.rounds) + " rounds)";
}

// A goal on one ratio a / b of two timed rows: met when the median ratio is at most `limit`.
PerfGoal ratio_goal(const std::string& goal, const std::string& label, const BenchTime* a,
                    const BenchTime* b, double limit, const std::string& unit,
                    const char* behind = "") {
  PerfGoal g;
  g.goal = goal;
  g.behind = behind;
  if (!a || !b) {
    g.measured = "not measured";
    return g;
  }
  const RatioSpread r = bench_ratio(*a, *b);
  g.ratios.push_back({label, r});
  g.measured =
      "medians " + (unit == "ns" ? fmt_duration_ns(a->median) : goal_num(a->median) + " " + unit) +
      " vs " + (unit == "ns" ? fmt_duration_ns(b->median) : goal_num(b->median) + " " + unit) +
      "; ratio round by round " + ratio_text(r);
  g.met = r.rounds > 0 && r.median <= limit;
  return g;
}

}  // namespace

// The profiles behind the contact-query goals (perf and cachegrind, 2026-11-28, after the inner
// polytope, the region's centre and the scan on AVX; hulls of random points on a sphere), each a
// measured cause.
constexpr const char* kDetectorProfile =
    "touching, the tests no longer run for shapes the inner polytope proves to overlap: at N = 32 "
    "the shapes' vertex climbs (GJK's and EPA's supports, the candidates' overlaps) are about a "
    "quarter of the query, the narrowed search an eighth, EPA's own bookkeeping a tenth and the "
    "region's centre about a fifth.";
constexpr const char* kDeepProfile =
    "deep, small hulls: at N = 128 the shapes' supports (a scan of every vertex, four at a time) "
    "are about 3/10 of the query's instructions (about 15 EPA iterations, two supports each, "
    "before the polytope's nearest triangle lies on a face of the Minkowski difference), EPA's "
    "own bookkeeping (nearest triangle, seen triangles, new faces) about a quarter, the narrowed "
    "search about a fifth and the region's centre about a twentieth. FCL's convex pairs run "
    "libccd's MPR, which estimates the depth without certifying the least overlap.";

// The profile behind the whole-step goal (callgrind, 2026-12-06, many_1000 over its first 300
// steps), a measured cause.
constexpr const char* kStepProfile =
    "the whole step, many_1000: the time of impact that moves each new contact to its first touch "
    "is about a quarter of the step (its samples' detections and the touch witness's answers "
    "about a sixth, its distances about a tenth), the separation proofs of the pairs passing the "
    "bounding check (the seed's bounding spheres of neighbouring cubes overlap, so about 2,700 "
    "pairs pass it each step) about a sixth, the look-ahead's moves of every body about a tenth, "
    "and the broad phase, the contact solve and the manifolds about a twentieth each.";

std::vector<PerfGoal> perf_goals(const BenchPlan& plan, const BenchResults& results) {
  std::vector<PerfGoal> goals;
  const std::vector<NarrowRow>& nr = results.narrow;
  auto query = [&](const char* backend, const char* variant, const char* pose,
                   int n) -> const BenchTime* {
    const NarrowRow* r = find_row(nr, backend, variant, pose, n);
    return r && r->ns_per_query.rounds > 0 ? &r->ns_per_query : nullptr;
  };
  const double fast_exp = series_exponent(nr, "custom", "default", "touching");
  goals.push_back({"custom, touching: time grows no faster than N^1.2",
                   "exponent " + goal_num(fast_exp) +
                       " (N = " + std::to_string(plan.hull_sizes.front()) + " to " +
                       std::to_string(plan.hull_sizes.back()) + ")",
                   std::isfinite(fast_exp) && fast_exp <= 1.2,
                   "",
                   {}});
  // Against FCL with its shapes built once (custom keeps its hierarchies per shape too): the
  // per-call `fcl` row also pays for building fcl::Convex, which would flatter custom.
  goals.push_back(ratio_goal("custom no slower than fcl (shapes prebuilt) at N = 2048, touching",
                             "N = 2048", query("custom", "default", "touching", 2048),
                             query("fcl", "prebuilt", "touching", 2048), 1.0, "ns",
                             kDetectorProfile));
  goals.push_back(ratio_goal("custom within 1.5x of fcl on two boxes (fcl::Box), touching", "box",
                             query("custom", "default", "touching", 8),
                             query("fcl", "boxes", "touching", 8), 1.5, "ns"));
  {
    std::vector<std::pair<double, double>> pts;
    for (const BroadRow& r : results.broad)
      if (r.method == to_string(BroadPhaseMethod::Tree) && std::isfinite(r.ns_per_step.median))
        pts.push_back({static_cast<double>(r.bodies), r.ns_per_step.median});
    const double e = fit_exponent(pts);
    goals.push_back(
        {"broad phase (tree, the world's default): pair finding grows no faster than "
         "N^1.2",
         "exponent " + goal_num(e) + " (" + std::to_string(plan.crowd_sizes.front()) + " to " +
             std::to_string(plan.crowd_sizes.back()) + " bodies)",
         std::isfinite(e) && e <= 1.2,
         "",
         {}});
  }
  // The custom contact query (detector and contact plane) no slower than FCL with prebuilt shapes
  // at every hull size timed, touching and deep.
  for (const char* pose : {"touching", "deep"}) {
    PerfGoal g;
    g.goal = std::string(
                 "custom no slower than fcl (shapes prebuilt) at every hull "
                 "size timed, ") +
             pose;
    g.behind = std::string(pose) == "touching" ? kDetectorProfile : kDeepProfile;
    g.met = true;
    for (int n : plan.hull_sizes) {
      const BenchTime *c = query("custom", "default", pose, n),
                      *f = query("fcl", "prebuilt", pose, n);
      if (!c || !f) continue;
      const RatioSpread r = bench_ratio(*c, *f);
      g.ratios.push_back({"N = " + std::to_string(n), r});
      g.met = g.met && r.rounds > 0 && r.median <= 1.0;
      g.measured += (g.measured.empty() ? "" : ", ") + ("N = " + std::to_string(n) + ": ") +
                    goal_num(r.median, 2) + "x (" + goal_num(r.q25, 2) + "-" + goal_num(r.q75, 2) +
                    ")";
    }
    if (g.ratios.empty()) {
      g.measured = "not measured";
      g.met = false;
    }
    goals.push_back(g);
  }
  auto step = [&](const char* scene, const char* backend, const char* variant) -> const BenchTime* {
    const StepRow* r = find_step(results.step, scene, backend, variant);
    return r && r->us_per_body_step.rounds > 0 ? &r->us_per_body_step : nullptr;
  };
  for (const char* scene : {"many_100", "many_1000"}) {
    const BenchTime *custom = step(scene, "custom", "default"),
                    *bullet = step(scene, "bullet", "default");
    goals.push_back(
        ratio_goal(std::string("whole custom step within 2x of Bullet per body-step on ") + scene,
                   scene, custom, bullet, 2.0, "µs"));
    // With the time of impact of every new contact and the chosen plane.
    goals.push_back(
        ratio_goal(std::string("whole custom step no slower than Bullet per body-step on ") + scene,
                   scene, custom, bullet, 1.0, "µs", kStepProfile));
  }
  // The extended engine (friction, manifolds, time of impact) within 2x of the seed's algorithm
  // (the custom-seed backend) per body-step on many_1000.
  goals.push_back(ratio_goal("custom step within 2x of custom-seed per body-step on many_1000",
                             "many_1000", step("many_1000", "custom", "default"),
                             step("many_1000", "custom-seed", "default"), 2.0, "µs"));
  // Explore's contact samples per minute per core.
  for (const ExploreRow& r : results.explore)
    goals.push_back({"rbx explore: at least 50,000 contact samples per minute per core through " +
                         r.backends + " on hulls under 100 points",
                     goal_num(r.samples_per_minute.median, 3) + " per minute (" +
                         goal_num(r.samples_per_minute.q25, 3) + "-" +
                         goal_num(r.samples_per_minute.q75, 3) + " over " +
                         std::to_string(r.samples_per_minute.rounds) + " rounds; one thread, " +
                         std::to_string(r.samples) +
                         " samples of seed 1, as `rbx explore --bench --threads 1`)",
                     r.samples_per_minute.median >= 50000.0,
                     "",
                     {}});
  return goals;
}

}  // namespace rbx
