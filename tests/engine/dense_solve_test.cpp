// The contact solver's dense solves (engine/dense_solve.h) on systems with answers by hand: a
// singular system's least-norm answer, an inconsistent one's least-squares answer, and a small
// square system.
#include "engine/dense_solve.h"

#include <gtest/gtest.h>

namespace rbx {
namespace {

// Round-off of a few operations on numbers of order one.
constexpr double kDenseRoundOff = 1e-14;

TEST(LeastNormSolve, ASingularSystemGetsItsLeastNormAnswer) {
  // y1 + y2 = 2, twice: every y on that line solves it; the shortest is (1, 1).
  Eigen::MatrixXd A(2, 2);
  A << 1, 1, 1, 1;
  const Eigen::VectorXd y = least_norm_solve_refined(A, Eigen::Vector2d(2, 2));
  EXPECT_NEAR(y(0), 1.0, kDenseRoundOff);
  EXPECT_NEAR(y(1), 1.0, kDenseRoundOff);
}

TEST(LeastNormSolve, AnInconsistentSystemGetsTheLeastSquaresAnswer) {
  // y1 + y2 = 1 and y1 + y2 = 3 cannot both hold: the least squares ask y1 + y2 = 2, and of
  // those answers the least-norm one is (1, 1). A third unknown nothing constrains stays 0.
  Eigen::MatrixXd A(2, 3);
  A << 1, 1, 0, 1, 1, 0;
  const Eigen::VectorXd y = least_norm_solve_refined(A, Eigen::Vector2d(1, 3));
  ASSERT_EQ(y.size(), 3);
  EXPECT_NEAR(y(0), 1.0, kDenseRoundOff);
  EXPECT_NEAR(y(1), 1.0, kDenseRoundOff);
  EXPECT_NEAR(y(2), 0.0, kDenseRoundOff);
}

TEST(PivotedQrSolve, SolvesASquareSystem) {
  // 2 s1 + s2 = 3, s1 + 3 s2 = 5: s = (0.8, 1.4).
  Eigen::MatrixXd J(2, 2);
  J << 2, 1, 1, 3;
  const Eigen::VectorXd s = pivoted_qr_solve(J, Eigen::Vector2d(3, 5));
  EXPECT_NEAR(s(0), 0.8, kDenseRoundOff);
  EXPECT_NEAR(s(1), 1.4, kDenseRoundOff);
}

}  // namespace
}  // namespace rbx
