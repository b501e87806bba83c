// The touch witness (engine/touch_witness.h) answers for the detector near a touch it found: its
// answer must be the detector's wherever it gives one, down to poses within the detector's
// tolerance of the touch, for blunt and sharp shapes, and it must give one often enough to pay.
#include "engine/touch_witness.h"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <random>
#include <vector>

#include "engine/detect.h"
#include "engine/separation.h"
#include "tests/common/fixtures.h"

namespace rbx {
namespace {

using test::random_rotation;
using test::sharp_wedge;

bool any_vertex_inside(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                       const Pose& pb, double tol) {
  for (const Vec3& v : a.vertices())
    if (point_in_mesh(b, pb, pa.apply(v), tol)) return true;
  return false;
}

// A moves toward a fixed B along a straight line while it turns at a constant rate, as a
// time-of-impact search moves a pair; the first touch is found by bisection on the detector, a
// witness taken a little after it, and every answer the witness gives at times around the touch
// (from 1e-12 to 1e-2 of the approach away, either side) is checked against both detectors.
TEST(TouchWitness, EveryAnswerItGivesIsTheDetectors) {
  const std::vector<ConvexPolyhedron> shapes = {
      make_box(Vec3(1.0, 1.0, 1.0)), make_box(Vec3(2.0, 0.3, 0.7)), make_prism(0.6, 1.2, 7),
      make_icosphere(0.5, 1), sharp_wedge()};
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0), exponent(-12.0, -2.0);
  long apart = 0, touching = 0, by_edge = 0, near = 0, open = 0;
  for (int k = 0; k < 1500; ++k) {
    const ConvexPolyhedron& a = shapes[k % shapes.size()];
    const ConvexPolyhedron& b = shapes[(k / shapes.size()) % shapes.size()];
    const double tol = point_in_mesh_tolerance(a, b);
    const double reach = separation_margin(tol, tolerance_reach(a), tolerance_reach(b));
    Pose pb;
    pb.orientation = random_rotation(rng);
    const Vec3 toward = Vec3(u(rng), u(rng), u(rng)).normalized();
    const Vec3 spin = 0.5 * Vec3(u(rng), u(rng), u(rng));
    const Quat q0 = random_rotation(rng);
    const Vec3 start = 3.0 * toward;
    auto pose_a = [&](double s) {
      Pose p;
      p.position = start - s * toward;
      const double angle = spin.norm() * s;
      p.orientation =
          (angle > 0.0 ? Quat(Eigen::AngleAxisd(angle, spin.normalized())) : Quat::Identity()) * q0;
      return p;
    };
    auto detected = [&](double s) { return detect(a, pose_a(s), b, pb, Detector::Accelerated); };
    // The first touch along s in [0, 3]: apart at 0 (3 m off, every shape within 1.1 m of its
    // origin), touching at 3 (the origins meet).
    double lo = 0.0, hi = 3.0;
    if (detected(lo) || !detected(hi)) continue;
    while (hi - lo > 1e-13) (detected(0.5 * (lo + hi)) ? hi : lo) = 0.5 * (lo + hi);
    const double after = hi + std::pow(10.0, exponent(rng));
    const std::optional<ContactPoint> hit = detected(after);
    if (!hit) continue;
    std::optional<TouchWitness> witness = TouchWitness::of(a, pose_a(after), b, pb, *hit);
    ASSERT_TRUE(witness);
    for (int m = 0; m < 40; ++m) {
      const double s = hi + (m % 2 ? 1.0 : -1.0) * std::pow(10.0, exponent(rng));
      const Pose pa = pose_a(s);
      const std::optional<bool> settled = witness->settle(pa, pb, reach, tol);
      if (!settled) {
        ++open;
        continue;
      }
      const bool fast = detect(a, pa, b, pb, Detector::Accelerated).has_value();
      const bool faithful = detect(a, pa, b, pb, Detector::Faithful).has_value();
      EXPECT_EQ(*settled, fast) << "pair " << k << ", sample " << m;
      EXPECT_EQ(*settled, faithful) << "pair " << k << ", sample " << m;
      (*settled ? touching : apart) += 1;
      if (std::abs(s - hi) < 1e-8) ++near;
      if (*settled && !any_vertex_inside(a, pa, b, pb, tol) &&
          !any_vertex_inside(b, pb, a, pa, tol))
        ++by_edge;
    }
  }
  // Not vacuous: both answers, within the detector's tolerance of travel of the touch (1e-9 m at
  // this unit speed) and from edges alone (no vertex inside); and some left to the detector.
  EXPECT_GT(apart, 5000);
  EXPECT_GT(touching, 5000);
  EXPECT_GT(near, 1000);
  EXPECT_GT(by_edge, 200);
  EXPECT_GT(open, 500);
}

}  // namespace
}  // namespace rbx
