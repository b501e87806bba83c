// `rbx bench`'s goals (comparisons/eval/bench_goals.h): judged on the ratio of two rows taken
// round by round, and a goal not met carries the profile behind it.
#include "comparisons/eval/bench_goals.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace rbx {
namespace {

// Rounds of a row: `base` seconds times each factor.
BenchTime rounds_of(double base, const std::vector<double>& factors) {
  std::vector<double> v;
  for (double f : factors) v.push_back(base * f);
  return bench_time(v);
}

// The detector goal of a run where custom takes `ratio` times FCL's prebuilt time at every hull
// size of the plan, in every round.
PerfGoal detector_goal(double ratio) {
  BenchPlan plan;
  plan.hull_sizes = {32, 128};
  plan.crowd_sizes = {1000, 2000};  // (perf_goals names the first and last)
  BenchResults results;
  for (int n : plan.hull_sizes) {
    NarrowRow fcl;
    fcl.backend = "fcl";
    fcl.variant = "prebuilt";
    fcl.pose = "touching";
    fcl.vertices = n;
    fcl.ns_per_query = rounds_of(1000.0 * n, {1.0, 1.1, 0.9});
    NarrowRow custom = fcl;
    custom.backend = "custom";
    custom.variant = "default";
    custom.ns_per_query = rounds_of(ratio * 1000.0 * n, {1.0, 1.1, 0.9});
    results.narrow.push_back(fcl);
    results.narrow.push_back(custom);
  }
  for (const PerfGoal& g : perf_goals(plan, results))
    if (g.goal.find("every hull size timed") != std::string::npos) return g;
  ADD_FAILURE() << "no detector goal";
  return {};
}

TEST(PerfReport, AGoalNotMetCarriesItsProfile) {
  const PerfGoal slow = detector_goal(3.0);
  EXPECT_FALSE(slow.met);
  EXPECT_EQ(slow.measured, "N = 32: 3x (3-3), N = 128: 3x (3-3)");
  ASSERT_EQ(slow.ratios.size(), 2u);
  EXPECT_EQ(slow.ratios[0].label, "N = 32");
  EXPECT_EQ(slow.ratios[0].ratio.rounds, 3);
  EXPECT_NE(slow.behind.find("touching, the tests no longer run"), std::string::npos);
  const PerfGoal fast = detector_goal(0.5);
  EXPECT_TRUE(fast.met);
}

TEST(PerfReport, ARatioIsTakenRoundByRound) {
  // A load that slows both rows of a round alike leaves their ratio alone: rounds 2 and 4 ran
  // on a busy machine (3x and 5x), the ratio stays 0.5 in every round, while the medians' ratio
  // (1.5 / 2 = 0.75) does not.
  const BenchTime custom = rounds_of(1.0, {1.0, 3.0, 1.0, 5.0, 1.0});
  const BenchTime bullet = rounds_of(2.0, {1.0, 3.0, 1.0, 5.0, 1.0});
  const RatioSpread r = bench_ratio(custom, bullet);
  EXPECT_EQ(r.median, 0.5);
  EXPECT_EQ(r.q25, 0.5);
  EXPECT_EQ(r.q75, 0.5);
  EXPECT_EQ(r.rounds, 5);
  // Rounds are paired by index: only the rounds both rows have count.
  const RatioSpread shorter = bench_ratio(rounds_of(1.0, {1.0, 2.0}), bullet);
  EXPECT_EQ(shorter.rounds, 2);
  EXPECT_EQ(shorter.median, 0.5 * (0.5 + 1.0 / 3.0));  // rounds 1.0 / 2.0 and 2.0 / 6.0
  // No rounds: no ratio.
  EXPECT_EQ(bench_ratio(BenchTime{}, bullet).rounds, 0);
  EXPECT_TRUE(std::isnan(bench_ratio(BenchTime{}, bullet).median));
}

TEST(PerfReport, AStepGoalIsJudgedOnTheMedianRatio) {
  BenchPlan plan;
  plan.hull_sizes = {32};
  plan.crowd_sizes = {1000};
  BenchResults results;
  for (const char* scene : {"many_100", "many_1000"}) {
    StepRow bullet;
    bullet.backend = "bullet";
    bullet.variant = "default";
    bullet.scene = scene;
    bullet.us_per_body_step = rounds_of(0.5, {1.0, 1.0, 1.0});
    StepRow custom = bullet;
    custom.backend = "custom";
    custom.variant = "default";
    // Two rounds of three faster than Bullet: the median ratio is 0.9, met, though one round
    // is slower.
    custom.us_per_body_step = rounds_of(0.5, {0.9, 1.2, 0.9});
    results.step.push_back(bullet);
    results.step.push_back(custom);
  }
  int judged = 0;
  for (const PerfGoal& g : perf_goals(plan, results))
    if (g.goal.find("no slower than Bullet") != std::string::npos) {
      ++judged;
      EXPECT_TRUE(g.met) << g.goal << ": " << g.measured;
      ASSERT_EQ(g.ratios.size(), 1u);
      EXPECT_NEAR(g.ratios[0].ratio.median, 0.9, 1e-15);  // 0.45 / 0.5, round-off of a quotient
      EXPECT_NE(g.measured.find("over 3 rounds"), std::string::npos) << g.measured;
    }
  EXPECT_EQ(judged, 2);
}

// The pages print exponents the evaluation computed: each narrow series' slope of log time over
// log size from its hull rows (the box row left out), each broad-phase method's over its crowd
// sizes, NaN for a series with one size.
TEST(BenchExponents, FilledFromTheRowsNotByThePages) {
  BenchResults results;
  for (int n : {8, 16, 64, 256}) {
    NarrowRow r;
    r.backend = "custom";
    r.variant = "default";
    r.pose = "touching";
    r.vertices = n;
    r.ns_per_query = rounds_of(n == 8 ? 1e9 : std::pow(n, 1.5), {1.0});  // the box: an outlier
    results.narrow.push_back(r);
  }
  NarrowRow alone = results.narrow.back();
  alone.pose = "deep";  // one size: no slope
  results.narrow.push_back(alone);
  const std::string tree = to_string(kBenchBroadPhaseMethods[0]);
  for (int n : {100, 1000, 10000}) {
    BroadRow b;
    b.method = tree;
    b.bodies = n;
    b.ns_per_step = rounds_of(std::pow(n, 1.2), {1.0});
    results.broad.push_back(b);
  }
  fill_exponents(results);
  // Exact power laws: the fitted slopes are theirs to round-off of the logarithms.
  EXPECT_NEAR(results.narrow_exponents.at(narrow_series("custom", "default", "touching")), 1.5,
              1e-12);
  EXPECT_TRUE(std::isnan(results.narrow_exponents.at(narrow_series("custom", "default", "deep"))));
  EXPECT_NEAR(results.broad_exponents.at(tree), 1.2, 1e-12);
}

}  // namespace
}  // namespace rbx
