// Sampled trajectories for results.json and the replay pages: key frames reproduce every sample
// they drop within the stated tolerance, events are capped with their total kept.
#include "comparisons/eval/trajectory.h"

#include <gtest/gtest.h>

#include <cmath>

namespace rbx {
namespace {

/// One moving body "a" sampled at `n` steps of `dt`, placed by `at(t)` (position, angle about z).
template <class F>
std::vector<StateSample> sampled(size_t n, double dt, F at) {
  std::vector<StateSample> out;
  for (size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) * dt;
    const auto [p, angle] = at(t);
    BodyFinal b;
    b.name = "a";
    b.position = p;
    b.orientation = Quat(Eigen::AngleAxisd(angle, Vec3::UnitZ()));
    out.push_back({t, {b}});
  }
  return out;
}

std::vector<RigidBody> one_moving_body() {
  RigidBody b;
  b.name = "a";
  return {b};
}

/// The page's interpolation (positions linear) at time t of the key frames in `traj`.
Vec3 position_at(const Json& traj, double t) {
  const Json& time = traj["time"];
  const Json& f = traj["bodies"]["a"];
  size_t k = 0;
  while (k + 1 < time.size() && time[k + 1].get<double>() <= t) ++k;
  auto at = [&](size_t i) { return Vec3(f[i][0], f[i][1], f[i][2]); };
  if (k + 1 >= time.size()) return at(k);
  const double u =
      (t - time[k].get<double>()) / (time[k + 1].get<double>() - time[k].get<double>());
  return at(k) + (at(k + 1) - at(k)) * u;
}

TEST(Trajectory, FreeFlightNeedsOnlyItsEnds) {
  // Constant velocity, no spin: every inner frame is the lerp of the ends.
  const auto s = sampled(1001, 1e-3, [](double t) {
    return std::pair<Vec3, double>{Vec3(1.0 + 2.0 * t, -0.5 * t, 0.25), 0.0};
  });
  const Json traj = trajectory_json(s, one_moving_body(), kMaxFrames);
  EXPECT_EQ(traj["time"].size(), 2u);
  EXPECT_EQ(traj["bodies"]["a"].size(), 2u);
  EXPECT_DOUBLE_EQ(traj["time"][1].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(traj["bodies"]["a"][1][0].get<double>(), 3.0);
}

TEST(Trajectory, KeyFramesReproduceTheDroppedSamples) {
  // A ball falling, bouncing at t = 0.45 and spinning: the drop keeps the bounce and enough of
  // the parabola that the page's interpolation stays within the tolerance at every sample
  // kept by the frame budget (1e-4 of the extent for the thinning, plus half the 1e-4..1e-5
  // output grid).
  auto at = [](double t) {
    const double z = t < 0.45 ? 1.0 - 4.905 * t * t : 1.0 - 4.905 * 0.2025 + 2.0 * (t - 0.45);
    return std::pair<Vec3, double>{Vec3(0.3 * t, 0.0, z), 3.0 * t};
  };
  const auto s = sampled(1001, 1e-3, at);
  const Json traj = trajectory_json(s, one_moving_body(), kMaxFrames);
  const size_t keys = traj["time"].size();
  EXPECT_GT(keys, 3u);
  EXPECT_LT(keys, kMaxFrames);
  double extent = 0.0;
  for (const auto& smp : s) extent = std::max(extent, smp.bodies[0].position.cwiseAbs().maxCoeff());
  // The budget's frames: every 10th sample (1001 samples, 100 frames).
  double worst = 0.0;
  for (size_t k = 0; k < kMaxFrames; ++k) {
    const size_t i = static_cast<size_t>(std::llround(k * 1000.0 / (kMaxFrames - 1)));
    worst = std::max(worst, (position_at(traj, s[i].time) - s[i].bodies[0].position).norm());
  }
  EXPECT_LE(worst, std::sqrt(3.0) * 1.5 * kKeyFrameTolerance * extent);
  // The bounce (a kink) is a key frame to within one frame of the budget (10 ms).
  bool bounce = false;
  for (const auto& t : traj["time"]) bounce = bounce || std::abs(t.get<double>() - 0.45) <= 0.011;
  EXPECT_TRUE(bounce);
}

TEST(Trajectory, StaticBodiesAreLeftOut) {
  auto s = sampled(3, 0.1, [](double t) { return std::pair<Vec3, double>{Vec3(t, 0, 0), 0.0}; });
  BodyFinal still;
  still.name = "floor";
  for (auto& smp : s) smp.bodies.push_back(still);
  auto inputs = one_moving_body();
  RigidBody floor;
  floor.name = "floor";
  floor.is_static = true;
  inputs.push_back(floor);
  const Json traj = trajectory_json(s, inputs, kMaxFrames);
  EXPECT_TRUE(traj["bodies"].contains("a"));
  EXPECT_FALSE(traj["bodies"].contains("floor"));
}

TEST(Trajectory, ResultsKeepTheFirstEventsAndTheirCount) {
  Json events = Json::array();
  for (size_t i = 0; i < kResultsMaxEvents + 7; ++i) events.push_back({{"step", i}});
  const Json scene = {{"backends",
                       {{"custom", {{"contacts", events}}},
                        {"few", {{"contacts", Json::array({{{"step", 0}}})}}}}}};
  const Json out = results_scene_json(scene);
  EXPECT_EQ(out["backends"]["custom"]["contacts"].size(), kResultsMaxEvents);
  EXPECT_EQ(out["backends"]["custom"]["contacts_total"], kResultsMaxEvents + 7);
  EXPECT_TRUE(out["backends"]["custom"].value("contacts_truncated", false));
  EXPECT_EQ(out["backends"]["few"]["contacts"].size(), 1u);
  EXPECT_FALSE(out["backends"]["few"].contains("contacts_truncated"));
}

TEST(Trajectory, ResultsShareTheMassPropertiesMostBackendsReportAndKeepEveryOtherValue) {
  // Three backends on two bodies: `seed` simulates A with another inertia (a point-mass model);
  // every final state stays with its backend.
  const Json inertia = Json::array({{1, 0, 0}, {0, 1, 0}, {0, 0, 1}});
  const Json other = Json::array({{2, 0, 0}, {0, 2, 0}, {0, 0, 2}});
  auto body = [](double mass, const Json& i, double x) {
    return Json{{"mass", mass},
                {"static", false},
                {"center_of_mass", {x, 0, 0}},
                {"inertia", i},
                {"final", {{"position", {x + 1, 0, 0}}}}};
  };
  const Json scene = {
      {"metrics", Json::array({{{"name", "velocity_err_ke"}}})},
      {"error_vs_runtime", Json::array({{{"dt", 0.01}}})},
      {"backends",
       {{"custom", {{"bodies", {{"A", body(1, inertia, 0)}, {"B", body(2, inertia, 5)}}}}},
        {"seed", {{"bodies", {{"A", body(1, other, 0)}, {"B", body(2, inertia, 5)}}}}},
        {"ode", {{"bodies", {{"A", body(1, inertia, 0)}, {"B", body(2, inertia, 5.5)}}}}}}}};
  const Json out = results_scene_json(scene);
  // metrics.csv and error_vs_runtime.csv hold these.
  EXPECT_FALSE(out.contains("metrics"));
  EXPECT_FALSE(out.contains("error_vs_runtime"));
  // The scene's block: what most backends report.
  EXPECT_EQ(out["bodies"]["A"]["inertia"], inertia);
  EXPECT_EQ(out["bodies"]["B"]["center_of_mass"], Json::array({5, 0, 0}));
  EXPECT_EQ(out["bodies"]["B"]["mass"], 2);
  // Each backend keeps what differs, and its final state.
  EXPECT_EQ(out["backends"]["seed"]["bodies"]["A"]["inertia"], other);
  EXPECT_FALSE(out["backends"]["seed"]["bodies"]["A"].contains("mass"));
  EXPECT_EQ(out["backends"]["ode"]["bodies"]["B"]["center_of_mass"], Json::array({5.5, 0, 0}));
  EXPECT_FALSE(out["backends"]["custom"]["bodies"]["A"].contains("inertia"));
  for (const char* b : {"custom", "seed", "ode"})
    for (const char* name : {"A", "B"})
      EXPECT_TRUE(out["backends"][b]["bodies"][name].contains("final")) << b << " " << name;
  // Reading it back: a backend's value is its own where it has one, else the scene's.
  for (const auto& [b, entry] : scene["backends"].items())
    for (const auto& [name, original] : entry["bodies"].items())
      for (const char* key : kMassProperties) {
        const Json& mine = out["backends"][b]["bodies"][name];
        EXPECT_EQ(mine.contains(key) ? mine[key] : out["bodies"][name][key], original[key])
            << b << " " << name << " " << key;
      }
}

}  // namespace
}  // namespace rbx
