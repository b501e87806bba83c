// Ensembles: the nudges, the spread and its amplification, contact sequences, clusters, the step
// test, and the same answer on any number of threads.
#include "comparisons/eval/ensemble.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "comparisons/scene/scene_file.h"

namespace rbx {
namespace {

Scene scene_at(const std::string& relative) {
  return load_scene(std::string(RBX_SOURCE_DIR) + "/" + relative);
}

// The nudges of copies 0 .. n-1 of body `i`'s position along x, minus the nominal value.
std::vector<double> position_nudges(const Scene& s, int i, long n, uint64_t seed) {
  std::vector<double> d;
  for (long k = 0; k < n; ++k)
    d.push_back(nudged_copy(s, Nudge{}, seed, static_cast<uint64_t>(k)).bodies[i].position.x() -
                s.bodies[i].position.x());
  return d;
}

TEST(Ensemble, NudgesAreAFunctionOfSeedAndIndexWithTheirScaleAndSpareStaticBodies) {
  Scene s = scene_at("scenes/analytic/headon_e05.toml");
  s.bodies[1].is_static = true;
  // The same (seed, index): the same copy; another index or seed: another copy.
  const Scene a = nudged_copy(s, Nudge{}, 7, 3), b = nudged_copy(s, Nudge{}, 7, 3);
  EXPECT_EQ(a.bodies[0].position, b.bodies[0].position);
  EXPECT_EQ(a.bodies[0].orientation.coeffs(), b.bodies[0].orientation.coeffs());
  EXPECT_NE(a.bodies[0].position, nudged_copy(s, Nudge{}, 7, 4).bodies[0].position);
  EXPECT_NE(a.bodies[0].position, nudged_copy(s, Nudge{}, 8, 3).bodies[0].position);
  // A static body is never moved.
  EXPECT_EQ(a.bodies[1].position, s.bodies[1].position);
  EXPECT_EQ(a.bodies[1].velocity, s.bodies[1].velocity);
  // The sample standard deviation of 4,000 nudges: its relative error is about 1/sqrt(2 n),
  // 1.1 %, so 5 % is more than four of those; the mean within four standard errors of zero.
  const long n = 4000;
  const std::vector<double> d = position_nudges(s, 0, n, 1);
  double sum = 0.0, squares = 0.0;
  for (double x : d) sum += x;
  const double mean = sum / n;
  for (double x : d) squares += (x - mean) * (x - mean);
  const double sd = std::sqrt(squares / (n - 1));
  EXPECT_NEAR(sd, 1e-6, 0.05e-6);
  EXPECT_LT(std::abs(mean), 4.0 * 1e-6 / std::sqrt(static_cast<double>(n)));
}

TEST(Ensemble, AContactSequenceNamesEachPairAndFeatureInTheOrderFirstTouched) {
  auto event = [](const std::string& a, const std::string& b, const std::string& feature) {
    CollisionEvent e;
    e.body_a = a;
    e.body_b = b;
    e.contact.feature = feature;
    return e;
  };
  EXPECT_EQ(contact_sequence({}), "none");
  EXPECT_EQ(
      contact_sequence({event("A", "B", "edge"), event("B", "C", "face"), event("A", "B", "edge"),
                        event("A", "B", "face"), event("B", "C", "face")}),
      "A-B:edge > B-C:face > A-B:face");
}

// Copies of one moving body at the given final positions.
CopyStates copies_at(const std::vector<Vec3>& positions) {
  CopyStates c;
  for (const Vec3& p : positions) c.push_back({BodyFinal{"A", p, Quat::Identity(), {}, {}}});
  return c;
}

TEST(Ensemble, TwoSeparateGroupsAreTwoClustersAndOneCloudIsOne) {
  Scene s;
  s.bodies.resize(1);
  // A Gaussian cloud of 60 copies (from the nudges themselves): one cluster.
  std::vector<Vec3> cloud;
  for (uint64_t k = 0; k < 60; ++k) {
    Scene one;
    one.bodies.resize(1);
    cloud.push_back(nudged_copy(one, Nudge{}, 3, k).bodies[0].position);
  }
  EXPECT_EQ(cluster_count(s, copies_at(cloud)), 1);
  // The same cloud split in two, half of it moved a thousand standard deviations away.
  std::vector<Vec3> split = cloud;
  for (size_t k = 0; k < split.size() / 2; ++k) split[k] += Vec3(1e-3, 0, 0);
  EXPECT_EQ(cluster_count(s, copies_at(split)), 2);
  // One copy far off is an outlier, not a cluster (fewer than a tenth of the copies).
  std::vector<Vec3> outlier = cloud;
  outlier[0] += Vec3(1e-3, 0, 0);
  EXPECT_EQ(cluster_count(s, copies_at(outlier)), 1);
}

TEST(Ensemble, SpreadIsTheRootMeanSquareDistanceFromTheMean) {
  Scene s;
  s.bodies.resize(1);
  // Two copies 2 mm apart: each 1 mm from their mean.
  const StateSpread sp = state_spread(s, copies_at({Vec3(0, 0, 0), Vec3(0, 0.002, 0)}));
  EXPECT_NEAR(sp.position, 1e-3, 1e-15);
  // 5-95 % of two values by linear interpolation: 90 % of the gap.
  EXPECT_NEAR(sp.position_range, 0.0018, 1e-15);
  EXPECT_EQ(sp.orientation, 0.0);
}

// Head-on impacts nudged in position and velocity (an orientation nudge turns the face impact
// into a corner impact, which is discontinuous for rigid bodies): the closed form is smooth in
// those, so a backend that meets it to round-off keeps the velocity spread of the input, and
// the engine with a time of impact for every contact keeps the position spread too. The seed's
// detection after penetration resolves each copy at a whole step: a position spread of the
// order of (closing speed) x dt, which shrinks with the step (the engine's, by the step test).
TEST(Ensemble, HeadOnImpactsKeepTheInputSpreadWhereTheClosedFormIsMetAndTheStepTestNamesTheSeeds) {
  const Scene s = scene_at("scenes/analytic/headon_e05.toml");
  EnsembleSettings set;
  set.count = 16;
  set.nudge.orientation = 0.0;
  set.nudge.angular_velocity = 0.0;
  set.step_test = true;
  const ParallelRun par(2);
  const EnsembleResult r = run_ensemble(s, {"custom", "custom-seed", "bullet", "ode"}, set, par);
  ASSERT_EQ(r.backends.size(), 4u);
  for (const BackendEnsemble& b : r.backends) {
    SCOPED_TRACE(b.backend);
    EXPECT_EQ(b.runs, set.count);
    // Order one: the velocity spread is the input's, up to the impact's mix of the two bodies'
    // nudges (a factor between 0.5 and 2 for these masses and e).
    EXPECT_GT(b.velocity_amplification, 0.5);
    EXPECT_LT(b.velocity_amplification, 2.0);
    // One face contact in every copy; the seed's first hit names the feature its tests find
    // first at the depth the step first sees, which varies with the copy.
    if (b.backend != "custom-seed") {
      EXPECT_EQ(b.sequences.size(), 1u);
    }
  }
  const BackendEnsemble& custom = r.backends[0];
  EXPECT_GT(custom.amplification, 0.5);
  EXPECT_LT(custom.amplification, 2.0);
  EXPECT_EQ(custom.clusters, 1);
  EXPECT_EQ(custom.verdict, "physics");
  const BackendEnsemble& seed = r.backends[1];
  // (closing speed 2 m/s) x (dt 1 ms) against a 1e-6 m input: hundreds.
  EXPECT_GT(seed.amplification, 100.0);
  EXPECT_NEAR(seed.step_ratio, 0.1, 0.05);
  EXPECT_EQ(seed.verdict, "engine");
}

TEST(Ensemble, TheReportRunsTheScenesWithATableForTheirDurationAndANudgedStackRests) {
  // Two scenes, one with an [ensemble] table (6 copies of the first 0.2 s of the stack of
  // five): only it gets an `ensemble`, run for that long through the backends asked for.
  std::vector<Scene> scenes = {scene_at("scenes/analytic/headon_e05.toml"),
                               scene_at("scenes/friction/stack_five.toml")};
  scenes[0].ensemble.reset();
  scenes[1].ensemble = EnsembleSpec{6, false, 0.2};
  std::vector<SceneEvaluation> evs(2);
  const ParallelRun par(2);
  run_scene_ensembles(scenes, "custom,ode", evs, par);
  EXPECT_FALSE(evs[0].json.contains("ensemble"));
  ASSERT_TRUE(evs[1].json.contains("ensemble"));
  const Json& e = evs[1].json["ensemble"];
  EXPECT_EQ(e["count"], 6);
  EXPECT_EQ(e["duration"], 0.2);
  ASSERT_EQ(e["backends"].size(), 2u);
  // The custom engine's nudged stacks rest: the copies end where they started to within the
  // nudge's order (the start's overlaps pushed apart, 1e-6 m/s drifts for 0.2 s); one that slid
  // or toppled would spread millimetres, thousands of times the nudge.
  const Json& custom = e["backends"]["custom"];
  EXPECT_EQ(custom["runs"], 6);
  EXPECT_EQ(custom["failed"], 0);
  EXPECT_LT(custom["amplification"].get<double>(), 100.0);
}

TEST(Ensemble, TheResultIsTheSameOnOneAndOnThreeThreads) {
  const Scene s = scene_at("scenes/seed/edge_drop.toml");
  EnsembleSettings set;
  set.count = 9;
  const ParallelRun one(1), three(3);
  const std::vector<std::string> names = {"custom", "ode"};
  EXPECT_EQ(ensemble_json(run_ensemble(s, names, set, one)).dump(),
            ensemble_json(run_ensemble(s, names, set, three)).dump());
}

}  // namespace
}  // namespace rbx
