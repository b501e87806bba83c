// Contact-law residuals: zero on contacts that obey each law, and each law's residual, alone,
// on an impulse made to violate it; the tally's worst and median.
#include "reference/contact_laws.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace rbx {
namespace {

constexpr int kPen = static_cast<int>(Law::Penetration);
constexpr int kPull = static_cast<int>(Law::Pulling);
constexpr int kComp = static_cast<int>(Law::Complementarity);
constexpr int kCone = static_cast<int>(Law::Cone);
constexpr int kDiss = static_cast<int>(Law::Dissipation);

// A contact on the floor (normal +z), mu = 0.5, e = 0.5, approaching at 2 m/s before the step.
LawInputs floor_contact() {
  LawInputs in;
  in.normal = Vec3::UnitZ();
  in.restitution = 0.5;
  in.friction = 0.5;
  in.v_before = Vec3(0.0, 0.0, -2.0);
  return in;
}

// Every residual but the one named is exactly zero.
void expect_only(const std::array<double, kLaws>& r, int law, double value) {
  for (int l = 0; l < kLaws; ++l)
    if (l == law)
      EXPECT_DOUBLE_EQ(r[l], value) << to_string(kAllLaws[l]);
    else
      EXPECT_EQ(r[l], 0.0) << to_string(kAllLaws[l]);
}

TEST(LawResiduals, AreZeroOnContactsThatObeyTheLaws) {
  // A bounce at Newton's speed (e 2 m/s = 1 m/s), no friction needed.
  LawInputs bounce = floor_contact();
  bounce.impulse = Vec3(0.0, 0.0, 3.0);
  bounce.v_after = Vec3(0.0, 0.0, 1.0);
  for (double r : law_residuals(bounce)) EXPECT_EQ(r, 0.0);
  // Sliding after the step at 2 m/s along +x with friction mu j_n exactly against the slip.
  LawInputs slide = floor_contact();
  slide.v_before = Vec3(2.0, 0.0, 0.0);
  slide.impulse = Vec3(-0.5, 0.0, 1.0);
  slide.v_after = Vec3(2.0, 0.0, 0.0);
  for (double r : law_residuals(slide)) EXPECT_EQ(r, 0.0);
  // Sticking inside the cone: any friction below mu j_n with no slip after.
  LawInputs stick = slide;
  stick.impulse = Vec3(-0.2, 0.1, 1.0);
  stick.v_after = Vec3::Zero();
  for (double r : law_residuals(stick)) EXPECT_EQ(r, 0.0);
  // A separating contact that applies nothing.
  LawInputs apart = floor_contact();
  apart.v_after = Vec3(0.0, 0.0, 5.0);
  for (double r : law_residuals(apart)) EXPECT_EQ(r, 0.0);
}

TEST(LawResiduals, FlagEachViolationAlone) {
  // Penetration: the depth at detection, whatever the impulse did.
  LawInputs deep = floor_contact();
  deep.depth = 1e-3;
  deep.impulse = Vec3(0.0, 0.0, 3.0);
  deep.v_after = Vec3(0.0, 0.0, 1.0);
  expect_only(law_residuals(deep), kPen, 1e-3);
  // Pulling: a negative normal impulse (the bodies then still approach: no push, so no
  // complementarity to score).
  LawInputs pull = floor_contact();
  pull.impulse = Vec3(0.0, 0.0, -0.2);
  pull.v_after = Vec3(0.0, 0.0, -2.2);
  expect_only(law_residuals(pull), kPull, 0.2);
  // Complementarity: pushing to 1.3 m/s where Newton's law gives 1 m/s: 3 N s x 0.3 m/s.
  LawInputs push = floor_contact();
  push.impulse = Vec3(0.0, 0.0, 3.0);
  push.v_after = Vec3(0.0, 0.0, 1.3);
  expect_only(law_residuals(push), kComp, 3.0 * 0.3);
  // Cone: friction 0.7 where mu j_n = 0.5, sticking (no slip after, so nothing to dissipate).
  LawInputs cone = floor_contact();
  cone.v_before = Vec3(1.0, 0.0, 0.0);
  cone.impulse = Vec3(-0.7, 0.0, 1.0);
  cone.v_after = Vec3::Zero();
  expect_only(law_residuals(cone), kCone, 0.2);
  // Dissipation: sliding at 2 m/s along +x with friction inside the cone but across the slip:
  // it removes nothing where mu j_n |v_t| = 1 J was due.
  LawInputs across = floor_contact();
  across.v_before = Vec3(2.0, 0.0, 0.0);
  across.impulse = Vec3(0.0, 0.5, 1.0);
  across.v_after = Vec3(2.0, 0.0, 0.0);
  expect_only(law_residuals(across), kDiss, 1.0);
  // ... and friction pushing along the slip: it adds 1 J and misses 1 J.
  LawInputs along = across;
  along.impulse = Vec3(0.5, 0.0, 1.0);
  expect_only(law_residuals(along), kDiss, 2.0);
}

TEST(LawTally, KeepsTheWorstAndTheMedianWithinItsBin) {
  LawTally tally;
  // Residuals 1, 2, ..., 101 for every law but pulling, which stays zero on all but one.
  for (int i = 1; i <= 101; ++i) {
    std::array<double, kLaws> r{};
    r.fill(static_cast<double>(i));
    r[kPull] = i == 7 ? 1e-3 : 0.0;
    tally.add(r);
  }
  const ContactLaws s = tally.summary();
  EXPECT_TRUE(s.measured);
  EXPECT_EQ(s.contacts, 101);
  EXPECT_EQ(s.residuals[kPen].worst, 101.0);
  // The median is 51; a bin spans 1/100 decade, its centre within 1.2 % of any value in it.
  EXPECT_NEAR(s.residuals[kPen].median, 51.0, 0.012 * 51.0);
  EXPECT_EQ(s.residuals[kPull].worst, 1e-3);
  EXPECT_EQ(s.residuals[kPull].median, 0.0);
  // A non-finite residual is the worst there is.
  std::array<double, kLaws> bad{};
  bad[kCone] = std::numeric_limits<double>::quiet_NaN();
  tally.add(bad);
  EXPECT_TRUE(std::isinf(tally.summary().residuals[kCone].worst));
  // Nothing scored: zeros.
  EXPECT_EQ(LawTally().summary().contacts, 0);
  EXPECT_EQ(LawTally().summary().residuals[kDiss].median, 0.0);
}

}  // namespace
}  // namespace rbx
