// rbx explore's slide kind: samples reproducible from (seed, index), the closed form checked by
// hand and against the custom engine through the harness, the time to rest read through a
// library's resting jitter but not through a creep, and a rest-time disagreement reproduced from
// the written scene alone.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "comparisons/eval/explore.h"
#include "comparisons/eval/harness.h"
#include "comparisons/scene/scene_file.h"
#include "reference/bullet.h"
#include "reference/ode.h"

namespace rbx {
namespace {

constexpr double kG = 9.81;

// `bullet` at its settings changed by `change`, under `name`, for a table of its own: run in
// process (the test's speed, the same library calls).
Backend bullet_with(const std::string& name, std::function<void(BulletSettings&)> change) {
  Backend b = *find_backend("bullet");
  b.name = name;
  b.library = false;
  b.dynamics = [change](const WorldDefinition& scene, const DynamicsOptions& opt) {
    BulletSettings s = bullet_native_settings();
    change(s);
    return bullet_at_settings().dynamics(scene, opt, s);
  };
  return b;
}

TEST(ExploreSlide, IsAFunctionOfSeedAndIndexAlone) {
  const std::string alone = make_slide_sample(7, 12).text;
  ASSERT_FALSE(alone.empty());
  for (uint64_t i = 0; i < 5; ++i) make_slide_sample(7, i);
  EXPECT_EQ(make_slide_sample(7, 12).text, alone);
  EXPECT_NE(make_slide_sample(7, 13).text, alone);
  EXPECT_NE(make_slide_sample(8, 12).text, alone);
}

TEST(ExploreSlide, ClosedFormMatchesTheHandDerivedSlides) {
  // A unit cube on a floor at 1 m/s, mu = 0.5: a = mu g, v^2 / 2a = 0.10194 m, v / a = 0.2039 s.
  SlideSample s;
  s.friction = 0.5;
  s.speed = 1.0;
  ASSERT_TRUE(realize_slide(s));
  EXPECT_EQ(slide_case(s), "floor");
  EXPECT_DOUBLE_EQ(s.deceleration, 0.5 * kG);
  EXPECT_NEAR(s.stop_distance, 1.0 / (2 * 0.5 * kG), 1e-15);
  EXPECT_NEAR(s.rest_time, 1.0 / (0.5 * kG), 1e-15);
  EXPECT_NEAR(s.expect_position.x(), 1.0 / (2 * 0.5 * kG), 1e-15);
  EXPECT_DOUBLE_EQ(s.expect_position.z(), 0.5 - 1e-6);  // a micrometre into the floor
  // The scene as written gives the same time (its surface, launch, gravity and friction).
  EXPECT_NEAR(slide_rest_time(parse_scene(s.text, "slide.toml")), s.rest_time, 1e-12);
  EXPECT_NEAR(s.duration / s.dt, std::round(s.duration / s.dt), 1e-9);

  // Down and up a 20 deg incline, mu = 0.6: a = g (mu cos -/+ sin), along the fall line.
  const double th = 20 * M_PI / 180;
  for (const int along : {1, -1}) {
    SlideSample c;
    c.friction = 0.6;
    c.speed = 0.8;
    c.incline_deg = 20;
    c.azimuth_deg = 30;
    c.along_fall_line = along;
    ASSERT_TRUE(realize_slide(c));
    EXPECT_EQ(slide_case(c), along > 0 ? "down" : "up");
    const double a = kG * (0.6 * std::cos(th) - along * std::sin(th));
    EXPECT_NEAR(c.deceleration, a, 1e-14);
    EXPECT_NEAR(c.rest_time, 0.8 / a, 1e-14);
    EXPECT_NEAR(slide_rest_time(parse_scene(c.text, "slide.toml")), c.rest_time, 1e-12);
    // The fall line: heading 30 deg, descending by tan(20 deg) per metre across.
    const Vec3 down(std::cos(th) * std::cos(M_PI / 6), std::cos(th) * std::sin(M_PI / 6),
                    -std::sin(th));
    const Vec3 travel = c.expect_position - c.start_position;
    EXPECT_NEAR((travel - along * c.stop_distance * down).norm(), 0.0, 1e-12);
    EXPECT_NEAR(c.normal.z(), std::cos(th), 1e-15);
  }
  // Left at rest on a 10 deg incline with mu = 0.5 > tan(10 deg): it stays.
  SlideSample r;
  r.friction = 0.5;
  r.incline_deg = 10;
  r.along_fall_line = 0;
  r.speed = 0.0;
  ASSERT_TRUE(realize_slide(r));
  EXPECT_EQ(slide_case(r), "sticks");
  EXPECT_EQ(r.rest_time, 0.0);
  EXPECT_EQ(r.expect_position, r.start_position);
  // Not slides of the closed form: a box that could tip, an incline it would not stick on.
  SlideSample tall = s;
  tall.size = Vec3(1, 1, 3);
  EXPECT_FALSE(realize_slide(tall));
  SlideSample steep = r;
  steep.incline_deg = 26;  // 0.5 cos - sin = 0.011 < 0.1
  EXPECT_FALSE(realize_slide(steep));
}

TEST(ExploreSlide, CustomMeetsTheClosedFormOnEveryCase) {
  // The closed form is right: the custom engine meets every [expect] of the written scenes
  // through the harness (1 mm, 1e-3 m/s), and explore finds no turn, no position and no time to
  // rest off its marks, on floors and inclines down, up and at rest.
  std::map<std::string, int> seen;
  for (uint64_t i = 0; i < 60; ++i) {
    const SlideSample s = make_slide_sample(2, i);
    if (seen[slide_case(s)] >= 2) continue;
    ++seen[slide_case(s)];
    HarnessOptions h;
    h.backends = "custom";
    h.studies = false;
    h.timing_budget_s = 0.0;
    const SceneEvaluation ev = evaluate_scene(parse_scene(s.text, "slide.toml"), h);
    EXPECT_TRUE(ev.expect_checked) << i;
    EXPECT_TRUE(ev.expect_failures.empty()) << i << ": " << ev.expect_failures.front();
    const SampleOutcome o = evaluate_slide_sample(s, {"custom"});
    ASSERT_EQ(o.backends.size(), 1u);
    EXPECT_EQ(o.backends[0].error, "")
        << i << ": " << o.backends[0].position_err_m << " m, " << o.backends[0].turn_rad << " rad, "
        << o.backends[0].rest_time_err_s << " s";
  }
  for (const char* c : {"floor", "down", "up", "sticks"}) EXPECT_EQ(seen[c], 2) << c;
}

// A run's samples of one body moving along x: speed v(t) at step k, position the sum.
std::vector<StateSample> run_of(const std::vector<double>& speeds, double dt) {
  std::vector<StateSample> out;
  double x = 0;
  for (size_t k = 0; k < speeds.size(); ++k) {
    x += speeds[k] * dt;
    StateSample s;
    s.time = (k + 1) * dt;
    BodyFinal b;
    b.position = Vec3(x, 0, 0.5);
    b.velocity = Vec3(speeds[k], 0, 0);
    s.bodies = {b};
    out.push_back(s);
  }
  return out;
}

TEST(ExploreSlide, TimeToRestReadsThroughJitterNotThroughACreep) {
  const double dt = 1e-3;
  std::vector<double> v;
  for (int k = 0; k < 100; ++k) v.push_back(std::max(0.0, 0.1 - 1e-3 * k));  // stops at step 100
  for (int k = 0; k < 200; ++k) v.push_back(0.0);
  const double stop = 0.101;  // the first sample below 1 mm/s: step 100, at its end
  EXPECT_NEAR(measured_rest_time(run_of(v, dt), Vec3::UnitZ(), 0.3), stop, 1e-12);
  // A resting jitter: single steps at 2 mm/s, a few micrometres each: still at rest from 0.1 s.
  std::vector<double> jitter = v;
  jitter[150] = 2e-3;
  jitter[151] = -2e-3;
  jitter[250] = 2e-3;
  EXPECT_NEAR(measured_rest_time(run_of(jitter, dt), Vec3::UnitZ(), 0.3), stop, 1e-12);
  // A creep at 0.9 mm/s for 150 ms (0.135 mm in all): at rest only once what is left of it is
  // within the 0.1 mm drift, 39 ms into it.
  std::vector<double> creep = v;
  for (int k = 100; k < 250; ++k) creep[k] = 9e-4;
  const double t = measured_rest_time(run_of(creep, dt), Vec3::UnitZ(), 0.3);
  EXPECT_GT(t, 0.13);
  EXPECT_LE(t, 0.25 + 1e-12);
  // Never at rest: the end of the run.
  EXPECT_EQ(measured_rest_time(run_of(std::vector<double>(300, 0.5), dt), Vec3::UnitZ(), 0.3), 0.3);
}

TEST(ExploreSlide, AContactReportedMetresDeepNamesTheDisagreement) {
  // Seed 8086, sample 25: a box sliding on a floor, which MuJoCo's box-box collider reports in
  // contact metres deep (MujocoKnownDefect.*), so the box is thrown and turned. The run's own
  // deepest reported contact names it; custom, on the same slide, reports none so deep.
  const SlideSample s = make_slide_sample(8086, 25);
  const SampleOutcome o = evaluate_slide_sample(s, {"mujoco", "custom"});
  ASSERT_EQ(o.backends.size(), 2u);
  EXPECT_EQ(o.backends[0].error, "deep_contact");
  EXPECT_GT(o.backends[0].reported_depth_m, 0.1 * s.size.minCoeff());
  EXPECT_EQ(o.backends[1].error, "");
  EXPECT_LT(o.backends[1].reported_depth_m, 1e-3);
}

TEST(ExploreSlide, TheBoxStartsAMicrometreIntoItsSurfaceEveryCornerOfItsBaseIn) {
  // At exactly zero depth the written pose's rounding left some corners of the base on an
  // incline about 1e-16 m above the surface: ODE's and DART's first step found one or two
  // corners, whose friction turned the box (ODE, seed 8086 samples 84, 147, 520, 581 and 682)
  // or pushed it aside (DART, 283, 872 and 877). Every corner of the base now starts in.
  for (uint64_t i : {84, 283, 682, 872, 877}) {
    const SlideSample s = make_slide_sample(8086, i);
    const Scene scene = parse_scene(s.text, "slide.toml");
    const std::vector<RigidBody> bodies = make_bodies(scene);
    const Vec3 n = bodies[1].orientation * Vec3::UnitZ();
    const Vec3 top = bodies[1].position + 0.5 * n;  // the slab is 1 m thick
    int below = 0;
    for (const Vec3& v : bodies[0].shape->vertices()) {
      const double height = (bodies[0].position + bodies[0].orientation * v - top).dot(n);
      // The base's corners sit 1 µm in, to the rounding of the written pose (1e-15 m here).
      if (height < 0.0) {
        EXPECT_NEAR(height, -1e-6, 1e-12) << "sample " << i;
        ++below;
      }
    }
    EXPECT_EQ(below, 4) << "sample " << i;
  }
  // The misses they were, now within the closed form: ODE's largest turn, DART's largest shift.
  for (const auto& [i, name] : {std::pair<uint64_t, std::string>{682, "ode"}, {877, "dart"}}) {
    const SampleOutcome o = evaluate_slide_sample(make_slide_sample(8086, i), {name});
    ASSERT_EQ(o.backends.size(), 1u);
    EXPECT_EQ(o.backends[0].error, "")
        << name << " on sample " << i << ": turned " << o.backends[0].turn_rad << " rad, rests "
        << o.backends[0].position_err_m << " m off";
  }
}

TEST(ExploreSlide, FrictionBeyondTheConeNamesBulletsTurn) {
  // Seed 8086, sample 416: a box sliding on a floor that Bullet turns by 0.011 rad. Its solver
  // bounds a point's friction by mu times its normal impulse only while that impulse is
  // positive, so a corner whose normal impulse fell to zero keeps an earlier iteration's friction
  // (docs/contact_laws.md). The run's own impulses measure the turn that friction gives, and
  // name the miss; the written scene shows it again. Custom leaves no friction at a point
  // without load.
  const SlideSample s = make_slide_sample(8086, 416);
  const SampleOutcome o = evaluate_slide_sample(s, {"bullet", "custom"});
  ASSERT_EQ(o.backends.size(), 2u);
  EXPECT_EQ(o.backends[0].error, "cone_excess");
  EXPECT_GT(o.backends[0].turn_rad, kLandingTurnMark);
  std::string detail;
  EXPECT_TRUE(harness_reproduces(s.text, "slide.toml", o.backends[0], &detail)) << detail;
  EXPECT_EQ(o.backends[1].error, "");
}

TEST(ExploreSlide, TheRiseIsTheCentresHighestOffTheSurfaceAlongItsNormal) {
  // On a 30 deg incline: a centre that moves along the surface never rises; one lifted 2 mm
  // along the normal at one sample rises 2 mm; one sinking into the surface rises 0.
  const Vec3 n(0.5, 0, std::sqrt(3.0) / 2), along(-n.z(), 0, n.x()), start(1, 2, 3);
  std::vector<StateSample> run(5);
  for (int k = 0; k < 5; ++k) {
    run[k].bodies.resize(1);
    run[k].bodies[0].position = start + 0.1 * k * along - 1e-5 * n;
  }
  EXPECT_EQ(largest_rise(run, start, start, n), 0.0);
  run[3].bodies[0].position += 2e-3 * n + 1e-5 * n;
  // Below, 1e-15 m: the round-off of positions of a few metres.
  EXPECT_NEAR(largest_rise(run, start, start, n), 2e-3, 1e-15);
  // Landing from 5 mm above its resting height: the fall is not a rise; the first sample at or
  // below the rest height starts the count, and a hop 1 mm up after it is one.
  const Vec3 drop = start + 5e-3 * n;
  EXPECT_NEAR(largest_rise(run, drop, start, n), 2e-3, 1e-15);  // sample 3: after the touch
  run[0].bodies[0].position = start + 4e-3 * n;                 // still falling at the first sample
  run[1].bodies[0].position = start - 1e-5 * n;                 // on the surface
  run[3].bodies[0].position = start + 1e-3 * n;                 // hops
  EXPECT_NEAR(largest_rise(run, drop, start, n), 1e-3, 1e-15);
}

TEST(ExploreSlide, ABoxThatRoseOffItsSurfaceNamesTheDisagreement) {
  // Seed 8086, sample 18: a box launched up an incline, which MuJoCo's contact lets leave the
  // surface at mu times its slip (MujocoKnownDefect.ASlidingBoxLeavesItsSurfaceAtMuTimesItsSlip);
  // it flies, lands late and rests off the closed form. The run's own rise names it, and the
  // written scene's own run shows the rise again; custom's box stays on the surface.
  const SlideSample s = make_slide_sample(8086, 18);
  const SampleOutcome o = evaluate_slide_sample(s, {"mujoco", "custom"});
  ASSERT_EQ(o.backends.size(), 2u);
  EXPECT_EQ(o.backends[0].error, "lift_off");
  EXPECT_GT(o.backends[0].rise_m, kSlideLiftMark);
  std::string detail;
  EXPECT_TRUE(harness_reproduces(s.text, "slide.toml", o.backends[0], &detail)) << detail;
  EXPECT_EQ(o.backends[1].error, "");
  EXPECT_LT(o.backends[1].rise_m, 1e-9);  // round-off on the incline's pose
}

TEST(ExploreSlide, AHopAccountsForALateRestByTheNormalMomentumBeforeTheStop) {
  // A slide up a 20 deg incline, mu = 1 (a = g (cos + sin) = 12.57 m/s^2), whose closed-form rest
  // is at 5 ms; the run rests at 9 ms, 4 ms late, its box coming down at 0.036 m/s at its last
  // sliding sample (8 ms): mu |v_n| / a = 2.86 ms of it, leaving 1.14 ms, within the 3 ms mark.
  const double theta = 20.0 * M_PI / 180.0, mu = 1.0;
  const double a = 9.81 * (std::cos(theta) + std::sin(theta));
  const Vec3 n(std::sin(theta), 0.0, std::cos(theta));
  std::vector<StateSample> run(12);
  for (int k = 0; k < 12; ++k) {
    run[k].time = 1e-3 * k;
    run[k].bodies.resize(1);
  }
  run[8].bodies[0].velocity = -0.036 * n;
  // The landing that stopped it: no normal motion left at the rest, which the account does not
  // read.
  run[9].bodies[0].velocity = Vec3(0.0, 0.0, 0.0);
  const double rise = 6e-5;  // the hop: more than a tenth of the lift mark, less than the mark
  EXPECT_TRUE(hop_accounts_for_rest(run, n, 9e-3, 5e-3, mu, a, rise));
  // Moving off the surface, or along it, the momentum takes nothing from the lateness (or makes
  // it earlier).
  run[8].bodies[0].velocity = 0.036 * n;
  EXPECT_FALSE(hop_accounts_for_rest(run, n, 9e-3, 5e-3, mu, a, rise));
  run[8].bodies[0].velocity = Vec3(0.0, 0.0, 0.0);
  EXPECT_FALSE(hop_accounts_for_rest(run, n, 9e-3, 5e-3, mu, a, rise));
  // Coming down faster: 0.09 m/s accounts for 7.2 ms, 3.2 ms more than the 4 ms seen, past the
  // mark the other way; 0.08 m/s for 6.4 ms, 2.4 ms more, within it.
  run[8].bodies[0].velocity = -0.09 * n;
  EXPECT_FALSE(hop_accounts_for_rest(run, n, 9e-3, 5e-3, mu, a, rise));
  run[8].bodies[0].velocity = -0.08 * n;
  EXPECT_TRUE(hop_accounts_for_rest(run, n, 9e-3, 5e-3, mu, a, rise));
  // A box that never left its surface (a soft contact's sinking, not a hop) is not named so, nor
  // one that rests at its first sample.
  run[8].bodies[0].velocity = -0.036 * n;
  EXPECT_FALSE(hop_accounts_for_rest(run, n, 9e-3, 5e-3, mu, a, 0.5e-5));
  EXPECT_FALSE(hop_accounts_for_rest(run, n, 0.0, 5e-3, mu, a, rise));
}

TEST(ExploreSlide, ASmallHopThatDelaysTheRestNamesTheDisagreement) {
  // Seed 31337, sample 660: a box launched up a 20 deg incline at 0.07 m/s, mu = 1. MuJoCo's box
  // leaves the surface at its first step at mu times its slip, rises 59 micrometres (under the
  // lift mark), flies without friction and rests 3.3 ms late; at its last sliding sample it comes
  // down at 0.036 m/s, which accounts for 2.8 ms of it, so the rest_time miss is named lift_off,
  // and the written scene's own run shows it again. custom's box stays on the surface and rests
  // on time.
  const SlideSample s = make_slide_sample(31337, 660);
  const SampleOutcome o = evaluate_slide_sample(s, {"mujoco", "custom"});
  ASSERT_EQ(o.backends.size(), 2u);
  EXPECT_EQ(o.backends[0].error, "lift_off");
  EXPECT_LT(o.backends[0].rise_m, kSlideLiftMark);
  EXPECT_GT(o.backends[0].rest_time_err_s, kSlideRestTimeMark);
  std::string detail;
  EXPECT_TRUE(harness_reproduces(s.text, "slide.toml", o.backends[0], &detail)) << detail;
  EXPECT_EQ(o.backends[1].error, "");
}

TEST(ExploreSlide, ARestTimeDisagreementIsReproducedFromTheWrittenScene) {
  // Bullet with its processing threshold at 0 and its own push turn (the settings
  // BulletSettingsMeasuredOnTheFamily rejects), left at rest on an incline or launched on one,
  // creeps before it holds on some samples: its time to rest is off by tens of milliseconds.
  // The written scene alone shows it (the scene's own run against the closed form recomputed
  // from the scene); custom's does not. Registered as a user backend: the harness finds it by
  // name, as it finds the scene's.
  const std::string creeper = "bullet-threshold-0";
  if (!find_backend(creeper)) {
    Backend b = *find_backend("bullet");
    b.name = creeper;
    b.dynamics = [](const WorldDefinition& scene, const DynamicsOptions& opt) {
      BulletSettings s = bullet_native_settings();
      s.processing_fraction = 0;
      s.split_turn_erp = -1;
      return bullet_at_settings().dynamics(scene, opt, s);
    };
    register_backend(b);
  }
  for (uint64_t i = 0; i < 100; ++i) {
    const SlideSample s = make_slide_sample(5150, i);
    const SampleOutcome o = evaluate_slide_sample(s, {creeper});
    ASSERT_EQ(o.backends.size(), 1u);
    if (o.backends[0].error != "rest_time") continue;
    std::string detail;
    EXPECT_TRUE(harness_reproduces(s.text, "slide.toml", o.backends[0], &detail)) << detail;
    BackendOutcome custom = o.backends[0];
    custom.backend = "custom";
    EXPECT_FALSE(harness_reproduces(s.text, "slide.toml", custom, &detail)) << detail;
    return;
  }
  FAIL() << "no sample among the first 100 of seed 5150 where " << creeper
         << "'s time to rest is off";
}

TEST(ExploreSlide, BulletSettingsMeasuredOnTheFamily) {
  // Bullet's two resting-contact settings (reference/bullet.h), measured on slides of a seed
  // not used while choosing them, each alternative beside the chosen pair: the processing
  // threshold at 0 drops a point the split push lifted past zero, and the box hops and creeps
  // (time to rest); Bullet's default solves points before they touch; the push's turn at
  // Bullet's 0.1 tilts sliding boxes and delays their rest. Judged on the errors' 90th and 99th
  // percentiles, which 200 slides fix far better than the few disagreements they hold. (With the
  // box started at zero depth, the 0.1 turn also turned the boxes, p90 3x; from a micrometre in
  // both turn by round-off only.)
  const std::vector<Backend> table = {
      bullet_with("chosen", [](BulletSettings&) {}),
      bullet_with("threshold 0", [](BulletSettings& s) { s.processing_fraction = 0; }),
      bullet_with("threshold default", [](BulletSettings& s) { s.processing_fraction = 1e30; }),
      bullet_with("turn erp 0.1", [](BulletSettings& s) { s.split_turn_erp = -1; })};
  std::vector<std::string> names;
  for (const Backend& b : table) names.push_back(b.name);
  std::map<std::string, int> misses;
  std::map<std::string, std::vector<double>> turn, rest;
  constexpr int kCount = 200;
  for (uint64_t i = 0; i < kCount; ++i) {
    const SampleOutcome o = evaluate_slide_sample(make_slide_sample(31, i), names, &table);
    for (const BackendOutcome& b : o.backends) {
      misses[b.backend] += !b.error.empty();
      turn[b.backend].push_back(b.turn_rad);
      rest[b.backend].push_back(b.rest_time_err_s);
    }
  }
  const auto p90 = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() * 9 / 10];
  };
  const auto p99 = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() * 99 / 100];
  };
  for (const std::string& n : names)
    std::printf(
        "[measured] bullet, %-18s %2d of %d disagree; turn p90 %.3g p99 %.3g rad, rest "
        "time p90 %.3g p99 %.3g s\n",
        n.c_str(), misses[n], kCount, p90(turn[n]), p99(turn[n]), p90(rest[n]), p99(rest[n]));
  const std::string chosen = "chosen";
  EXPECT_LE(misses[chosen], kCount / 20);
  // Each alternative worse by a factor past the percentiles' sampling spread (a few tens of
  // per cent at 200 samples).
  EXPECT_GT(p90(turn["threshold 0"]), 5 * p90(turn[chosen]));
  EXPECT_GT(p99(rest["threshold 0"]), 2 * p99(rest[chosen]));
  EXPECT_GT(p99(rest["turn erp 0.1"]), 2 * p99(rest[chosen]));
  // Bullet's default threshold slides about as well, but it solves a projectile's contact
  // before it reaches the wall and sends it back early, at the wrong speed.
  std::map<std::string, int> tunnel_misses;
  constexpr int kProjectiles = 40;
  for (uint64_t i = 0; i < kProjectiles; ++i) {
    const SampleOutcome o = evaluate_tunnel_sample(make_tunnel_sample(31, i), names, &table);
    for (const BackendOutcome& b : o.backends) tunnel_misses[b.backend] += !b.error.empty();
  }
  for (const std::string& n : names)
    std::printf("[measured] bullet, %-18s %2d of %d projectiles disagree\n", n.c_str(),
                tunnel_misses[n], kProjectiles);
  EXPECT_LE(tunnel_misses[chosen], kProjectiles / 20);
  EXPECT_GT(tunnel_misses["threshold default"], kProjectiles / 2);
}

