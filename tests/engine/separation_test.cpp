// The separation witness (engine/separation.h) lets the extended world skip detection: it must
// hold only where both detectors find no contact, down to gaps at the detector's tolerance, for
// blunt and sharp shapes alike.
#include "engine/separation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "engine/detect.h"
#include "tests/common/fixtures.h"

namespace rbx {
namespace {

Quat random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  Quat q(g(rng), g(rng), g(rng), g(rng));
  return q.normalized();
}

using test::sharp_wedge;

TEST(Separation, ReachIsSqrt3ForABoxAndLargerForAWedge) {
  EXPECT_NEAR(tolerance_reach(make_box(Vec3(1.0, 2.0, 0.5))), std::sqrt(3.0), 1e-12);
  EXPECT_GT(tolerance_reach(sharp_wedge()), 5.0);  // 1 / sin(~5.7 deg) at the sharp edge's corners
}

TEST(Separation, AWitnessMeansTheDetectorFindsNothing) {
  const std::vector<ConvexPolyhedron> shapes = {
      make_box(Vec3(1.0, 1.0, 1.0)), make_box(Vec3(2.0, 0.3, 0.7)), make_prism(0.6, 1.2, 7),
      make_icosphere(0.5, 1), sharp_wedge()};
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int witnessed = 0, near = 0;
  const int trials = 30000;
  for (int k = 0; k < trials; ++k) {
    const ConvexPolyhedron& a = shapes[k % shapes.size()];
    const ConvexPolyhedron& b = shapes[(k / shapes.size()) % shapes.size()];
    Pose pa, pb;
    pa.orientation = random_rotation(rng);
    pb.orientation = random_rotation(rng);
    pb.position = Vec3(u(rng), u(rng), u(rng)) * 3.0;
    const double tol = point_in_mesh_tolerance(a, b);
    // Two trials in three: A placed apart from B along a random axis by a gap of 0 .. 12 tol,
    // where the margin decides.
    if (k % 3 != 0) {
      const Vec3 axis = Vec3(u(rng), u(rng), u(rng)).normalized();
      pa.position = pb.position + axis * 5.0;
      const double gap = static_cast<double>(k % 13) * tol;
      pa.position += axis * (gap - gap_along(a, pa, b, pb, axis));
    }
    const double margin = separation_margin(tol, tolerance_reach(a), tolerance_reach(b));
    const Vec3 w = find_separating_axis(a, pa, b, pb, margin);
    if (w == Vec3::Zero()) continue;
    ++witnessed;
    if (gap_along(a, pa, b, pb, w) < 20.0 * tol) ++near;
    EXPECT_FALSE(detect(a, pa, b, pb, Detector::Accelerated)) << "trial " << k;
    EXPECT_FALSE(detect(a, pa, b, pb, Detector::Faithful)) << "trial " << k;
  }
  // Not vacuous: a good share found a witness, and some of them within a few tolerances.
  EXPECT_GT(witnessed, trials / 10);
  EXPECT_GT(near, 100);
}

// The bounding boxes' bound on the gap, which the extended step tries before the vertices: never
// above the gap, equal to it (to round-off) for two boxes.
TEST(Separation, TheBoxBoundNeverExceedsTheGapAndIsExactForBoxes) {
  const std::vector<ConvexPolyhedron> shapes = {make_box(Vec3(1.0, 1.0, 1.0)),
                                                make_box(Vec3(2.0, 0.3, 0.7)),
                                                make_prism(0.6, 1.2, 7), make_icosphere(0.5, 1)};
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < 4000; ++k) {
    const ConvexPolyhedron& a = shapes[k % shapes.size()];
    const ConvexPolyhedron& b = shapes[(k / shapes.size()) % shapes.size()];
    Pose pa, pb;
    pa.orientation = random_rotation(rng);
    pb.orientation = random_rotation(rng);
    pa.position = Vec3(u(rng), u(rng), u(rng)) * 3.0;
    pb.position = Vec3(u(rng), u(rng), u(rng)) * 3.0;
    const Vec3 axis = Vec3(u(rng), u(rng), u(rng)).normalized();
    const double gap = gap_along(a, pa, b, pb, axis), bound = gap_bound_along(a, pa, b, pb, axis);
    // 1e-12 of the coordinates: the round-off of the two sums.
    EXPECT_LE(bound, gap + 1e-12 * 6.0) << "trial " << k;
    if (k % shapes.size() < 2 && (k / shapes.size()) % shapes.size() < 2) {
      EXPECT_NEAR(bound, gap, 1e-12 * 6.0) << "trial " << k;
    }
  }
}

TEST(Separation, NoWitnessWithinTheMargin) {
  // Two unit cubes face to face: the margin ((sqrt 3 + 1) tol) refuses gaps up to 2.7 tol, as
  // the detector's tolerance may reach across them (a corner's region reaches sqrt 3 tol); at
  // 3 tol the witness holds.
  const ConvexPolyhedron cube = make_box(Vec3::Ones());
  const double tol = point_in_mesh_tolerance(cube, cube);
  const double margin = separation_margin(tol, tolerance_reach(cube), tolerance_reach(cube));
  for (double gap : {0.0, tol, 2.0 * tol, 2.7 * tol}) {
    Pose pa, pb;
    pa.position = Vec3(1.0 + gap, 0.0, 0.0);
    EXPECT_EQ(find_separating_axis(cube, pa, cube, pb, margin), Vec3::Zero()) << gap;
  }
  Pose pa, pb;
  pa.position = Vec3(1.0 + 3.0 * tol, 0.0, 0.0);
  EXPECT_NE(find_separating_axis(cube, pa, cube, pb, margin), Vec3::Zero());
}

TEST(Separation, BesideAWallTheNearestPointOfItsBoxProvesIt) {
  // A unit cube (turned 0.05 rad) 1.6 cm beside a 10 m wall, near its end: the line of centres
  // is 8 degrees off the wall's axis, so along it, along the wall's face normal nearest it (the
  // end face's) and along the cube's the two overlap; the direction from the wall's box to the
  // cube's centre (+y) proves the gap. Without that candidate this pair went to the detector at
  // every step.
  const ConvexPolyhedron wall = make_box(Vec3(10.0, 0.2, 3.0)), cube = make_box(Vec3::Ones());
  Pose pa, pb;
  pa.position = Vec3(4.5, 0.64, 0.0);  // lowest corner at y = 0.64 - 0.524
  pa.orientation = Quat(Eigen::AngleAxisd(0.05, Vec3::UnitZ()));
  const double tol = point_in_mesh_tolerance(cube, wall);
  const double margin = separation_margin(tol, tolerance_reach(cube), tolerance_reach(wall));
  const Vec3 w = find_separating_axis(cube, pa, wall, pb, margin);
  ASSERT_NE(w, Vec3::Zero());
  EXPECT_GT(gap_along(cube, pa, wall, pb, w), margin);
  EXPECT_NEAR(w.y(), 1.0, 1e-12);
  EXPECT_FALSE(detect(cube, pa, wall, pb, Detector::Accelerated));
  // The same pair with the roles swapped (the wall as a): the cube's box sees it from -y.
  const Vec3 v = find_separating_axis(wall, pb, cube, pa, margin);
  ASSERT_NE(v, Vec3::Zero());
  EXPECT_GT(gap_along(wall, pb, cube, pa, v), margin);
}

}  // namespace
}  // namespace rbx
