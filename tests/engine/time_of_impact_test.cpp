// Time of impact on the detector, and the extended world's step: resting, no tunnelling.
#include "engine/time_of_impact.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <utility>

#include "engine/distance.h"
#include "engine/separation.h"
#include "engine/world.h"
#include "tests/common/fixtures.h"

namespace rbx {
namespace {

using test::box_body;

// The extended world's sample limit (WorldSettings::toi_max_samples).
const long kSamples = WorldSettings().toi_max_samples;

RigidBody plate(double dt_unused = 0) {
  (void)dt_unused;
  return box_body("A", Vec3(0.01, 1, 1), 1.0, Vec3(-0.3, 0, 0), Quat::Identity(), Vec3(100, 0, 0));
}
RigidBody wall() {
  return box_body("B", Vec3(0.01, 2, 2), 1.0, Vec3(1, 0, 0), Quat::Identity(), Vec3::Zero(),
                  Vec3::Zero(), true);
}

TEST(TimeOfImpact, ThinPlateMeetsThinWallAtTheClosedFormTime) {
  // stress/tunnel_thin_wall: front face -0.295 + 100 t meets 0.995 at t = 0.0129 s; the step
  // 0.02 s starts separated and ends past the wall.
  const TimeOfImpact hit = time_of_impact(plate(), wall(), 0.02, Detector::Faithful, kSamples);
  ASSERT_TRUE(hit.certified);
  ASSERT_TRUE(hit.time);
  const double t = *hit.time;
  // The detector's touching tolerance (1e-9 of the size, 2e-11 s at 100 m/s), once for where it
  // first calls the pair touching and once more for the bisection, which stops within that
  // tolerance of travel.
  EXPECT_NEAR(t, 0.0129, 1e-10);
  const TimeOfImpact miss = time_of_impact(plate(), wall(), 0.012, Detector::Faithful, kSamples);
  EXPECT_TRUE(miss.certified);
  EXPECT_FALSE(miss.time);
}

// A unit cube falling at 2.99e8 m/s (just under the loader's speed limit, the speed of light)
// onto a 1 cm slab 100 km below, in a step of 1 ms: a grid of quarter-thickness samples would
// take 1.2e11 samples, so the search steps by the gap along a separating axis instead and meets
// the closed-form time.
TEST(TimeOfImpact, AFallAtTheSpeedLimitIsCaughtAtItsClosedFormTime) {
  const double v = 2.99e8, drop = 1e5;
  const RigidBody cube =
      box_body("cube", Vec3::Ones(), 1.0, Vec3(0, 0, 0.5 + drop), Quat::Identity(), Vec3(0, 0, -v));
  const RigidBody slab = box_body("slab", Vec3(4, 4, 0.01), 1.0, Vec3(0, 0, -0.005),
                                  Quat::Identity(), Vec3::Zero(), Vec3::Zero(), true);
  for (const double dt : {1e-3, 1.0}) {
    const TimeOfImpact hit = time_of_impact(cube, slab, dt, Detector::Accelerated, 100);
    ASSERT_TRUE(hit.certified) << "dt " << dt;
    ASSERT_TRUE(hit.time) << "dt " << dt;
    // Bisection to 1e-12 of dt (longer than the detector's tolerance of travel here: 1e-9 of
    // the size, 3e-18 s at this speed, which also bounds where it first calls the pair
    // touching) and the round-off of a position 1e5 m from the origin (1.5e-11 m, 5e-20 s).
    EXPECT_NEAR(*hit.time, drop / v, 1e-12 * dt + 1e-17) << "dt " << dt;
  }
  // The extended world bounces it (e = 1): one collision, the velocity reversed to round-off.
  SimSettings sim;
  sim.dt = 1e-3;
  sim.duration = 0.002;
  World world(sim, {cube, slab}, ContactModel::Extended);
  const RunResult r = world.run();
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.events.size(), 1u);
  EXPECT_NEAR(r.bodies[0].velocity.z(), v, 1e-12 * v);
}

// A thin plate skimming 0.1 mm over a floor 1 km wide (the detector's touching tolerance there
// is 1.4 micrometres) at 1e8 m/s: the gap proves nothing, so the
// search is left with quarter-thickness steps, more than it may take; it says it is not
// certified, and the world's run stops on it, naming the pair, instead of passing the step.
TEST(TimeOfImpact, ASearchPastItsSampleLimitIsNotCertified) {
  const RigidBody plate_over = box_body("plate", Vec3(1, 1, 0.01), 1.0, Vec3(0, 0, 0.005 + 1e-4),
                                        Quat::Identity(), Vec3(1e8, 0, 0));
  const RigidBody floor = box_body("floor", Vec3(1e3, 1e3, 1), 1.0, Vec3(0, 0, -0.5),
                                   Quat::Identity(), Vec3::Zero(), Vec3::Zero(), true);
  const TimeOfImpact hit = time_of_impact(plate_over, floor, 1e-3, Detector::Accelerated, 100);
  EXPECT_FALSE(hit.certified);
  EXPECT_FALSE(hit.time);
  // Over a step of 1 ns (0.1 m, 40 quarter thicknesses of the plate) the search is within its
  // limit: certified, no touch.
  const TimeOfImpact short_step =
      time_of_impact(plate_over, floor, 1e-9, Detector::Accelerated, 100);
  EXPECT_TRUE(short_step.certified);
  EXPECT_FALSE(short_step.time);

  SimSettings sim;
  sim.dt = 1e-3;
  sim.duration = 0.01;
  WorldSettings tunables;
  tunables.toi_max_samples = 100;
  World world(sim, {plate_over, floor}, ContactModel::Extended, Detector::Accelerated,
              BroadPhaseMethod::Tree, tunables);
  const RunResult r = world.run();
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.steps_taken, 1);
  EXPECT_NE(r.message.find("time of impact of bodies plate and floor not certified at step 1"),
            std::string::npos)
      << r.message;
}

