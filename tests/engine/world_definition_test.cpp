// A world definition's settings: the step count a run takes.
#include "engine/world_definition.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace rbx {
namespace {

// The message of the std::domain_error that step_count throws ("" if none).
std::string step_count_error(double duration, double dt) {
  try {
    step_count(duration, dt);
  } catch (const std::domain_error& e) {
    return e.what();
  }
  return "";
}

TEST(StepCount, RoundsToTheNearestStep) {
  EXPECT_EQ(step_count(1.0, 1e-3), 1000);
  EXPECT_EQ(step_count(0.0, 1e-3), 0);
  EXPECT_EQ(step_count(1.0004, 1e-3), 1000);
  // 2^53 itself is still a count a double holds exactly.
  EXPECT_EQ(step_count(kMaxStepCount, 1.0), 9007199254740992L);
}

TEST(StepCount, RefusesCountsThatAreNotFiniteOrPastTwoToThe53) {
  // Before, llround(1e303) overflowed to a negative count: a run of no steps, reported ok.
  EXPECT_EQ(step_count_error(1e300, 1e-3),
            "duration 1e+300 s at dt = 0.001 s is 1e+303 steps, not a step count a run can take "
            "(at most 2^53)");
  EXPECT_NE(step_count_error(1.0, 1e-320).find("is inf steps"), std::string::npos);
  EXPECT_NE(step_count_error(NAN, 1e-3), "");
  EXPECT_NE(step_count_error(-1.0, 1e-3), "");
  EXPECT_NE(step_count_error(2 * kMaxStepCount, 1.0), "");
  SimSettings s;
  s.duration = 1e300;
  EXPECT_THROW(s.steps(), std::domain_error);
}

}  // namespace
}  // namespace rbx
