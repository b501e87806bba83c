// The exact time of impact under translation (reference/exact_time_of_impact.cpp) on closed
// forms derived by hand, and `custom`'s time of impact (engine/time_of_impact.h) against it on
// random translating pairs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <utility>

#include "engine/settings.h"
#include "engine/time_of_impact.h"
#include "reference/exact.h"
#include "tests/common/fixtures.h"

namespace rbx {
namespace {

using test::at;

// Round-off of a quotient of unit-scale projections (~1e-16 each) over speeds of order 1: 1e-12
// leaves a wide margin and still catches a wrong axis (the times here differ by >= 0.05 s).
constexpr double kQuotientRoundOff = 1e-12;

TEST(ExactTranslationImpact, ClosedForms) {
  const ConvexPolyhedron cube = make_box(Vec3::Ones());
  // Face to face: B 0.5 m beyond A's +x face, closing at 2 m/s (A at +0.5, B at -1.5): the gap
  // closes at t = 0.5 / 2 = 0.25 s, normal from B toward A -x.
  ExactImpact hit = exact_translation_impact(cube, at(Vec3::Zero()), Vec3(0.5, 0, 0), cube,
                                             at(Vec3(1.5, 0, 0)), Vec3(-1.5, 0, 0), 1.0);
  ASSERT_TRUE(hit.time);
  EXPECT_NEAR(*hit.time, 0.25, kQuotientRoundOff);
  EXPECT_NEAR((hit.normal - Vec3(-1, 0, 0)).norm(), 0.0, kQuotientRoundOff);
  // The same within dt = 0.2 s: no contact yet.
  EXPECT_FALSE(exact_translation_impact(cube, at(Vec3::Zero()), Vec3(0.5, 0, 0), cube,
                                        at(Vec3(1.5, 0, 0)), Vec3(-1.5, 0, 0), 0.2)
                   .time);
  // Passing by: B 2 m up in z moves along -x under A, its path 1 m clear of A's top (z 0.5 to
  // 1.5 against A's up to 0.5): never, whatever dt.
  EXPECT_FALSE(exact_translation_impact(cube, at(Vec3::Zero()), Vec3::Zero(), cube,
                                        at(Vec3(3, 0, 2)), Vec3(-10, 0, 0), 10.0)
                   .time);
  // Edges: A turned 45 deg about z (its edge at x = sqrt(2)/2 along z), B turned 45 deg about y
  // (its edge at x = c - sqrt(2)/2 along y), 0.3 m apart, B closing at 1 m/s along -x: 0.3 s,
  // along -x.
  const double c = std::sqrt(2.0) + 0.3;
  hit = exact_translation_impact(
      cube, at(Vec3::Zero(), Quat(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitZ()))), Vec3::Zero(), cube,
      at(Vec3(c, 0, 0), Quat(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitY()))), Vec3(-1, 0, 0), 1.0);
  ASSERT_TRUE(hit.time);
  EXPECT_NEAR(*hit.time, 0.3, kQuotientRoundOff);
  EXPECT_NEAR((hit.normal - Vec3(-1, 0, 0)).norm(), 0.0, 1e-9);
  // Overlapping at the start: 0.
  hit = exact_translation_impact(cube, at(Vec3::Zero()), Vec3::Zero(), cube, at(Vec3(0.9, 0, 0)),
                                 Vec3(1, 0, 0), 1.0);
  ASSERT_TRUE(hit.time);
  EXPECT_EQ(*hit.time, 0.0);
}

RigidBody moving(const ConvexPolyhedron& shape, const Pose& p, const Vec3& v) {
  RigidBody b;
  b.shape_kind = ShapeKind::Convex;
  b.shape = std::make_shared<const ConvexPolyhedron>(shape);
  b.position = p.position;
  b.orientation = p.orientation;
  b.velocity = v;
  return b;
}

