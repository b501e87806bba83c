// The harness's metric functions against hand-computed cases: the kinetic-energy-norm velocity
// error, the energy rule, the distance to a contact region, touch agreement and the stability
// verdict rules.
#include "comparisons/eval/metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>

#include "comparisons/scene/scene_file.h"
#include "reference/backend.h"

namespace rbx {
namespace {

// Bodies of a scene written inline (the scene parser builds shapes and mass properties).
std::vector<RigidBody> bodies_of(const std::string& toml) {
  return make_bodies(parse_scene(toml, "metrics_test.toml"));
}

BodyFinal final_state(const RigidBody& b, const Vec3& v, const Vec3& w = Vec3::Zero()) {
  return {b.name, b.position, b.orientation, v, w};
}

// Round-off of a handful of double operations on numbers of order 1.
constexpr double kRoundOff = 1e-14;

TEST(KeNormError, TwoBodiesByHand) {
  // A: unit cube, 1 kg. B: 1 x 2 x 3 box, 6 kg, turned 90 deg about z, so its body inertia
  // m/12 diag(b^2 + c^2, a^2 + c^2, a^2 + b^2) = diag(6.5, 5, 2.5) becomes diag(5, 6.5, 2.5)
  // in the world frame.
  const auto in = bodies_of(
      "[[body]]\nname = \"A\"\n"
      "[[body]]\nname = \"B\"\nmass = 6\nsize = [1, 2, 3]\nrotation = [0, 0, 90]\n"
      "position = [3, 0, 0]\n");
  const std::vector<BodyFinal> fin = {final_state(in[0], {-1.0, 0, 0}),
                                      final_state(in[1], {-0.5, 0, 0}, {1.0, 0, 0})};
  const std::vector<std::optional<RefState>> ref = {RefState{Vec3(-1.25, 0, 0), Vec3::Zero()},
                                                    RefState{Vec3(-0.25, 0, 0), Vec3::Zero()}};
  // num = 1 * 0.25^2 + 6 * 0.25^2 + (1, 0, 0).I_world.(1, 0, 0) = 0.0625 + 0.375 + 5 = 5.4375
  // E_ref = 0.5 * 1 * 1.25^2 + 0.5 * 6 * 0.25^2 = 0.78125 + 0.1875 = 0.96875
  // error = sqrt(5.4375 / (2 * 0.96875)) = sqrt(2.806451...)
  const double want = std::sqrt(5.4375 / 1.9375);
  EXPECT_NEAR(ke_norm_error(in, fin, ref, 1.0), want, kRoundOff * want);
}

TEST(KeNormError, OnlyBodiesAndQuantitiesInTheReferenceCount) {
  const auto in =
      bodies_of("[[body]]\nname = \"A\"\n[[body]]\nname = \"B\"\nposition = [3, 0, 0]\n");
  const std::vector<BodyFinal> fin = {final_state(in[0], {2.0, 0, 0}, {0, 0, 7.0}),
                                      final_state(in[1], {5.0, 0, 0})};
  // Only A's velocity is referenced: B and A's spin do not count. num = 1, E_ref = 0.5 * 9.
  const std::vector<std::optional<RefState>> ref = {RefState{Vec3(3.0, 0, 0), std::nullopt},
                                                    std::nullopt};
  EXPECT_NEAR(ke_norm_error(in, fin, ref, 1.0), std::sqrt(1.0 / 9.0), kRoundOff);
}

TEST(KeNormError, ReferenceAtRestFallsBackToTheInitialEnergy) {
  const auto in = bodies_of("[[body]]\nname = \"A\"\n");
  const std::vector<BodyFinal> fin = {final_state(in[0], {0.5, 0, 0})};
  const std::vector<std::optional<RefState>> ref = {RefState{Vec3::Zero(), Vec3::Zero()}};
  // num = 0.25; E_ref = 0 -> fallback 2 J: sqrt(0.25 / 4) = 0.25.
  EXPECT_NEAR(ke_norm_error(in, fin, ref, 2.0), 0.25, kRoundOff);
}

TEST(KeNormError, StaticBodiesNeverCount) {
  const auto in = bodies_of(
      "[[body]]\nname = \"A\"\nstatic = true\n[[body]]\nname = \"B\"\n"
      "position = [3, 0, 0]\n");
  const std::vector<BodyFinal> fin = {final_state(in[0], {9.0, 0, 0}),
                                      final_state(in[1], {1.0, 0, 0})};
  const std::vector<std::optional<RefState>> ref = {RefState{Vec3::Zero(), Vec3::Zero()},
                                                    RefState{Vec3(1.0, 0, 0), Vec3::Zero()}};
  EXPECT_EQ(ke_norm_error(in, fin, ref, 1.0), 0.0);
}

TEST(EnergyError, InvariantRuleWithoutAClosedForm) {
  // e = 1: a loss of 0.2 of the scale is an error of 0.2; a gain likewise.
  EXPECT_NEAR(energy_error(10.0, 8.0, 8.0, std::nullopt, 1.0, 10.0).value, 0.2, kRoundOff);
  EXPECT_NEAR(energy_error(10.0, 12.0, 12.0, std::nullopt, 1.0, 10.0).value, 0.2, kRoundOff);
  // e < 1: a loss is allowed, a gain is not.
  EXPECT_EQ(energy_error(10.0, 8.0, 8.0, std::nullopt, 0.5, 10.0).value, 0.0);
  EXPECT_NEAR(energy_error(10.0, 11.0, 11.0, std::nullopt, 0.5, 10.0).value, 0.1, kRoundOff);
  EXPECT_EQ(energy_error(10.0, 11.0, 11.0, std::nullopt, 0.5, 10.0).against, "invariant");
}

TEST(EnergyError, AgainstTheClosedFormALossBeyondWhatEAllowsCounts) {
  // headon_e05 by hand: E0 = 2 J, the closed form keeps 0.875 J (56.25 % lost). A backend that
  // keeps 0.79 J (60.5 % lost) is 0.085 / 2 = 4.25 % off, though it gained nothing.
  const EnergyError err = energy_error(2.0, 0.79, 0.79, 0.875, 0.5, 2.0);
  EXPECT_NEAR(err.value, 0.0425, kRoundOff);
  EXPECT_EQ(err.against, "analytic");
}

TEST(ExpectedKineticEnergy, NeedsBothVelocitiesOfEveryMovingBody) {
  // A: 1 kg unit cube (I = diag(1/6)); C: static. A at v = (1, 2, 0), w = (0, 0, 6):
  // 0.5 * 1 * 5 + 0.5 * 36 / 6 = 2.5 + 3 = 5.5 J.
  const auto in = bodies_of(
      "[[body]]\nname = \"A\"\n[[body]]\nname = \"C\"\nstatic = true\n"
      "position = [5, 0, 0]\n");
  const std::vector<BodyFinal> fin = {final_state(in[0], Vec3::Zero()),
                                      final_state(in[1], Vec3::Zero())};
  const auto e =
      expected_kinetic_energy(in, fin, {RefState{Vec3(1, 2, 0), Vec3(0, 0, 6)}, std::nullopt});
  ASSERT_TRUE(e.has_value());
  EXPECT_NEAR(*e, 5.5, kRoundOff);
  // Without A's angular velocity the closed form says nothing about its energy.
  EXPECT_FALSE(
      expected_kinetic_energy(in, fin, {RefState{Vec3(1, 2, 0), std::nullopt}, std::nullopt}));
  EXPECT_FALSE(expected_kinetic_energy(in, fin, {std::nullopt, std::nullopt}));
}

TEST(DistanceToRegion, SquareSegmentPointAndEmpty) {
  const std::vector<Vec3> square = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  // Above the inside: the height. Beside an edge: the distance to it. Off a corner: to it.
  EXPECT_NEAR(distance_to_region({0.5, 0.5, 0.3}, square), 0.3, kRoundOff);
  EXPECT_NEAR(distance_to_region({0.5, -2.0, 0.0}, square), 2.0, kRoundOff);
  EXPECT_NEAR(distance_to_region({2.0, 2.0, 0.0}, square), std::sqrt(2.0), kRoundOff);
  EXPECT_EQ(distance_to_region({0.25, 0.75, 0.0}, square), 0.0);
  // A segment (two points) and a single point.
  const std::vector<Vec3> segment = {{0, 0, 0}, {2, 0, 0}};
  EXPECT_NEAR(distance_to_region({1.0, 3.0, 4.0}, segment), 5.0, kRoundOff);
  EXPECT_NEAR(distance_to_region({3.0, 0.0, 0.0}, segment), 1.0, kRoundOff);
  EXPECT_NEAR(distance_to_region({0, 3, 4}, {Vec3(0, 0, 0)}), 5.0, kRoundOff);
  EXPECT_TRUE(std::isinf(distance_to_region({0, 0, 0}, {})));
}

TEST(ContactPointError, ZeroInsideBothBodiesElseTheDistanceToTheManifold) {
  // Two unit cubes overlapping 0.1 along x (A at the origin, B at x = 0.9): the intersection
  // is the slab 0.4 <= x <= 0.5, |y|, |z| <= 0.5. Take as manifold the square on A's face x = 0.5.
  const auto in =
      bodies_of("[[body]]\nname = \"A\"\n[[body]]\nname = \"B\"\nposition = [0.9, 0, 0]\n");
  const std::vector<Vec3> face = {
      {0.5, -0.5, -0.5}, {0.5, 0.5, -0.5}, {0.5, 0.5, 0.5}, {0.5, -0.5, 0.5}};
  // Inside the overlap, 0.05 from the manifold's plane: on the true contact region.
  EXPECT_EQ(contact_point_error({0.45, 0.1, 0.0}, in[0], in[1], face), 0.0);
  // On the overlap's boundary (A's face): inside both within the round-off tolerance.
  EXPECT_EQ(contact_point_error({0.5, 0.0, 0.0}, in[0], in[1], face), 0.0);
  EXPECT_EQ(contact_point_error({0.4, 0.5, -0.5}, in[0], in[1], face), 0.0);
  // Inside A only (x = 0.3 < 0.4): the distance to the manifold, 0.2.
  EXPECT_NEAR(contact_point_error({0.3, 0.0, 0.0}, in[0], in[1], face), 0.2, kRoundOff);
  // Outside both, beside the overlap: distance to the manifold's edge, sqrt(0.1^2 + 0.5^2).
  EXPECT_NEAR(contact_point_error({0.4, 1.0, 0.0}, in[0], in[1], face), std::sqrt(0.26), kRoundOff);
}

TEST(TouchingError, ZeroExactlyWhenTheAnswerMatchesTheTruth) {
  ContactResult none;
  ContactResult one;
  one.contacts.push_back(ContactPoint{});
  EXPECT_EQ(touching_error(none, false), 0.0);
  EXPECT_EQ(touching_error(one, true), 0.0);
  EXPECT_EQ(touching_error(none, true), 1.0);  // a missed contact
  EXPECT_EQ(touching_error(one, false), 1.0);  // a false contact
}

TEST(StabilityVerdict, StableWhenNoRuleFires) {
  StabilityFacts f;
  f.energy_growth = 0.009;  // below 1 %
  f.max_penetration = 0.4;  // below half a body
  f.momentum_drift = 1.0;   // ignored: not a closed system
  const StabilityVerdict v = stability_verdict(f);
  EXPECT_EQ(v.verdict, "stable");
  EXPECT_TRUE(v.why.empty());
}

TEST(StabilityVerdict, SinksWhenStillPenetratingAtRest) {
  StabilityFacts f;
  f.restitution = 0.0;
  f.max_penetration = 0.3;     // a deep transient alone is not sinking
  f.rest_penetration = 0.009;  // below 1 % of the smaller body
  EXPECT_EQ(stability_verdict(f).verdict, "stable");
  f.rest_penetration = 0.011;
  const StabilityVerdict v = stability_verdict(f);
  EXPECT_EQ(v.verdict, "sinks");
  ASSERT_EQ(v.why.size(), 1u);
  EXPECT_NE(v.why[0].find("at rest"), std::string::npos);
  // Worse words win, and every reason is listed.
  f.tunnelled_pairs = 1;
  EXPECT_EQ(stability_verdict(f).verdict, "unstable");
  EXPECT_EQ(stability_verdict(f).why.size(), 2u);
}

TEST(StabilityVerdict, DissipativeOnlyWithElasticFrictionlessContact) {
  StabilityFacts f;
  f.restitution = 1.0;
  f.energy_final = -0.009;  // lost 0.9 %: round-off and soft-contact storage
  EXPECT_EQ(stability_verdict(f).verdict, "stable");
  f.energy_final = -0.02;  // lost 2 % with e = 1 and no friction
  EXPECT_EQ(stability_verdict(f).verdict, "dissipative");
  f.friction = 0.5;  // friction may take energy out
  EXPECT_EQ(stability_verdict(f).verdict, "stable");
  f.friction = 0.0;
  f.restitution = 0.9;  // so may e < 1
  EXPECT_EQ(stability_verdict(f).verdict, "stable");
  // A sinking run that also loses energy is reported as sinking, with both reasons.
  f.restitution = 1.0;
  f.rest_penetration = 0.05;
  EXPECT_EQ(stability_verdict(f).verdict, "sinks");
  EXPECT_EQ(stability_verdict(f).why.size(), 2u);
}

TEST(StabilityVerdict, EachUnstableRuleFiresAlone) {
  const std::vector<std::pair<std::string, std::function<void(StabilityFacts&)>>> rules = {
      {"non-finite", [](StabilityFacts& f) { f.nonfinite = true; }},
      {"energy grew", [](StabilityFacts& f) { f.energy_growth = 0.011; }},
      {"tunnelled", [](StabilityFacts& f) { f.tunnelled_pairs = 1; }},
      {"guard tripped",
       [](StabilityFacts& f) {
         f.stopped = true;
         f.stop_message = "guard tripped";
       }},
      {"momentum drift",
       [](StabilityFacts& f) {
         f.closed = true;
         f.momentum_drift = 2e-6;
       }},
      {"penetration", [](StabilityFacts& f) { f.max_penetration = 0.51; }},
  };
  for (const auto& [text, set] : rules) {
    StabilityFacts f;
    set(f);
    const StabilityVerdict v = stability_verdict(f);
    EXPECT_EQ(v.verdict, "unstable") << text;
    ASSERT_EQ(v.why.size(), 1u) << text;
    EXPECT_NE(v.why[0].find(text), std::string::npos) << v.why[0];
  }
}

}  // namespace
}  // namespace rbx
