// rbx explore --kind toi: its samples ask what their motion class says (head-on ones touch,
// hair-misses do not), the written scene asks the same question, custom agrees with the oracle on
// them (the samples it once missed included), rbx toi's verdict excuses only what is decided
// at the nanometre, and the report's section counts what each row got wrong.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "comparisons/eval/explore.h"
#include "comparisons/eval/explore_campaign.h"
#include "comparisons/eval/explore_check.h"
#include "comparisons/eval/explore_detail.h"
#include "comparisons/eval/toi_query.h"
#include "comparisons/scene/scene_file.h"
#include "reference/exact.h"
#include "tests/common/fixtures.h"

namespace rbx {
namespace {

TEST(ExploreToi, HeadOnSamplesTouchAndHairMissesDoNot) {
  std::map<std::string, int> classes;
  for (uint64_t i = 0; i < 150; ++i) {
    const ToiSample s = make_toi_sample(3, i);
    ++classes[s.pair.pose_class];
    if (s.pair.pose_class != "head-on" && s.pair.pose_class != "hair-miss") continue;
    const Scene scene = parse_scene(toi_scene_text(s), "explore.toml");
    const std::vector<RigidBody> bodies = make_bodies(scene);
    const ToiResult truth = exact_toi(bodies[0], bodies[1], scene.sim.dt);
    ASSERT_EQ(truth.status, Status::Ok) << i;
    // Head-on: the gap closes within the interval, at a drawn 0.05 to 0.95 of it. Hair-miss: it
    // ends short by at least 1e-9 of the smaller size, far above the positions' round-off.
    if (s.pair.pose_class == "head-on") {
      EXPECT_TRUE(truth.hit) << i;
      EXPECT_GT(truth.fraction, 0.05 - 1e-9) << i;
      EXPECT_LT(truth.fraction, 0.95 + 1e-9) << i;
    } else {
      EXPECT_FALSE(truth.hit) << i << " at " << truth.fraction;
    }
  }
  EXPECT_EQ(classes.size(), 5u);  // every motion drawn
  for (const auto& [name, n] : classes) EXPECT_GT(n, 15) << name;
}

TEST(ExploreToi, TheWrittenSceneAsksTheSameQuestion) {
  for (uint64_t i = 0; i < 20; ++i) {
    const ToiSample s = make_toi_sample(5, i);
    const SampleOutcome o = evaluate_toi_sample(s, {"custom"});
    const Scene scene = parse_scene(toi_scene_text(s), "explore.toml");
    const ToiComparison c = compare_tois(scene, {"custom"}, scene.sim.dt, 0.0);
    ASSERT_EQ(c.pairs.size(), 1u);
    EXPECT_EQ(c.pairs[0].truth.hit, o.touching) << i;
    EXPECT_EQ(make_toi_sample(5, i).velocity_b, s.velocity_b) << i;  // a pure function
  }
}

TEST(ExploreToi, CustomAgreesWithTheOracleOnRandomSamples) {
  // Seed 11 (not used while developing), 300 samples; and three of seed 1 that custom missed or
  // put late before its steps took the touching features' own axes (a drift carrying two edges
  // a nanometre apart past each other: the closest points' direction, tilted by round-off, had
  // called the pair apart for good).
  std::vector<std::pair<uint64_t, uint64_t>> samples = {{1, 242}, {1, 805}, {1, 287}};
  for (uint64_t i = 0; i < 300; ++i) samples.push_back({11, i});
  for (const auto& [seed, index] : samples) {
    const SampleOutcome o = evaluate_toi_sample(make_toi_sample(seed, index), {"custom"});
    if (o.feature == "unresolved") continue;  // the oracle's own limit, counted nowhere
    ASSERT_EQ(o.backends.size(), 1u) << seed << " " << index;
    const BackendOutcome& b = o.backends[0];
    EXPECT_EQ(b.error, "") << "seed " << seed << " sample " << index << " (" << o.pose_class << ", "
                           << o.shapes << ", " << o.feature << "): " << b.message;
  }
}

// rbx toi's verdict on closed forms: a time 1e-3 of the interval early on a head-on landing
// disagrees, and says how far apart the pair is then (late: how deep); a touch reported on a pass
// that ends 1e-12 of the size short of touching is excused (the band), one that ends 1e-3 short is
// not.
TEST(ToiVerdict, OnlyWhatIsDecidedAtTheNanometreIsExcused) {
  RigidBody a = test::unit_cube("A", Vec3(0.2, 0.1, 1.3));
  const RigidBody b = test::unit_cube("B", Vec3::Zero());
  a.velocity = Vec3(0, 0, -0.6);  // touches at 0.5 of the interval of 1 s
  const ToiResult truth = exact_toi(a, b, 1.0);
  ASSERT_TRUE(truth.hit);
  ToiResult early = truth;
  early.fraction -= 1e-3;
  early.located = false;
  const ToiVerdict short_stop = judge_toi(early, truth, a, b, 1.0);
  EXPECT_EQ(short_stop.mark, "disagrees");
  // It stopped 1e-3 s of a 0.6 m/s fall short: the faces 6e-4 m apart, exactly (flat faces).
  EXPECT_NEAR(short_stop.separation_m, 6e-4, 1e-12);
  ToiResult late = truth;
  late.fraction += 0.05;
  late.located = false;
  // 0.05 s past the touch the faces overlap by 0.03 m.
  EXPECT_NEAR(judge_toi(late, truth, a, b, 1.0).separation_m, -0.03, 1e-12);
  early.fraction = truth.fraction - 1e-8;
  EXPECT_EQ(judge_toi(early, truth, a, b, 1.0).mark, "deviates");
  // The pass that ends just short: A falls 0.3 m less a hair.
  for (const double hair : {1e-12, 1e-3}) {
    RigidBody short_of = a;
    short_of.velocity = Vec3(0, 0, -(0.3 - hair));
    const ToiResult none = exact_toi(short_of, b, 1.0);
    ASSERT_FALSE(none.hit) << hair;
    ToiResult claimed;
    claimed.hit = true;
    claimed.fraction = 1.0;
    EXPECT_EQ(judge_toi(claimed, none, short_of, b, 1.0).mark, hair < 1e-9 ? "" : "disagrees")
        << hair;
  }
}

// The report's section from outcomes made by hand: rows ranked by disagreement rate, then median
// error; each kind of disagreement counted with its first sample; an early stop's and a late
// pass's separations as measured.
TEST(QueryFamily, RanksTheRowsAndCountsEachKindWithItsFirstSample) {
  auto row = [](const std::string& name, const std::string& error, double time_err,
                double separation) {
    BackendOutcome o;
    o.backend = name;
    o.error = error;
    o.measured = error != "misses" && error != "error";
    o.time_err = time_err;
    o.separation_m = separation;
    return o;
  };
  std::vector<std::string> encoded;
  for (uint64_t i = 0; i < 4; ++i) {
    SampleOutcome s;
    s.index = 10 + i;
    s.backends.push_back(row("good", "", 1e-12 * static_cast<double>(i + 1), 0.0));
    s.backends.push_back(i == 1 ? row("short", "late", 0.2, -2e-4)
                                : row("short", "early", 0.1, 1e-3 * static_cast<double>(i + 1)));
    // Sample 13: right, though 5e-3 of the interval off (a grazing touch the verdict excused).
    s.backends.push_back(i == 0   ? row("lost", "misses", 0.0, 0.0)
                         : i == 3 ? row("lost", "", 5e-3, 0.0)
                                  : row("lost", "", 1e-9, 0.0));
    encoded.push_back(encode(s));
  }
  const QueryFamily f = query_family("explore/toi", "time_err", encoded);
  EXPECT_EQ(f.count, 4);
  ASSERT_EQ(f.rows.size(), 3u);
  EXPECT_EQ(f.rows[0].backend, "good");
  EXPECT_EQ(f.rows[1].backend, "lost");
  EXPECT_EQ(f.rows[2].backend, "short");
  EXPECT_EQ(f.rows[0].disagreements, 0);
  EXPECT_EQ(f.rows[0].measured, 4);
  EXPECT_DOUBLE_EQ(f.rows[0].quantiles.front(), 1e-12);
  EXPECT_DOUBLE_EQ(f.rows[0].quantiles.back(), 4e-12);
  EXPECT_EQ(f.rows[0].quantiles.size(), 21u);
  const QueryFamilyRow& lost = f.rows[1];
  EXPECT_EQ(lost.disagreements, 1);
  EXPECT_EQ(lost.measured, 3);
  EXPECT_EQ(lost.grazing, 1);
  EXPECT_EQ(f.rows[0].grazing, 0);
  ASSERT_EQ(lost.kinds.size(), 1u);
  EXPECT_EQ(lost.kinds[0].name, "misses");
  EXPECT_EQ(lost.kinds[0].first, 10u);
  const QueryFamilyRow& shorter = f.rows[2];
  EXPECT_EQ(shorter.disagreements, 4);
  ASSERT_EQ(shorter.kinds.size(), 2u);
  EXPECT_EQ(shorter.kinds[0].name, "early");  // three, before the one late
  EXPECT_EQ(shorter.kinds[0].count, 3);
  EXPECT_EQ(shorter.kinds[0].first, 10u);
  EXPECT_DOUBLE_EQ(shorter.kinds[0].separation_p50, 3e-3);  // of 1, 3 and 4 mm
  EXPECT_DOUBLE_EQ(shorter.kinds[0].separation_max, 4e-3);
  EXPECT_EQ(shorter.kinds[1].name, "late");
  EXPECT_EQ(shorter.kinds[1].first, 11u);
  EXPECT_DOUBLE_EQ(shorter.kinds[1].separation_p50, 2e-4);
}

// A toi group's pair is shrunk over the same motion while the row still shows the group's
// signature, and the written scene reproduces it through `rbx toi`: `bullet-hull`'s cast stops
// within its 1 mm, early, on the first head-on sample it answers so.
TEST(ExploreToi, AGroupIsShrunkAndItsSceneReproducesIt) {
  uint64_t index = 0;
  std::string sig;
  for (; index < 100 && sig.empty(); ++index) {
    const ToiSample s = make_toi_sample(1, index);
    if (s.pair.pose_class != "head-on") continue;
    const SampleOutcome o = evaluate_toi_sample(s, {"bullet-hull"});
    for (const BackendOutcome& b : o.backends)
      if (b.backend == "bullet-hull" && b.error == "early") sig = signature(o, b);
  }
  ASSERT_FALSE(sig.empty()) << "no head-on sample bullet-hull stops early on";
  ExploreSettings set;
  set.kind = "toi";
  set.count = 100;
  const Json g = {
      {"backend", "bullet-hull"}, {"signature", sig}, {"first_sample", index - 1}, {"count", 1}};
  const Json r = Json::parse(explore_detail::shrink_group(g, set));
  ASSERT_TRUE(r["ok"].get<bool>()) << r.dump();
  EXPECT_TRUE(r["reproduced"].get<bool>()) << r["harness"];
  EXPECT_LE(r["points_after"].get<int>(), r["points_before"].get<int>());
  EXPECT_GT(r["evaluations"].get<int>(), 1);
  const std::string text = r["text"];
  EXPECT_NE(text.find("the motion as drawn"), std::string::npos) << text;
  EXPECT_EQ(text.find("(0 simplifications kept"), std::string::npos) << text;
  // It states the oracle's first touch, which the oracle and custom meet.
  ASSERT_NE(text.find("[expect.toi]\ntouch = true\nfraction = "), std::string::npos) << text;
  const Scene scene = parse_scene(text, "shrunk.toml");
  const ToiComparison c = compare_tois(scene, {"custom", "bullet-hull"}, scene.sim.dt, 0.0);
  EXPECT_EQ(c.expect.met, (std::vector<std::string>{"exact", "custom"}));
  EXPECT_TRUE(c.expect.failing.empty());
}

}  // namespace
}  // namespace rbx
