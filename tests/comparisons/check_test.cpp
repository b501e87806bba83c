// `rbx check` against a broken copy of the engine: every changed metric is named under its scene
// and backend, worse and better, and --update refuses to record a regression.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "comparisons/cli/commands.h"
#include "engine/detect.h"
#include "reference/backend.h"
#include "reference/custom.h"
#include "tests/common/fixtures.h"

namespace rbx {
namespace {

using test::temp_dir;

// The backends under test, by their registry names.
const Backend& custom = custom_adapter().backend("custom");
const Backend& custom_seed = custom_adapter().backend("custom-seed");

namespace fs = std::filesystem;

// The registry with `custom` replaced by a broken copy: its contact normals turned 2 degrees
// about the world z axis, and its final velocities off by 1e-3 m/s along x. An engine edit that
// moves answers this much must never pass the check.
std::vector<Backend> table_with_broken_engine() {
  std::vector<Backend> table = backends();
  for (Backend& b : table) {
    if (b.name != "custom") continue;
    b.contact = [](const RigidBody& a, const RigidBody& bb) {
      ContactResult r = custom.contact(a, bb);
      const Quat turn(Eigen::AngleAxisd(2.0 * M_PI / 180.0, Vec3::UnitZ()));
      for (ContactPoint& c : r.contacts) c.normal = turn * c.normal;
      return r;
    };
    b.dynamics = [](const WorldDefinition& s, const DynamicsOptions& o) {
      DynamicsResult r = custom.dynamics(s, o);
      for (BodyFinal& f : r.finals) f.velocity.x() += 1e-3;
      return r;
    };
  }
  return table;
}

struct CheckRun {
  int code = -1;
  std::string out;
};

CheckRun run_check(ReportOptions opt) {
  opt.no_cache = true;  // this test's own results only; the cache has its own test
  testing::internal::CaptureStdout();
  CheckRun r;
  r.code = check_command(opt);
  r.out = testing::internal::GetCapturedStdout();
  return r;
}

// A contact scene (axis_x: the normal is exactly -x) and an impact with a closed form
// (headon_e05): the broken copy's normal error and velocity error both grow.
const std::vector<std::string> kScenes = {RBX_SOURCE_DIR "/scenes/contact/axis_x.toml",
                                          RBX_SOURCE_DIR "/scenes/analytic/headon_e05.toml"};

TEST(Check, ABrokenEngineCopyFailsAndEveryChangedMetricIsNamed) {
  const fs::path dir = temp_dir("check_broken");
  ReportOptions opt;
  opt.inputs = kScenes;
  opt.baseline = (dir / "baseline.json").string();
  opt.update = true;
  ASSERT_EQ(run_check(opt).code, 0);
  const std::string recorded = [&] {
    std::ifstream in(opt.baseline);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }();

  const std::vector<Backend> broken = table_with_broken_engine();
  ReportOptions check = opt;
  check.update = false;
  check.registry = &broken;
  const CheckRun r = run_check(check);
  EXPECT_EQ(r.code, 1) << r.out;
  // Grouped: the scene, then the backend, then the metric with old -> new and the change.
  const size_t contact = r.out.find("contact/axis_x\n  custom\n");
  ASSERT_NE(contact, std::string::npos) << r.out;
  EXPECT_NE(r.out.find("worse   contact A-B normal_err_deg: 0 -> 2 (+2 deg)", contact),
            std::string::npos)
      << r.out;
  const size_t impact = r.out.find("analytic/headon_e05\n  custom\n");
  ASSERT_NE(impact, std::string::npos) << r.out;
  EXPECT_NE(r.out.find("worse   impulse velocity_err_ke:", impact), std::string::npos) << r.out;
  // The references did not change, so no other backend is listed.
  EXPECT_EQ(r.out.find("\n  bullet\n"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("some errors shrank"), std::string::npos) << r.out;

  // --update refuses to record the regression, and leaves the baseline as it was.
  ReportOptions update = check;
  update.update = true;
  const CheckRun refused = run_check(update);
  EXPECT_EQ(refused.code, 1);
  EXPECT_NE(refused.out.find("--update refused"), std::string::npos) << refused.out;
  EXPECT_NE(refused.out.find("--accept-worse"), std::string::npos) << refused.out;
  {
    std::ifstream in(opt.baseline);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), recorded);
  }
  // With --accept-worse it is recorded; then the healthy engine shows as better, named too.
  update.accept_worse = true;
  EXPECT_EQ(run_check(update).code, 0);
  opt.update = false;
  const CheckRun healed = run_check(opt);
  EXPECT_EQ(healed.code, 0) << healed.out;
  EXPECT_NE(healed.out.find("better  contact A-B normal_err_deg: 2 -> 0 (-2 deg)"),
            std::string::npos)
      << healed.out;
  EXPECT_NE(healed.out.find("some errors shrank"), std::string::npos) << healed.out;
  fs::remove_all(dir);
}

TEST(Check, BackendsLimitTheComparisonAndUpdateMergesOnlyWhatRan) {
  const fs::path dir = temp_dir("check_merge");
  ReportOptions opt;
  opt.inputs = {kScenes[0]};
  opt.baseline = (dir / "baseline.json").string();
  opt.update = true;
  ASSERT_EQ(run_check(opt).code, 0);
  // A metric of a scene not in the run, and a bullet metric made to look better in the past.
  nlohmann::json b;
  std::ifstream(opt.baseline) >> b;
  b["metrics"]["other/not_run | contact | fcl | A-B | depth_err"] = 0.25;
  std::string bullet_key;
  for (auto& [k, v] : b["metrics"].items())
    if (k.find(" | bullet | ") != std::string::npos &&
        k.find("normal_err_deg") != std::string::npos) {
      bullet_key = k;
      v = -1.0;  // below any error: the rerun is worse
    }
  ASSERT_FALSE(bullet_key.empty());
  std::ofstream(opt.baseline) << b.dump(2);

  ReportOptions check = opt;
  check.update = false;
  EXPECT_EQ(run_check(check).code, 1);  // every backend: bullet is worse
  check.backends = "custom,exact";
  const CheckRun only = run_check(check);
  EXPECT_EQ(only.code, 0) << only.out;  // bullet's metrics are not compared
  // --update with --backends merges custom's and exact's metrics: bullet's stays, and so does
  // the scene that did not run.
  ReportOptions update = check;
  update.update = true;
  ASSERT_EQ(run_check(update).code, 0);
  nlohmann::json after;
  std::ifstream(opt.baseline) >> after;
  EXPECT_EQ(after["metrics"][bullet_key], -1.0);
  EXPECT_EQ(after["metrics"]["other/not_run | contact | fcl | A-B | depth_err"], 0.25);
  EXPECT_EQ(after["metrics"].size(), b["metrics"].size());
  // In key order whatever was merged, so that a partial update changes only its own lines.
  nlohmann::ordered_json in_order;
  std::ifstream(opt.baseline) >> in_order;
  std::vector<std::string> keys;
  for (const auto& [k, v] : in_order["metrics"].items()) keys.push_back(k);
  EXPECT_TRUE(std::is_sorted(keys.begin(), keys.end()));
  fs::remove_all(dir);
}

TEST(Check, AKnownFailureThatPassesIsNamed) {
  // Two unit cubes overlapping by 0.1 along x, an exact [expect.contact] the engine meets, and a
  // known_failure claiming it does not: check says to remove it.
  const fs::path dir = temp_dir("check_known");
  std::ofstream(dir / "known.toml")
      << "checks = [\"contact\"]\n[sim]\nduration = 0\n[[body]]\nname = \"A\"\n"
         "[[body]]\nname = \"B\"\nposition = [0.9, 0, 0]\n[expect]\ntolerance = 1e-9\n"
         "known_failure = \"custom: thought to miss this\"\n[expect.contact]\nnormal = [-1, 0, 0]\n"
         "depth = 0.1\n";
  ReportOptions opt;
  opt.inputs = {(dir / "known.toml").string()};
  opt.baseline = (dir / "baseline.json").string();
  opt.backends = "custom,exact";
  opt.update = true;
  const CheckRun r = run_check(opt);
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("custom now meets [expect], a known failure: remove known_failure from"),
            std::string::npos)
      << r.out;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rbx

namespace rbx {
namespace {

TEST(Check, AChangeThatOnlyBreaksRandomPosesIsNamedByTheExploreSamples) {
  // The broken copy keeps custom's points and takes the normal and depth of the seed's first
  // hit (the plane of the first face the tests meet): right on axis_x, whose bodies are
  // axis-aligned, wrong on many random poses. Its points stay custom's, so that the set's
  // metrics (coverage) do not name it on the scene either. The scene alone passes; with
  // explore's fixed samples the check names the regression.
  std::vector<Backend> broken = backends();
  for (Backend& b : broken)
    if (b.name == "custom")
      b.contact = [own = b.contact](const RigidBody& a, const RigidBody& c) {
        ContactResult r = own(a, c);
        if (const auto hit = detect(*a.shape, a.pose(), *c.shape, c.pose()))
          for (ContactPoint& p : r.contacts) {
            p.normal = hit->normal;
            p.depth = hit->depth;
          }
        return r;
      };
  const fs::path dir = temp_dir("check_random_poses");
  ReportOptions opt;
  opt.inputs = {RBX_SOURCE_DIR "/scenes/contact/axis_x.toml"};
  opt.backends = "custom";
  opt.explore = true;
  // Contact samples only, fewer than the check's 2,000: the broken copy is wrong on a large
  // share of random poses, so 400 of them name it as surely (and the sanitizer pass stays short).
  opt.explore_samples.contact = 400;
  opt.explore_samples.impact = 0;
  opt.explore_samples.landing = 0;
  opt.explore_samples.slide = 0;
  opt.explore_samples.tunnel = 0;
  opt.baseline = (dir / "baseline.json").string();
  opt.update = true;
  ASSERT_EQ(run_check(opt).code, 0);

  ReportOptions check = opt;
  check.update = false;
  check.registry = &broken;
  check.explore = false;
  const CheckRun scenes_only = run_check(check);
  EXPECT_EQ(scenes_only.code, 0) << scenes_only.out;
  check.explore = true;
  const CheckRun r = run_check(check);
  EXPECT_EQ(r.code, 1) << r.out;
  const size_t at = r.out.find("explore/contact\n  custom\n");
  ASSERT_NE(at, std::string::npos) << r.out;
  EXPECT_NE(r.out.find("worse   explore disagreement_rate_err: 0 -> ", at), std::string::npos)
      << r.out;
  fs::remove_all(dir);
}

TEST(Check, AChangeThatOnlyBreaksTheMeasuredTossesIsNamed) {
  // The broken copy simulates with the seed's frictionless impulse: axis_x (a contact query)
  // cannot see it; the measured tosses, where the real cube slides to rest by friction, do.
  std::vector<Backend> broken = backends();
  for (Backend& b : broken)
    if (b.name == "custom") b.dynamics = custom_seed.dynamics;
  const fs::path dir = temp_dir("check_tosses");
  ReportOptions opt;
  opt.inputs = {RBX_SOURCE_DIR "/scenes/contact/axis_x.toml"};
  opt.backends = "custom";
  opt.tosses = true;
  opt.baseline = (dir / "baseline.json").string();
  opt.update = true;
  ASSERT_EQ(run_check(opt).code, 0);

  ReportOptions check = opt;
  check.update = false;
  check.registry = &broken;
  const CheckRun r = run_check(check);
  EXPECT_EQ(r.code, 1) << r.out;
  const size_t at = r.out.find("tosses/cube_toss\n  custom\n");
  ASSERT_NE(at, std::string::npos) << r.out;
  EXPECT_NE(r.out.find("worse   tosses position_err_p50: ", at), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("contact/axis_x\n"), std::string::npos) << r.out;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rbx