TEST(ExploreSlide, BulletWarmStartingMeasuredOnSlidesLandingsAndImpacts) {
  // Bullet's warm starting (reference/bullet.h), measured at rbx's 0 and Bullet's own 0.85 on
  // the three random families it can move, on a seed not used while choosing it: slides and
  // landings (friction carried from step to step) and single-point impacts (an impulse carried
  // into the step after the bounce). Started from 0.85 of the last step's friction, an
  // iteration whose corner loads shift keeps friction the step no longer has: landings and slides
  // stop off the closed form; an impact, whose contact is gone the step after, is the same either
  // way. 0 stays.
  const std::vector<Backend> table = {
      bullet_with("warm 0", [](BulletSettings& s) { s.warmstarting_factor = 0.0; }),
      bullet_with("warm 0.85", [](BulletSettings& s) { s.warmstarting_factor = 0.85; })};
  const std::vector<std::string> names = {"warm 0", "warm 0.85"};
  std::map<std::string, std::map<std::string, int>> misses;  // family -> backend -> count
  std::map<std::string, std::map<std::string, std::vector<double>>> err;
  constexpr int kSlides = 200, kLandings = 100, kImpacts = 100;
  const auto tally = [&](const std::string& family, const SampleOutcome& o, bool velocity) {
    for (const BackendOutcome& b : o.backends) {
      misses[family][b.backend] += !b.error.empty();
      err[family][b.backend].push_back(velocity ? b.velocity_err_ke : b.position_err_m);
    }
  };
  for (uint64_t i = 0; i < kSlides; ++i)
    tally("slide", evaluate_slide_sample(make_slide_sample(97, i), names, &table), false);
  for (uint64_t i = 0; i < kLandings; ++i)
    tally("landing", evaluate_landing_sample(make_landing_sample(97, i), names, &table), false);
  for (uint64_t i = 0; i < kImpacts; ++i)
    tally("impact", evaluate_impact_sample(make_impact_sample(97, i), names, &table), true);
  const auto p99 = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() * 99 / 100];
  };
  for (const auto& [family, by] : misses)
    for (const std::string& n : names)
      std::printf("[measured] bullet %-9s %-8s %2d of %zu disagree; %s p99 %.3g\n", n.c_str(),
                  family.c_str(), by.at(n), err[family][n].size(),
                  family == "impact" ? "velocity err" : "position err (m)", p99(err[family][n]));
  // Margins past the sampling spread of a few disagreements in 100 or 200 samples.
  EXPECT_GT(misses["landing"]["warm 0.85"], 2 * misses["landing"]["warm 0"] + 5);
  EXPECT_GT(p99(err["landing"]["warm 0.85"]), 2 * p99(err["landing"]["warm 0"]));
  EXPECT_GT(p99(err["slide"]["warm 0.85"]), 5 * p99(err["slide"]["warm 0"]));
  EXPECT_EQ(misses["impact"]["warm 0.85"], misses["impact"]["warm 0"]);
}

