// What every time-of-impact query must do (reference/backend.h, ToiResult), run over every
// registered backend and query variant that has one, on closed forms: a cube falling flat onto
// another touches when its fall has closed the gap; the normal, where given, points from B toward
// A and turns round with the body order, which leaves the time alone; a cube moving away never
// touches. Accuracy is held to each library's own stopping rule, read from its source: FCL's
// conservative advancement stops once its next step is under 1e-4 of the interval, Bullet's casts
// once the pair is within 1 mm; custom and the oracle are held to round-off.
#include "comparisons/eval/toi_query.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "reference/backend.h"
#include "reference/exact.h"
#include "tests/common/fixtures.h"

namespace rbx {
namespace {

std::vector<std::string> toi_rows() {
  std::vector<std::string> names;
  for (const Backend& b : backends())
    if (b.toi) names.push_back(b.name);
  std::vector<std::string> rows;
  for (const ToiSubject& s : toi_subjects(names)) rows.push_back(s.name);
  return rows;
}

ToiSubject subject(const std::string& row) {
  const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const Backend& b : backends())
      if (b.toi) n.push_back(b.name);
    return n;
  }();
  for (const ToiSubject& s : toi_subjects(names))
    if (s.name == row) return s;
  ADD_FAILURE() << "no row " << row;
  return {};
}

std::string test_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string s = info.param;
  for (char& c : s)
    if (c == '-' || c == '/') c = '_';
  return s;
}

// How far short of the true time a row may stop, as a fraction of an interval over which the
// pair closes by `travel` (m): its library's stopping rule (file comment), plus round-off.
double allowed_early(const std::string& row, double travel) {
  if (row.rfind("fcl", 0) == 0) return 1e-4;
  if (row.rfind("bullet", 0) == 0) return 1e-3 / travel;
  return 1e-9;  // custom: kSweepTouchRel of the size over the travel; exact: round-off
}

// Unit cubes: B at the origin, A above it by `gap` (m), offset across and turned about z so that
// no two faces are flush; A falls at `speed` (m/s).
std::pair<RigidBody, RigidBody> falling(double gap, double speed) {
  RigidBody a =
      test::unit_cube("A", Vec3(0.2, 0.1, 1.0 + gap), Quat(Eigen::AngleAxisd(0.3, Vec3::UnitZ())));
  a.velocity = Vec3(0, 0, -speed);
  return {a, test::unit_cube("B", Vec3::Zero())};
}

class ToiConformance : public ::testing::TestWithParam<std::string> {};

// btGjkConvexCast misses a landing its first step reaches exactly (measured below, in
// BulletCasts.GjkCastMissesALandingItReachesExactly): in pure translation every landing here is
// one, so the hit tests skip it; its other conventions are held below all the same.
bool misses_exact_landings(const std::string& row) { return row == "bullet-hull/gjk-cast"; }

TEST_P(ToiConformance, AFallingCubeTouchesWhenItsFallClosesTheGap) {
  const ToiSubject s = subject(GetParam());
  if (misses_exact_landings(s.name)) GTEST_SKIP() << "measured in BulletCasts";
  // A falls 1 m over the interval of 0.5 s from 0.3 m above: it lands at 0.3 of the interval.
  const auto [a, b] = falling(0.3, 2.0);
  const ToiResult r = run_toi(s, a, b, 0.5);
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_TRUE(r.hit) << s.name;
  EXPECT_LE(r.fraction, 0.3 + 1e-12) << s.name << ": a query may stop early, never late";
  EXPECT_GE(r.fraction, 0.3 - allowed_early(s.name, 1.0)) << s.name;
  if (r.located) {
    EXPECT_GT(r.normal.z(), 0.5) << s.name << ": the normal points from B toward A (up)";
    EXPECT_NEAR(r.normal.norm(), 1.0, 1e-9) << s.name;
  }
}

TEST_P(ToiConformance, TheOtherBodyOrderTurnsTheNormalAndKeepsTheTime) {
  const ToiSubject s = subject(GetParam());
  if (misses_exact_landings(s.name)) GTEST_SKIP() << "measured in BulletCasts";
  const auto [a, b] = falling(0.3, 2.0);
  const ToiResult ab = run_toi(s, a, b, 0.5), ba = run_toi(s, b, a, 0.5);
  ASSERT_EQ(ab.status, Status::Ok) << ab.message;
  ASSERT_EQ(ba.status, Status::Ok) << ba.message;
  ASSERT_TRUE(ab.hit && ba.hit) << s.name;
  EXPECT_NEAR(ab.fraction, ba.fraction, allowed_early(s.name, 1.0)) << s.name;
  if (ba.located) {
    EXPECT_LT(ba.normal.z(), -0.5) << s.name << ": from A (now B) toward B";
  }
}

TEST_P(ToiConformance, ACubeMovingAwayNeverTouches) {
  const ToiSubject s = subject(GetParam());
  const auto [a, b] = falling(0.3, -2.0);
  const ToiResult r = run_toi(s, a, b, 0.5);
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  EXPECT_FALSE(r.hit) << s.name << " at " << r.fraction;
}

TEST_P(ToiConformance, ACubeFallingPastTheOtherNeverTouches) {
  const ToiSubject s = subject(GetParam());
  auto [a, b] = falling(0.3, 2.0);
  a.position.x() += 1.5;  // beside B: its fall passes 0.5 m clear of B's side
  const ToiResult r = run_toi(s, a, b, 0.5);
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  EXPECT_FALSE(r.hit) << s.name << " at " << r.fraction;
}

INSTANTIATE_TEST_SUITE_P(EveryToiRow, ToiConformance, ::testing::ValuesIn(toi_rows()), test_name);

