// perf.md's goals (comparisons/output/perf_report.h): judged on the rows of a run, and a goal not
// met carries the profile behind it.
#include "comparisons/output/perf_report.h"

#include <gtest/gtest.h>

#include <string>

namespace rbx {
namespace {

// The issue-11 detector goal of a run where custom takes `ratio` times FCL's prebuilt time at
// every hull size of the plan.
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
    fcl.ns_per_query = 1000.0 * n;
    NarrowRow custom = fcl;
    custom.backend = "custom";
    custom.variant = "accelerated";
    custom.ns_per_query = ratio * fcl.ns_per_query;
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
  EXPECT_EQ(slow.measured, "N = 32: 3x, N = 128: 3x");
  EXPECT_NE(slow.behind.find("touching, the tests no longer run"), std::string::npos);
  const PerfGoal fast = detector_goal(0.5);
  EXPECT_TRUE(fast.met);
}

}  // namespace
}  // namespace rbx
