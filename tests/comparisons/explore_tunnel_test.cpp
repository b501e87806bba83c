// rbx explore's tunnel kind: samples reproducible from (seed, index), the closed form checked by
// hand and against the custom engine, Bullet with its continuous collision stopping every fast
// projectile where libraries without it let some through, and a tunnel reproduced by the harness.
#include <gtest/gtest.h>

#include <string>

#include "comparisons/eval/explore.h"
#include "comparisons/eval/harness.h"
#include "comparisons/scene/scene_file.h"

namespace rbx {
namespace {

TEST(ExploreTunnel, IsAFunctionOfSeedAndIndexAlone) {
  const std::string alone = make_tunnel_sample(7, 12).text;
  ASSERT_FALSE(alone.empty());
  for (uint64_t i = 0; i < 5; ++i) make_tunnel_sample(7, i);
  EXPECT_EQ(make_tunnel_sample(7, 12).text, alone);
  EXPECT_NE(make_tunnel_sample(7, 13).text, alone);
  EXPECT_NE(make_tunnel_sample(8, 12).text, alone);
}

TEST(ExploreTunnel, ClosedFormMatchesTheHandDerivedBounce) {
  // A 0.1 m cube at a 5 cm wall facing +z, 2 x (0.05 + 0.1) m per 1 ms step: 300 m/s down, 60 m/s
  // along x; e = 0.5: 150 m/s up after, 60 m/s along x kept. First touch at 2.5 ms with its
  // centre 0.05 m above the face; 13 steps in all.
  TunnelSample s;
  s.size = Vec3::Constant(0.1);
  s.wall_thickness = 0.05;
  s.travel_ratio = 2.0;
  s.tangential = 0.2;
  s.restitution = 0.5;
  s.steps_before = 2;
  s.phase = 0.5;
  ASSERT_TRUE(realize_tunnel(s));
  EXPECT_NEAR(s.speed, 300.0, 1e-12);
  EXPECT_NEAR((s.velocity - Vec3(60, 0, -300)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((s.velocity_after - Vec3(60, 0, 150)).norm(), 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(s.contact_time, 2.5e-3);
  EXPECT_DOUBLE_EQ(s.duration, 13e-3);
  EXPECT_NEAR((s.start_position - Vec3(-0.15, 0, 0.05 + 0.75)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((s.expect_position - Vec3(0.63, 0, 0.05 + 1.575)).norm(), 0.0, 1e-12);
  SampleOutcome o = evaluate_tunnel_sample(s, {"custom"});
  ASSERT_EQ(o.backends.size(), 1u);
  EXPECT_EQ(o.feature, "fast");
  EXPECT_EQ(o.backends[0].error, "") << o.backends[0].velocity_err_ke;
  s.restitution = 1.5;
  EXPECT_FALSE(realize_tunnel(s));
}

TEST(ExploreTunnel, CustomMeetsTheClosedFormThroughTheHarness) {
  for (uint64_t i = 0; i < 12; ++i) {
    const TunnelSample s = make_tunnel_sample(2, i);
    HarnessOptions h;
    h.backends = "custom";
    h.studies = false;
    h.phases = false;
    h.timing_budget_s = 0.0;
    const SceneEvaluation ev = evaluate_scene(parse_scene(s.text, "tunnel.toml"), h);
    EXPECT_TRUE(ev.expect_checked) << i;
    EXPECT_TRUE(ev.expect_failures.empty()) << i << ": " << ev.expect_failures.front();
    const SampleOutcome o = evaluate_tunnel_sample(s, {"custom"});
    ASSERT_EQ(o.backends.size(), 1u);
    EXPECT_EQ(o.backends[0].error, "") << i << ": " << o.backends[0].velocity_err_ke;
  }
}

TEST(ExploreTunnel, BulletsContinuousCollisionStopsWhatALibraryWithoutItLetsThrough) {
  // On the same samples, fast ones among them: Bullet with its CCD (the backend's default, as
  // its demos set it) bounces every projectile back at the closed form's velocity; DART, with no
  // continuous collision, lets some fast ones through.
  int fast = 0, dart_through = 0;
  for (uint64_t i = 0; i < 40; ++i) {
    const TunnelSample s = make_tunnel_sample(3, i);
    const SampleOutcome o = evaluate_tunnel_sample(s, {"bullet", "dart"});
    ASSERT_EQ(o.backends.size(), 2u);
    fast += o.feature == "fast";
    EXPECT_EQ(o.backends[0].error, "")
        << i << " (" << o.feature << "): " << o.backends[0].velocity_err_ke;
    dart_through += o.feature == "fast" && o.backends[1].error == "tunnel";
  }
  EXPECT_GE(fast, 10);
  EXPECT_GT(dart_through, 0);
}

TEST(ExploreTunnel, ATunnelIsReproducedThroughTheHarness) {
  for (uint64_t i = 0; i < 40; ++i) {
    const TunnelSample s = make_tunnel_sample(3, i);
    const SampleOutcome o = evaluate_tunnel_sample(s, {"ode"});
    ASSERT_EQ(o.backends.size(), 1u);
    if (o.backends[0].error != "tunnel") continue;
    std::string detail;
    EXPECT_TRUE(harness_reproduces(s.text, "tunnel.toml", o.backends[0], &detail)) << detail;
    BackendOutcome custom = o.backends[0];
    custom.backend = "custom";
    EXPECT_FALSE(harness_reproduces(s.text, "tunnel.toml", custom, &detail)) << detail;
    return;
  }
  FAIL() << "no sample among the first 40 of seed 3 where ode lets the projectile through";
}

}  // namespace
}  // namespace rbx