TEST(TimeOfImpact, ThicknessIsTheThinnestWidth) {
  EXPECT_NEAR(shape_thickness(make_box(Vec3(0.01, 1, 2))), 0.01, 1e-15);
}

// The travel bound the extended step skips its look-ahead test by: no vertex of a fast-spinning
// body of any inertia moves farther under advanced(); and advanced() given the principal frame is
// the same move, bit for bit, as computing the frame itself.
TEST(TimeOfImpact, NoPointTravelsFartherThanTheTravelBound) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0), size(0.05, 2.0);
  double tightest = 0.0;  // the largest displacement / bound seen: the bound is not vacuous
  for (int k = 0; k < 300; ++k) {
    const Vec3 extent(size(rng), size(rng), size(rng));
    const Quat q = Quat(u(rng), u(rng), u(rng), u(rng)).normalized();
    const RigidBody b =
        test::box_body("b", extent, 1.0 + 9.0 * (u(rng) + 1.0), Vec3(u(rng), u(rng), u(rng)), q,
                       5.0 * Vec3(u(rng), u(rng), u(rng)), 50.0 * Vec3(u(rng), u(rng), u(rng)));
    const PrincipalFrame frame = principal_frame(b.inertia_body);
    double radius = 0.0;
    for (const Vec3& v : b.shape->vertices()) radius = std::max(radius, v.norm());
    for (const double t : {1e-4, 1e-3, 2e-2}) {
      const RigidBody moved = advanced(b, t, &frame), plain = advanced(b, t);
      EXPECT_EQ(moved.orientation.coeffs(), plain.orientation.coeffs());
      EXPECT_EQ(moved.position, plain.position);
      EXPECT_EQ(moved.angular_velocity, plain.angular_velocity);
      const double bound = travel_bound(b, free_turn_rate(frame), radius, t);
      for (const Vec3& v : b.shape->vertices()) {
        const double d = (moved.pose().apply(v) - b.pose().apply(v)).norm();
        // 1e-12 of the bound: the round-off of the two placements.
        EXPECT_LE(d, bound * (1.0 + 1e-12)) << "body " << k << " t " << t;
        tightest = std::max(tightest, d / bound);
      }
    }
  }
  EXPECT_GT(tightest, 0.2);
}

