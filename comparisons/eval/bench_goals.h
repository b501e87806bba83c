// `rbx bench`'s goals, judged on the rows of a run. A goal that compares two rows of one group
// (comparisons/eval/bench_cases.h) is judged on their ratio taken round by round: its median,
// with the 25-75 % range over the rounds beside it.
#pragma once

#include <string>
#include <vector>

#include "comparisons/eval/bench_cases.h"

namespace rbx {

/// A ratio a goal is judged on, and what it is between ("N = 32", "many_100").
struct GoalRatio {
  std::string label;
  RatioSpread ratio;
};

/// One performance goal and what was measured against it.
struct PerfGoal {
  std::string goal, measured;
  bool met = false;
  std::string behind;             // the profile last measured behind the goal, printed when not met
  std::vector<GoalRatio> ratios;  // the headline ratios (empty for an exponent or a rate)
};

/// The goals, judged on the rows of a run.
std::vector<PerfGoal> perf_goals(const BenchPlan& plan, const BenchResults& results);

}  // namespace rbx
