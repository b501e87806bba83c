// Contact-law residuals of real runs: every dynamics backend reports its impulses with the
// contract's signs (no pulling, friction against the slip on a sliding box), the custom engine
// obeys the laws to round-off on the friction and resting scenes (its solver checks them), and
// the scales and rows the report reads.
#include "comparisons/eval/law_residuals.h"

#include <gtest/gtest.h>

#include <cmath>

#include "comparisons/eval/json_io.h"
#include "comparisons/scene/scene_file.h"
#include "reference/backend.h"
#include "reference/dynamics_recorder.h"

namespace rbx {
namespace {

constexpr int kPull = static_cast<int>(Law::Pulling);
constexpr int kDiss = static_cast<int>(Law::Dissipation);

// The scene's residuals from `backend`'s run, divided by the scene's scales: worst and median.
struct Relative {
  ContactLaws laws;
  std::array<double, kLaws> worst{}, median{};
};

Relative run_relative(const std::string& backend, const Scene& scene) {
  const DynamicsResult r = find_backend(backend)->dynamics(scene, {});
  EXPECT_EQ(r.status, Status::Ok) << backend << ": " << r.message;
  Relative out;
  out.laws = r.laws;
  const LawScales scales = law_scales(scene);
  for (Law law : kAllLaws) {
    const int l = static_cast<int>(law);
    out.worst[l] = r.laws.residuals[l].worst / scales.of(law);
    out.median[l] = r.laws.residuals[l].median / scales.of(law);
  }
  return out;
}

TEST(LawScales, AreTheSmallestMovingBodysSizeMassAndTheFastestSpeed) {
  const Scene scene = load_scene(RBX_SOURCE_DIR "/scenes/analytic/headon_e05.toml");
  const LawScales s = law_scales(scene);
  // Two unit cubes (size: the diagonal, sqrt 3), masses 1 and 3, at 1 m/s and -1 m/s.
  EXPECT_NEAR(s.length, std::sqrt(3.0), 1e-12);
  EXPECT_DOUBLE_EQ(s.mass, 1.0);
  EXPECT_DOUBLE_EQ(s.speed, 1.0);
  EXPECT_DOUBLE_EQ(s.of(Law::Complementarity), 1.0);
}

TEST(ContactLaws, EveryDynamicsBackendReportsImpulsesWithTheContractsSigns) {
  // A 1 kg cube sliding down a 20 degree incline for 1 s from rest. Every contact pushes: a
  // flipped normal would pull on every point. Its friction opposes the slip: flipped, it would
  // miss 2 mu j_n |v_t| on every sliding point; at the median point (|v_t| about 0.75 m/s, half
  // the final speed; j_n at most a quarter of m g cos 20 dt on four corners) that is `flipped`
  // of the scene's scale, and a quarter of it separates the two whatever a library's friction
  // model (a pyramid, a soft contact) leaves at its median point.
  const Scene scene = load_scene(RBX_SOURCE_DIR "/scenes/friction/incline_slide.toml");
  const double per_point = 9.81 * std::cos(20.0 * M_PI / 180.0) * scene.sim.dt / 4.0;
  const double flipped =
      2.0 * scene.sim.friction * per_point * 0.75 / law_scales(scene).of(Law::Dissipation);
  for (const Backend& b : backends()) {
    if (!b.dynamics || b.user) continue;
    SCOPED_TRACE(b.name);
    const Relative r = run_relative(b.name, scene);
    ASSERT_TRUE(r.laws.measured);
    EXPECT_GT(r.laws.contacts, 100);
    // Round-off of impulses near m g dt, relative to the scene's m v: 1e-12 leaves room.
    EXPECT_LT(r.worst[kPull], 1e-12);
    // A frictionless model (custom-seed) misses all of it: nothing to check the sign of.
    if (b.friction) {
      EXPECT_LT(r.median[kDiss], flipped / 4.0);
    }
  }
}

TEST(ContactLaws, TheCustomEngineObeysThemToRoundOffOnTheFrictionAndRestingScenes) {
  // Its solver stops where these conditions hold; 1e-12 of the scene's scales is round-off of
  // impulses and velocities accumulated over thousands of steps (measured: below 1e-17).
  for (const char* file :
       {"friction/incline_slide", "friction/incline_stick", "friction/landing_slide",
        "friction/spin_to_rest", "friction/spin_landing", "friction/stack_five",
        "friction/tipping_box", "stress/resting_stack"}) {
    SCOPED_TRACE(file);
    const Scene scene = load_scene(std::string(RBX_SOURCE_DIR "/scenes/") + file + ".toml");
    const Relative r = run_relative("custom", scene);
    ASSERT_TRUE(r.laws.measured);
    EXPECT_GT(r.laws.contacts, 0);
    for (Law law : kAllLaws) EXPECT_LT(r.worst[static_cast<int>(law)], 1e-12) << to_string(law);
  }
}

TEST(LawRows, TakeTheWorstSceneAndTheMedianOfTheScenesMedians) {
  const Scene scene = load_scene(RBX_SOURCE_DIR "/scenes/analytic/headon_e05.toml");
  // Two scenes of one family through `custom`, one not measured through `ode`.
  auto ev_with = [](double cone_worst, double cone_median, bool measured) {
    SceneEvaluation ev;
    ev.family = "analytic";
    ContactLaws laws;
    laws.measured = measured;
    laws.contacts = 10;
    laws.residuals[static_cast<int>(Law::Cone)] = {cone_worst, cone_median};
    Json bj = {{"status", "ok"}};
    bj["contact_laws"] = {{"measured", measured}, {"contacts", laws.contacts}};
    for (Law law : kAllLaws)
      bj["contact_laws"][to_string(law)] = {
          {"worst", laws.residuals[static_cast<int>(law)].worst},
          {"median", laws.residuals[static_cast<int>(law)].median}};
    ev.json["backends"]["custom"] = bj;
    Json unmeasured = {{"status", "ok"}, {"contact_laws", {{"measured", false}}}};
    ev.json["backends"]["ode"] = unmeasured;
    return ev;
  };
  const std::vector<SceneEvaluation> evs = {ev_with(0.5, 0.1, true), ev_with(0.2, 0.3, true)};
  const std::vector<LawRow> rows = law_rows({scene, scene}, evs, {"custom", "ode"});
  ASSERT_EQ(rows.size(), 2u);
  const int cone = static_cast<int>(Law::Cone);
  EXPECT_EQ(rows[0].backend, "custom");
  EXPECT_EQ(rows[0].scenes, 2);
  EXPECT_EQ(rows[0].contacts, 20);
  EXPECT_DOUBLE_EQ(rows[0].worst[cone], 0.5);
  EXPECT_DOUBLE_EQ(rows[0].median[cone], 0.2);  // the median of 0.1 and 0.3
  EXPECT_DOUBLE_EQ(rows[0].relative[cone], 0.5 / law_scales(scene).of(Law::Cone));
  EXPECT_EQ(rows[1].backend, "ode");
  EXPECT_EQ(rows[1].scenes, 0);
  EXPECT_EQ(rows[1].unmeasured, 2);
}

TEST(ContactLaws, ABackendWithoutImpulsesSaysSoAndKeepsThePenetrationOfItsEvents) {
  // A researcher's backend that returns events (their depth at detection) and no impulses.
  const Scene scene = load_scene(RBX_SOURCE_DIR "/scenes/analytic/headon_e05.toml");
  DynamicsResult r;
  for (double depth : {0.02, 0.01, 0.0}) {
    CollisionEvent e;
    e.body_a = "A";
    e.body_b = "B";
    e.contact.depth = depth;
    r.events.push_back(e);
  }
  SceneEvaluation ev;
  ev.family = "analytic";
  ev.json["backends"]["mine"] = dynamics_result_json(make_bodies(scene), r, 0.0);
  const Json& laws = ev.json["backends"]["mine"]["contact_laws"];
  EXPECT_FALSE(laws["measured"].get<bool>());
  EXPECT_EQ(laws["contacts"].get<long>(), 3);
  EXPECT_DOUBLE_EQ(laws["penetration"]["worst"].get<double>(), 0.02);
  EXPECT_FALSE(laws.contains("cone"));
  const SceneLaws s = scene_laws(scene, ev, "mine");
  EXPECT_FALSE(s.measured);
  EXPECT_TRUE(s.penetration_only);
  const std::vector<LawRow> rows = law_rows({scene}, {ev}, {"mine"});
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].scenes, 0);
  EXPECT_EQ(rows[0].unmeasured, 1);
  EXPECT_DOUBLE_EQ(rows[0].penetration_only, 0.02 / law_scales(scene).length);
}

}  // namespace
}  // namespace rbx