// Two random boxes passing close by (B's centre within 1.6 m of A's along each axis), at speeds up
// to 17 m/s and turn rates up to 35 rad/s: fast enough to skim each other within a step of
// 0.05 s.
std::pair<RigidBody, RigidBody> skimming_pair(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), size(0.3, 1.5);
  auto random_quat = [&] { return Quat(u(rng), u(rng), u(rng), u(rng)).normalized(); };
  RigidBody a =
      box_body("a", Vec3(size(rng), size(rng), size(rng)), 1.0, Vec3::Zero(), random_quat(),
               10.0 * Vec3(u(rng), u(rng), u(rng)), 20.0 * Vec3(u(rng), u(rng), u(rng)));
  RigidBody b = box_body("b", Vec3(size(rng), size(rng), size(rng)), 2.0,
                         1.6 * Vec3(u(rng), u(rng), u(rng)), random_quat(),
                         10.0 * Vec3(u(rng), u(rng), u(rng)), 20.0 * Vec3(u(rng), u(rng), u(rng)));
  return {std::move(a), std::move(b)};
}

// The certificate the extended step skips a search by (apart_through): wherever a gap at each
// end of the step proves a pair apart all through it, the search itself finds no touch. Random
// boxes passing close by, fast enough to skim each other within a step (apart at both ends, a
// corner clipping between), so both answers occur.
TEST(TimeOfImpact, GapsAtBothEndsProveAStepApartOnlyWhereTheSearchFindsNoTouch) {
  std::mt19937_64 rng(29);
  const double dt = 0.05;
  auto gap_between = [](const RigidBody& a, const RigidBody& b) -> std::optional<GapAlong> {
    const Separation s = shape_distance(*a.shape, a.pose(), *b.shape, b.pose());
    if (s.overlapping) return std::nullopt;
    const Vec3 d = (s.point_a - s.point_b) / s.distance;
    return GapAlong{d, gap_along(*a.shape, a.pose(), *b.shape, b.pose(), d)};
  };
  int proved = 0, skims = 0;
  for (int k = 0; k < 4000; ++k) {
    const auto [a, b] = skimming_pair(rng);
    const BodyFacts fa = BodyFacts::of(a), fb = BodyFacts::of(b);
    const double margin = separation_margin(std::max(fa.own_tol, fb.own_tol), fa.reach, fb.reach);
    const std::optional<GapAlong> start = gap_between(a, b);
    const std::optional<GapAlong> end =
        gap_between(advanced(a, dt, &fa.principal), advanced(b, dt, &fb.principal));
    if (!start || !end || !(start->gap > margin) || !(end->gap > margin)) continue;
    const TimeOfImpact search = time_of_impact(a, b, dt, Detector::Accelerated, kSamples);
    ASSERT_TRUE(search.certified) << "pair " << k;
    if (apart_through(a, b, fa, fb, *start, *end, margin, dt)) {
      ++proved;
      EXPECT_FALSE(search.time) << "pair " << k << " touches at " << *search.time;
    } else if (search.time) {
      ++skims;
    }
  }
  // Both kinds of pair occur: the certificate is not vacuous, nor are the skims it must not hide.
  EXPECT_GT(proved, 100);
  EXPECT_GT(skims, 10);
}

// The extended world, every step size of the thin wall's dt study: the plate bounces at -100 m/s.
TEST(ExtendedWorld, ThinWallNeverTunnels) {
  for (double dt : {1e-2, 5e-3, 1e-3, 2e-4, 1e-4, 5e-5}) {
    SimSettings sim;
    sim.dt = dt;
    sim.duration = 0.05;
    World world(sim, {plate(), wall()}, ContactModel::Extended);
    const RunResult r = world.run();
    ASSERT_TRUE(r.ok) << r.message;
    EXPECT_NEAR(r.bodies[0].velocity.x(), -100.0, 1e-9) << "dt " << dt;
    EXPECT_LT(r.bodies[0].position.x(), 0.995) << "dt " << dt;
  }
}

// A three-cube stack rests: no sinking past 0.1 % of a body, no jitter past 1e-3 m/s, and the
// total energy never grows at any step (the position projection adds none).
TEST(ExtendedWorld, StackRestsWithoutAddingEnergy) {
  SimSettings sim;
  sim.gravity = Vec3(0, 0, -9.81);
  sim.restitution = 0.0;
  sim.friction = 0.5;
  std::vector<RigidBody> bodies = {box_body("floor", Vec3(4, 4, 1), 1.0, Vec3(0, 0, -0.5),
                                            Quat::Identity(), Vec3::Zero(), Vec3::Zero(), true)};
  for (int k = 0; k < 3; ++k)
    bodies.push_back(box_body("box", Vec3::Ones(), 1.0, Vec3(0, 0, 0.5 + k)));
  World world(sim, bodies, ContactModel::Extended);
  const double e0 = world.energy();
  for (int step = 0; step < 2000; ++step) {
    ASSERT_TRUE(world.step());
    ASSERT_LE(world.energy(), e0 + 1e-12 * std::abs(e0)) << "step " << step;
  }
  for (int k = 1; k <= 3; ++k) {
    EXPECT_LT(std::abs(world.bodies()[k].position.z() - (k - 0.5)), 1e-3);
    EXPECT_LT(world.bodies()[k].velocity.norm(), 1e-3);
  }
}