// With rotation the libraries' and custom's times are held to the oracle's (conservative
// advancement on the exact distance), not a closed form. A cube spinning about a tilted axis
// falls onto a slab: custom within 1e-9 of the interval; the rows that turn the bodies within
// their stopping rules, never late.
TEST(ToiRotating, EveryRowThatTurnsTheBodiesStopsNoLaterThanTheOracle) {
  RigidBody a = test::unit_cube("A", Vec3(0.1, 0.05, 1.6),
                                Quat(Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized())));
  a.velocity = Vec3(0.2, 0, -3);
  a.angular_velocity = Vec3(2, -3, 1);
  const RigidBody b = test::unit_cube("B", Vec3::Zero());
  const ToiResult truth = exact_toi(a, b, 0.5);
  ASSERT_EQ(truth.status, Status::Ok) << truth.message;
  ASSERT_TRUE(truth.hit);
  for (const std::string& row : toi_rows()) {
    if (row == "exact") continue;
    const ToiResult r = run_toi(subject(row), a, b, 0.5);
    if (r.status == Status::Unsupported) {
      EXPECT_NE(row.find("cast"), std::string::npos) << row << ": " << r.message;
      continue;
    }
    ASSERT_EQ(r.status, Status::Ok) << row << ": " << r.message;
    ASSERT_TRUE(r.hit) << row;
    // `bullet`'s btBoxShape is rounded by its margin at edges and corners
    // (BulletSettingsMeasured.BoxMarginRoundsTheDistanceAtCorners): a corner landing comes later,
    // by at most the corner's rounding, (sqrt 3 - 1) 0.04 m, over the 1.5 m closed.
    const double late = row == "bullet" ? (std::sqrt(3.0) - 1) * 0.04 / 1.5 : 1e-9;
    EXPECT_LE(r.fraction, truth.fraction + late) << row;
    // The pair closes by about 1.5 m over the interval (3 m/s for 0.5 s).
    EXPECT_GE(r.fraction, truth.fraction - allowed_early(row, 1.5)) << row;
  }
}

// A set-up variant (shapes built once and kept: "prebuilt") times its backend's own query, so it
// must answer as the backend does, bit for bit, the second call (from its kept shapes) as the
// first: on a falling cube and on a spinning one. It is not a row of rbx toi.
TEST(ToiPrebuilt, APrebuiltVariantAnswersAsItsBackendDoes) {
  RigidBody spun = test::unit_cube("A", Vec3(0.1, 0.05, 1.6),
                                   Quat(Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized())));
  spun.velocity = Vec3(0.2, 0, -3);
  spun.angular_velocity = Vec3(2, -3, 1);
  const RigidBody slab = test::unit_cube("B", Vec3::Zero());
  const auto [fall_a, fall_b] = falling(0.3, 2.0);
  int variants = 0;
  for (const QueryVariant& v : query_variants()) {
    if (!v.toi || !v.contact) continue;
    ++variants;
    for (const ToiSubject& s : toi_subjects({v.backend}))
      EXPECT_NE(s.name, v.backend + "/" + v.variant) << "a set-up variant is not a row";
    const Backend* backend = find_backend(v.backend);
    ASSERT_TRUE(backend && backend->toi) << v.backend;
    for (const auto& [a, b] : {std::pair{fall_a, fall_b}, std::pair{spun, slab}})
      for (int call = 0; call < 2; ++call) {
        const ToiResult own = backend->toi(a, b, 0.5), kept = v.toi(a, b, 0.5);
        ASSERT_EQ(kept.status, own.status) << v.backend << "/" << v.variant << ": " << kept.message;
        EXPECT_EQ(kept.hit, own.hit) << v.backend << "/" << v.variant;
        EXPECT_EQ(kept.fraction, own.fraction) << v.backend << "/" << v.variant;
      }
  }
  EXPECT_GE(variants, 3);  // fcl, fcl-hull, bullet, bullet-hull
}

// Bullet's btGjkConvexCast steps by the distance over the approach speed along GJK's normal; in
// pure translation onto a face that step lands exactly on the touch, where GJK (run without a
// penetration solver and, on zero-margin hulls, without margins) gives no usable normal, and the
// cast's last test, that the motion closes along the normal, fails: it reports no hit.
// btSubsimplexConvexCast on the same shapes and motion finds it.
TEST(BulletCasts, GjkCastMissesALandingItReachesExactly) {
  const auto [a, b] = falling(0.3, 2.0);
  const ToiResult gjk = run_toi(subject("bullet-hull/gjk-cast"), a, b, 0.5);
  const ToiResult subsimplex = run_toi(subject("bullet-hull/subsimplex-cast"), a, b, 0.5);
  ASSERT_EQ(gjk.status, Status::Ok) << gjk.message;
  ASSERT_EQ(subsimplex.status, Status::Ok) << subsimplex.message;
  EXPECT_FALSE(gjk.hit);
  EXPECT_TRUE(subsimplex.hit);
  // Sliding across as it falls, it lands exactly all the same (the step is along the normal),
  // and misses all the same, where the oracle has the touch.
  auto [c, d] = falling(0.3, 2.0);
  c.velocity = Vec3(0.3, 0.0, -2.0);
  const ToiResult oblique = run_toi(subject("bullet-hull/gjk-cast"), c, d, 0.5);
  ASSERT_EQ(oblique.status, Status::Ok) << oblique.message;
  EXPECT_FALSE(oblique.hit);
  EXPECT_TRUE(exact_toi(c, d, 0.5).hit);
}

}  // namespace
}  // namespace rbx