// custom's time of impact against the oracle on `trials` random translating pairs from `seed`,
// a share `skimming` of them with a sideways drift of 50 m/s (else `drift`, m/s); returns the
// hits and misses.
std::pair<int, int> compare_on_random_pairs(uint64_t seed, int trials, double skimming,
                                            double drift) {
  // Boxes, icospheres and prisms at random turns, B set apart from A along a random direction by
  // up to half a size beyond touching and sent back toward A, to arrive at a random fraction of
  // 1.2 steps (so about one in six arrives too late), with a sideways drift; A drifts too. The step
  // is 10 ms. custom samples the detector in time; its detector counts a pair as touching within
  // its tolerance (engine/detect.h: 1e-9 of the larger size), reached up to that tolerance over
  // the closing speed early, and it bisects until the pair travels no more than that tolerance
  // (or 1e-12 of the step), at most that late. So a hit agrees within 1e-12 dt + 2e-9 size /
  // (closing speed along the normal). Every draw in a statement of its own: C++ leaves
  // the order of the draws within one expression unspecified, and the pairs must be the same under
  // every compiler.
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  auto unit = [&]() { return uniform(rng); };
  auto vec = [&]() {
    const double x = normal(rng), y = normal(rng);
    return Vec3(x, y, normal(rng));
  };
  auto shape = [&]() {
    const int kind = static_cast<int>(unit() * 3);
    const double p = unit(), q = unit(), r = unit();
    if (kind == 0) return make_box(Vec3(0.2 + p, 0.2 + q, 0.2 + r));
    if (kind == 1) return make_icosphere(0.3 + p, 1);
    return make_prism(0.3 + p, 0.2 + q, 3 + static_cast<int>(r * 10));
  };
  auto turn = [&]() {
    const double w = normal(rng);
    const Vec3 xyz = vec();
    return Quat(w, xyz.x(), xyz.y(), xyz.z()).normalized();
  };
  const double dt = 0.01;
  int hits = 0, misses = 0;
  double worst = 0.0;
  for (int trial = 0; trial < trials; ++trial) {
    const ConvexPolyhedron sa = shape(), sb = shape();
    const Vec3 at_a = vec();
    const Pose pa = at(at_a, turn());
    const Quat qb = turn();
    const Vec3 dir = vec().normalized();
    const double size = std::max(shape_size(sa), shape_size(sb));
    double lo = 0.0, hi = 2.0 * size;  // overlapping at lo, apart at hi
    for (int it = 0; it < 40; ++it) {
      const double mid = 0.5 * (lo + hi);
      (sat_query(sa, pa, sb, at(pa.position + mid * dir, qb)).touching ? lo : hi) = mid;
    }
    const double gap = size * 0.5 * unit() + 1e-3 * size;
    const Pose pb = at(pa.position + (hi + gap) * dir, qb);
    const Vec3 va = vec();
    const Vec3 side = vec();
    const double arrival = unit() * 1.2 * dt + 1e-4;
    const double skim_draw = unit();
    const Vec3 vb = va - (gap / arrival) * dir + (skim_draw < skimming ? 50.0 : drift) * side;
    const ExactImpact truth = exact_translation_impact(sa, pa, va, sb, pb, vb, dt);
    const TimeOfImpact ours =
        time_of_impact(moving(sa, pa, va), moving(sb, pb, vb), dt, Detector::Accelerated,
                       WorldSettings{}.toi_max_samples);
    EXPECT_TRUE(ours.certified) << trial;
    EXPECT_EQ(ours.time.has_value(), truth.time.has_value())
        << trial << ": custom " << (ours.time ? *ours.time : -1.0) << ", exact "
        << (truth.time ? *truth.time : -1.0);
    if (!truth.time || !ours.time) {
      ++misses;
      continue;
    }
    ++hits;
    const double closing = std::abs((vb - va).dot(truth.normal));
    const double bound = 1e-12 * dt + 2e-9 * size / closing;
    EXPECT_NEAR(*ours.time, *truth.time, bound) << trial;
    worst = std::max(worst, std::abs(*ours.time - *truth.time) / bound);
  }
  std::printf(
      "[measured] %d hits, %d misses: custom's time against the exact one, worst %.3g "
      "of its bound\n",
      hits, misses, worst);
  return {hits, misses};
}

TEST(ExactTranslationImpact, CustomAgreesOnRandomApproaches) {
  const auto [hits, misses] = compare_on_random_pairs(4812, 400, 0.0, 3.0);
  EXPECT_GT(hits, 200);
  EXPECT_GT(misses, 20);
}