// A cube dropped from 0.5 m onto the floor with e = 0.5 and friction: the energy only falls.
TEST(ExtendedWorld, DropNeverGainsEnergy) {
  SimSettings sim;
  sim.gravity = Vec3(0, 0, -9.81);
  sim.restitution = 0.5;
  sim.friction = 0.4;
  World world(sim,
              {box_body("floor", Vec3(10, 10, 1), 1.0, Vec3(0, 0, -0.5), Quat::Identity(),
                        Vec3::Zero(), Vec3::Zero(), true),
               box_body("cube", Vec3::Ones(), 1.0, Vec3(0, 0, 1.2),
                        Quat(Eigen::AngleAxisd(0.3, Vec3(1, 2, 0).normalized())), Vec3(1, 0, 0),
                        Vec3(0, 0, 2))},
              ContactModel::Extended);
  double previous = world.energy();
  for (int step = 0; step < 3000; ++step) {
    ASSERT_TRUE(world.step());
    // A step may lift a body out of penetration by at most the projection (< 1 mm): m g 1e-3.
    EXPECT_LE(world.energy(), previous + 9.81e-3) << "step " << step;
    previous = std::min(previous, world.energy());
  }
  EXPECT_LT(world.bodies()[1].velocity.norm(), 1e-3);  // at rest in the end
}

TEST(TimeOfImpact, AnAdvancedPoseIsTheAdvancedBodysPoseBitForBit) {
  // The search moves poses without copying bodies: the same numbers as advanced().
  for (const Vec3& size : {Vec3(0.2, 0.2, 0.2), Vec3(1, 2, 3)}) {
    RigidBody b = box_body("b", size, 2, Vec3(0.1, -0.2, 0.3),
                           Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized())),
                           Vec3(1, -2, 0.5), Vec3(3, 0.4, -7));
    const PrincipalFrame f = principal_frame(b.inertia_body);
    for (double t : {0.0, 1e-3, 0.37}) {
      for (const PrincipalFrame* frame : {static_cast<const PrincipalFrame*>(nullptr), &f}) {
        const Pose p = advanced_pose(b, t, frame), q = advanced(b, t, frame).pose();
        EXPECT_EQ(p.position, q.position);
        EXPECT_EQ(p.orientation.coeffs(), q.orientation.coeffs());
      }
    }
  }
}

// The distance at the step's end handed to the search (what the extended step took to try to
// prove the pair apart) is the search's own sample there: every answer stays the same, touching
// pairs, skims and misses alike.
TEST(TimeOfImpact, TheEndsDistanceHandedOverLeavesTheAnswerAsItIs) {
  std::mt19937_64 rng(31);
  const double dt = 0.05;
  int hits = 0;
  for (int k = 0; k < 600; ++k) {
    const auto [a, b] = skimming_pair(rng);
    const BodyFacts fa = BodyFacts::of(a), fb = BodyFacts::of(b);
    const RigidBody a1 = advanced(a, dt, &fa.principal), b1 = advanced(b, dt, &fb.principal);
    const Separation end = shape_distance(*a1.shape, a1.pose(), *b1.shape, b1.pose());
    const TimeOfImpact own = time_of_impact(a, b, dt, Detector::Accelerated, kSamples, &fa, &fb);
    const TimeOfImpact handed =
        time_of_impact(a, b, dt, Detector::Accelerated, kSamples, &fa, &fb, nullptr, &end);
    EXPECT_EQ(own.certified, handed.certified) << "pair " << k;
    ASSERT_EQ(own.time.has_value(), handed.time.has_value()) << "pair " << k;
    if (!own.time) continue;
    ++hits;
    EXPECT_TRUE(test::same_bits(*own.time, *handed.time)) << "pair " << k;
  }
  EXPECT_GT(hits, 50);
}

}  // namespace
}  // namespace rbx