TEST(ExploreLanding, OdeCorrectingSpeedCapMeasuredOnTheFamily) {
  // ODE's cap on a contact's position-correction speed (reference/ode.h), on landings of a seed
  // not used while choosing it: without it a landing box first seen d deep is pushed off the
  // floor at ERP d / dt whatever e is, flies, and loses the rest of its slide; the cap stops
  // the pop. The stack's side of the choice is in tests/reference/fair_settings_test.cpp.
  const auto ode_at = [](const std::string& name, double cap) {
    Backend b = *find_backend("ode");
    b.name = name;
    b.library = false;  // in process: the test's speed, the same library calls
    b.dynamics = [cap](const WorldDefinition& scene, const DynamicsOptions& opt) {
      OdeSettings s;
      s.max_correcting_vel = cap;
      return ode_at_settings().dynamics(scene, opt, s);
    };
    return b;
  };
  const std::vector<Backend> table = {ode_at("no cap", double(INFINITY)), ode_at("cap 0.1", 0.1),
                                      ode_at("cap 0.01", 0.01)};
  const std::vector<std::string> names = {"no cap", "cap 0.1", "cap 0.01"};
  std::map<std::string, int> misses;
  std::map<std::string, std::vector<double>> rise, rest;
  constexpr int kCount = 200;
  for (uint64_t i = 0; i < kCount; ++i) {
    const SampleOutcome o = evaluate_landing_sample(make_landing_sample(97, i), names, &table);
    for (const BackendOutcome& b : o.backends) {
      misses[b.backend] += !b.error.empty() && b.error != "late_landing";
      rise[b.backend].push_back(b.rise_m);
      rest[b.backend].push_back(b.rest_time_err_s);
    }
  }
  const auto p99 = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() * 99 / 100];
  };
  for (const std::string& n : names)
    std::printf(
        "[measured] ode, %-8s %2d of %d disagree (late_landing aside); rise p99 %.3g m, rest "
        "time err p99 %.3g s\n",
        n.c_str(), misses[n], kCount, p99(rise[n]), p99(rest[n]));
  // Each step's pop rises by (ERP d / dt)^2 / 2g: millimetres at a millimetre's depth; capped at
  // 0.1 m/s, half a millimetre at most, and the flight that loses the slide goes with it.
  EXPECT_GT(p99(rise["no cap"]), 1e-3);
  EXPECT_LT(p99(rise["cap 0.1"]), 0.1 * p99(rise["no cap"]));
  // A lower cap bounds the pop further; what rejects it is the tosses' soft contact
  // (docs/references.md), not this family.
  EXPECT_LE(p99(rise["cap 0.01"]), p99(rise["cap 0.1"]));
  EXPECT_LE(misses["cap 0.1"], misses["no cap"]);
}

}  // namespace
}  // namespace rbx