TEST(ExactTranslationImpact, CustomSeesAFastSkimBetweenItsSamples) {
  // A triangular prism and a box skimming past each other at 60 m/s relative: pair 1727 of the
  // random pairs from seed 11 with three in ten drifting sideways at 50 m/s, its numbers written
  // out (the prism's radius and half height, the box's half extents). A corner clips the other
  // body for less than a quarter of the prism's thickness of travel, the spacing of custom's
  // samples, so no sample sees it. The oracle: first contact at 3.36 ms of the 10 ms step.
  // custom reported no contact until each interval between samples was certified by the
  // distance (engine/time_of_impact.cpp).
  const ConvexPolyhedron sa = make_prism(0.37629266059827682, 2 * 0.17781077512698107, 3);
  const ConvexPolyhedron sb =
      make_box(2 * Vec3(0.26505820958769311, 0.444778198337622, 0.25076218413961021));
  const Pose pa = at(
      Vec3(-0.31139526458603389, 1.6140504005490004, 1.9825602921693033),
      Quat(0.15112745554539009, 0.098325302386189292, 0.77348897840595032, -0.60762441308390491));
  const Pose pb = at(
      Vec3(-0.14935573721306591, 1.7102503711070789, 1.1258254370973395),
      Quat(0.85452954116066737, -0.38703500527324419, -0.30980256580799365, 0.15493720726688931));
  const Vec3 va(0.37393648978311184, 0.76268791094400368, -1.5920974401733419);
  const Vec3 vb(43.050796490725872, -34.04404273938691, 12.402013529075706);
  const double dt = 0.01;
  const ExactImpact truth = exact_translation_impact(sa, pa, va, sb, pb, vb, dt);
  ASSERT_TRUE(truth.time);
  EXPECT_NEAR(*truth.time, 0.0033595156251725131, 1e-15);
  // How deep the skim goes: the deepest overlap over the step, sampled every 10 microseconds.
  double deepest = 0.0;
  for (int k = 0; k <= 1000; ++k) {
    const double t = dt * k / 1000;
    deepest = std::max(deepest, sat_query(sa, at(pa.position + t * va, pa.orientation), sb,
                                          at(pb.position + t * vb, pb.orientation))
                                    .depth);
  }
  EXPECT_GT(deepest, 0.0);
  const TimeOfImpact ours = time_of_impact(moving(sa, pa, va), moving(sb, pb, vb), dt,
                                           Detector::Accelerated, WorldSettings{}.toi_max_samples);
  ASSERT_TRUE(ours.certified);
  ASSERT_TRUE(ours.time);
  const double size = std::max(shape_size(sa), shape_size(sb));
  EXPECT_NEAR(*ours.time, *truth.time,
              1e-12 * dt + 2e-9 * size / std::abs((vb - va).dot(truth.normal)));
  std::printf("[measured] skim: exact %.9g s, custom %.9g s, deepest overlap %.3g m\n", *truth.time,
              *ours.time, deepest);
}

}  // namespace
}  // namespace rbx

namespace rbx {
namespace {

// The oracle with rotation (exact_toi: conservative advancement on the exact distance) on the
// turning rod of tests/engine/sweep_test.cpp: the same closed form, to 1e-12 of the size over the
// closing speed (0.88 m/s).
TEST(ExactToi, ATurningRodsCornerMeetsAFaceAtTheClosedFormTime) {
  RigidBody rod, cube;
  rod.name = "A";
  rod.shape = std::make_shared<ConvexPolyhedron>(make_box(Vec3(2.0, 0.1, 0.1)));
  rod.angular_velocity = Vec3(0, 0, 2.0);
  cube.name = "B";
  cube.shape = std::make_shared<ConvexPolyhedron>(make_box(Vec3::Ones()));
  cube.position = Vec3(0, 1.4, 0);
  const double radius = std::hypot(1.0, 0.05), phi = std::atan2(0.05, 1.0);
  const double t_star = (std::asin(0.9 / radius) - phi) / 2.0;
  const ToiResult r = exact_toi(rod, cube, 1.0);
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_TRUE(r.hit);
  EXPECT_LE(r.fraction, t_star + 1e-14);
  EXPECT_GE(r.fraction, t_star - 1e-11);
  ASSERT_TRUE(r.located);
  EXPECT_LT((r.normal - Vec3(0, -1, 0)).norm(), 1e-6);
  // The same pair the other way round: the normal turns, the time stays.
  const ToiResult swapped = exact_toi(cube, rod, 1.0);
  EXPECT_EQ(swapped.fraction, r.fraction);
  EXPECT_LT((swapped.normal - Vec3(0, 1, 0)).norm(), 1e-6);
}

// In pure translation the oracle's time is exact_translation_impact's, as a fraction of dt.
TEST(ExactToi, InPureTranslationTheTimeIsTheClosedForm) {
  RigidBody a, b;
  a.shape = b.shape = std::make_shared<ConvexPolyhedron>(make_box(Vec3::Ones()));
  a.position = Vec3(0.2, 0.1, 1.3);
  a.velocity = Vec3(0, 0, -2);
  const ToiResult r = exact_toi(a, b, 0.5);
  ASSERT_TRUE(r.hit);
  EXPECT_NEAR(r.fraction, 0.3, 1e-15);
  ASSERT_TRUE(r.located);
  EXPECT_LT((r.normal - Vec3::UnitZ()).norm(), 1e-15);
  a.velocity = -a.velocity;
  EXPECT_FALSE(exact_toi(a, b, 0.5).hit);
}

}  // namespace
}  // namespace rbx
