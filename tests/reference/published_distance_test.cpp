// The published distance cases of coal (formerly hpp-fcl), test/box_box_distance.cpp, and of FCL,
// test/test_fcl_geometric_shapes.cpp and test/test_fcl_distance.cpp: box pairs with their
// distance (and closest points) stated in closed form, to eight digits, or to FCL's tolerances.
// Bullet's own collision tests hold sphere pairs only, and neither FCL's (a sphere on a spline)
// nor Bullet's suite has a time-of-impact case on polyhedra: nothing of theirs to translate. The
// oracle and `custom` must give every published value within the tolerance the source states; every
// other distance backend's answer is printed beside it ([measured]), the report's business.
//
// Conversion: coal's Box takes full extents, like ours; makeQuat(w, x, y, z) is Eigen's
// Quat(w, x, y, z); its nearest_points[0] is on the first object (our A), [1] on the second.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "engine/distance.h"
#include "reference/backend.h"
#include "reference/exact.h"
#include "tests/common/fixtures.h"

namespace rbx {
namespace {

struct Published {
  std::string name;
  RigidBody a, b;
  bool overlapping = false;
  double distance = 0.0;
  double distance_rel = 0.0;  // the source's tolerance on the distance, relative
  bool points = false;        // the source states the closest points (unique here)
  Vec3 point_a = Vec3::Zero(), point_b = Vec3::Zero();
  double point_rel = 0.0;  // its tolerance on each coordinate, relative
  // The source's tolerances where it states them in absolute terms (FCL's), m; 0: none.
  double distance_abs = 0.0, point_abs = 0.0;
};

Quat quat(double w, double x, double y, double z) { return Quat(w, x, y, z).normalized(); }

std::vector<Published> cases() {
  std::vector<Published> out;
  const double pi = M_PI;
  // distance_box_box_1: boxes 6 x 10 x 2 at the origin and 2 x 2 x 2 at (25, 20, 5): corner to
  // corner, (21, 14, 3) apart; BOOST_CHECK_CLOSE 1e-4 % on the distance, 1e-6 % on the points.
  {
    Published p{"distance_box_box_1", test::box_at("A", Vec3(6, 10, 2), Vec3::Zero()),
                test::box_at("B", Vec3(2, 2, 2), Vec3(25, 20, 5))};
    p.distance = std::sqrt(21.0 * 21 + 14 * 14 + 3 * 3);
    p.distance_rel = 1e-6;
    p.points = true;
    p.point_a = Vec3(3, 5, 1);
    p.point_b = Vec3(24, 19, 4);
    p.point_rel = 1e-8;
    out.push_back(p);
  }
  // distance_box_box_2: the small box at (0, 0, 10) turned by pi/4 about (1, 1, 1); its lowest
  // corner at z = 10 - 1.62123444; published to eight digits, 1e-4 % on everything.
  {
    const double s = std::sin(pi / 8) / std::sqrt(3.0);
    Published p{"distance_box_box_2", test::box_at("A", Vec3(6, 10, 2), Vec3::Zero()),
                test::box_at("B", Vec3(2, 2, 2), Vec3(0, 0, 10), quat(std::cos(pi / 8), s, s, s))};
    p.distance = -1.62123444 + 10 - 1;
    p.distance_rel = 1e-6;
    p.points = true;
    p.point_a = Vec3(0.60947571, 0.01175873, 1);
    p.point_b = Vec3(0.60947571, 0.01175873, -1.62123444 + 10);
    p.point_rel = 1e-6;
    out.push_back(p);
  }
  // distance_box_box_3: unit cubes turned by pi/4 about z at (-2, 1, 0.5) and about y at
  // (2, 0.5, 0.5): a vertical edge against a horizontal one, 4 - sqrt(2) apart; then both moved
  // by one more rigid motion (the same distance, the points moved); 1e-4 % on everything.
  {
    const Quat qa = quat(std::cos(pi / 8), 0, 0, std::sin(pi / 8));
    const Quat qb = quat(std::cos(pi / 8), 0, std::sin(pi / 8), 0);
    Published p{"distance_box_box_3", test::unit_cube("A", Vec3(-2, 1, 0.5), qa),
                test::unit_cube("B", Vec3(2, 0.5, 0.5), qb)};
    p.distance = 4 - std::sqrt(2.0);
    p.distance_rel = 1e-6;
    p.points = true;
    p.point_a = Vec3(std::sqrt(2.0) / 2 - 2, 1, 0.5);
    p.point_b = Vec3(2 - std::sqrt(2.0) / 2, 1, 0.5);
    p.point_rel = 1e-6;
    out.push_back(p);
    const Quat q3 = quat(0.435952844074, -0.718287018243, 0.310622451066, 0.444435113443);
    const Vec3 t3(4, 5, 6);
    Published m = p;
    m.name = "distance_box_box_3 moved";
    m.a = test::unit_cube("A", q3 * Vec3(-2, 1, 0.5) + t3, q3 * qa);
    m.b = test::unit_cube("B", q3 * Vec3(2, 0.5, 0.5) + t3, q3 * qb);
    m.point_a = q3 * p.point_a + t3;
    m.point_b = q3 * p.point_b + t3;
    out.push_back(m);
  }
  // distance_box_box_4: unit cubes along x, 1 and 0.01 apart (1e-4 % and 2e-3 %), then
  // overlapping by 0.01 and by 1 (coal's signed distance, -0.01 and -1: our `overlapping`).
  for (const double x : {2.0, 1.01, 0.99, 0.0}) {
    Published p{"distance_box_box_4 x = " + std::to_string(x), test::unit_cube("A", Vec3(x, 0, 0)),
                test::unit_cube("B", Vec3::Zero())};
    p.overlapping = x < 1;
    p.distance = x - 1;
    p.distance_rel = x == 2.0 ? 1e-6 : 2e-5;
    out.push_back(p);
  }
  // FCL, test/test_fcl_geometric_shapes.cpp, shapeDistance_boxbox (and shapeDistanceGJK_boxbox,
  // the same poses through its own GJK): boxes of full sides 10, and 20 x 40 x 50, at the origin
  // and translated; each distance checked to 0.001 absolute. Their closed forms: a face 0.1
  // across, a face 10.1 or 10.2 across (the box, 10 wide, sits 20.1 or 20.2 away), two edges
  // 0.1 across in x and in y (0.1 sqrt 2; the source writes 0.1 * 1.414), and the big box's face
  // at x = 10 from the small one's at 15.1 - 5 and 20 - 5.
  {
    const Vec3 ten(10, 10, 10), big(20, 40, 50);
    const struct {
      const char* name;
      Vec3 size_a, at_b;
      double distance;
    } fcl[] = {{"fcl shapeDistance_boxbox 10.1 x", ten, Vec3(10.1, 0, 0), 0.1},
               {"fcl shapeDistance_boxbox 20.1 x", ten, Vec3(20.1, 0, 0), 10.1},
               {"fcl shapeDistance_boxbox 20.2 y", ten, Vec3(0, 20.2, 0), 10.2},
               {"fcl shapeDistance_boxbox 10.1 xy", ten, Vec3(10.1, 10.1, 0), 0.1 * std::sqrt(2.0)},
               {"fcl shapeDistance_boxbox big 15.1 x", big, Vec3(15.1, 0, 0), 0.1},
               {"fcl shapeDistance_boxbox big 20 x", big, Vec3(20, 0, 0), 5.0}};
    for (const auto& c : fcl) {
      Published p{c.name, test::box_at("A", c.size_a, Vec3::Zero()),
                  test::box_at("B", ten, c.at_b)};
      p.distance = c.distance;
      p.distance_abs = 1e-3;
      out.push_back(p);
    }
  }
  // FCL, test/test_fcl_distance.cpp, NearestPointFromDegenerateSimplex: a thin plate 2.75 x 6 x
  // 0.05 at (1.625, 0, 0.5) and a small turned box 0.424 x 0.15 x 0.1686 below its corner, from
  // a real scene whose libccd GJK once ended on a degenerate simplex (NaN points). The source
  // states the distance to 2e-14 (its constants<double>::eps_78()) and the points, in each box's
  // frame, to 0.001 (its DELTA).
  {
    Published p{"fcl NearestPointFromDegenerateSimplex",
                test::box_at("A", Vec3(2.75, 6.0, 0.05), Vec3(1.625, 0.0, 0.5)),
                test::box_at("B", Vec3(0.424, 0.15, 0.1686), Vec3(0.192074, -0.277870, 0.273546),
                             quat(0.672811, 0.340674, 0.155066, 0.638138))};
    p.distance = 0.053516162824549;
    p.distance_abs = std::pow(std::numeric_limits<double>::epsilon(), 7.0 / 8.0);
    p.points = true;
    p.point_a =
        p.a.pose().orientation * Vec3(-1.375, -0.098881502700918666, -0.025000000000000022) +
        p.a.pose().position;
    p.point_b = p.b.pose().orientation *
                    Vec3(0.21199965773384655, 0.074999692703297122, 0.084299993303443954) +
                p.b.pose().position;
    p.point_abs = 1e-3;
    out.push_back(p);
  }
  return out;
}

// Within `rel` of `want`, relative, or within `abs` (the source's absolute tolerance, FCL's), or
// within 1e-12 (coal's BOOST_CHECK_CLOSE on a value near zero is relative to it, which no
// computation of a zero coordinate meets).
bool close(double got, double want, double rel, double abs = 0.0) {
  return std::abs(got - want) <= std::max({rel * std::abs(want), abs, 1e-12});
}

TEST(PublishedDistance, TheOracleAndCustomGiveEveryPublishedValue) {
  for (const Published& p : cases()) {
    const ExactDistance e = exact_distance(*p.a.shape, p.a.pose(), *p.b.shape, p.b.pose());
    const Separation c = shape_distance(*p.a.shape, p.a.pose(), *p.b.shape, p.b.pose());
    EXPECT_EQ(e.overlapping, p.overlapping) << p.name;
    EXPECT_EQ(c.overlapping, p.overlapping) << p.name;
    if (p.overlapping) continue;
    EXPECT_TRUE(close(e.distance, p.distance, p.distance_rel, p.distance_abs))
        << p.name << ": " << e.distance;
    EXPECT_TRUE(close(c.distance, p.distance, p.distance_rel, p.distance_abs))
        << p.name << ": " << c.distance;
    if (!p.points) continue;
    for (int k = 0; k < 3; ++k) {
      EXPECT_TRUE(close(e.point_a[k], p.point_a[k], p.point_rel, p.point_abs))
          << p.name << " A " << k;
      EXPECT_TRUE(close(e.point_b[k], p.point_b[k], p.point_rel, p.point_abs))
          << p.name << " B " << k;
      EXPECT_TRUE(close(c.point_a[k], p.point_a[k], p.point_rel, p.point_abs))
          << p.name << " A " << k;
      EXPECT_TRUE(close(c.point_b[k], p.point_b[k], p.point_rel, p.point_abs))
          << p.name << " B " << k;
    }
  }
}

TEST(PublishedDistance, EveryDistanceBackendMeasured) {
  // Measured, printed: what the report shows of each library. The one assertion: every backend
  // answers with status ok (an error or a timeout on two boxes would be the adapter's fault).
  for (const Published& p : cases())
    for (const Backend& b : backends()) {
      if (!b.distance) continue;
      const DistanceResult r = b.distance(p.a, p.b);
      EXPECT_EQ(r.status, Status::Ok) << p.name << " " << b.name << ": " << r.message;
      char line[160];
      std::snprintf(line, sizeof line, "%.15g (published %.15g, off by %.2g)", r.distance,
                    p.distance, r.distance - p.distance);
      std::printf("[measured] %-40s %-12s %s\n", p.name.c_str(), b.name.c_str(),
                  r.overlapping ? "overlapping" : line);
    }
}

}  // namespace
}  // namespace rbx
