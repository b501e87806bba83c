// The reference-result cache: results read back are byte-identical to an uncached run, ours
// (custom, exact) are never cached, and a change of the reference code misses.
#include "comparisons/eval/result_cache.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "comparisons/eval/explore_check.h"
#include "comparisons/eval/harness.h"
#include "comparisons/scene/scene_file.h"
#include "tests/common/fixtures.h"

namespace rbx {
namespace {

using test::temp_dir;

namespace fs = std::filesystem;

// The evaluation without what may differ between runs: timings and the "cached" labels.
Json without_timings(Json j) {
  if (j.is_object()) {
    j.erase("runtime_s");
    j.erase("timing");  // a query's timing (timing.h), measured anew or read with the answer
    j.erase("cached");
    for (auto& [k, v] : j.items()) v = without_timings(v);
  } else if (j.is_array()) {
    for (auto& v : j) v = without_timings(v);
  }
  return j;
}

class CacheScenes : public ::testing::TestWithParam<std::string> {};

TEST_P(CacheScenes, CachedResultsAreByteIdenticalToAnUncachedRun) {
  const fs::path dir = temp_dir("cache_identical");
  const Scene scene = load_scene(std::string(RBX_SOURCE_DIR) + "/scenes/" + GetParam());
  HarnessOptions opt;
  opt.studies = false;
  const std::string plain = without_timings(evaluate_scene(scene, opt).json).dump();
  opt.cache_dir = dir.string();
  const SceneEvaluation cold = evaluate_scene(scene, opt);  // fills the cache
  const SceneEvaluation warm = evaluate_scene(scene, opt);  // reads it
  EXPECT_EQ(without_timings(cold.json).dump(), plain);
  EXPECT_EQ(without_timings(warm.json).dump(), plain);
  int cached = 0;
  for (const auto& [name, bj] : warm.json["backends"].items()) {
    if (!ResultCache::caches(name)) {
      EXPECT_FALSE(bj.contains("cached")) << name << ": ours, under test, never cached";
    } else if (bj.value("cached", false)) {
      ++cached;
    }
    EXPECT_FALSE(cold.json["backends"][name].contains("cached")) << name;
  }
  EXPECT_GT(cached, 0) << "no reference result came from the cache";
  fs::remove_all(dir);
}

// Contact, impact with a closed form, trajectory, mass and stability scenes. The stability scene
// is a two-body one: its overlaps go through the cache as a stack's do, at a small part of the
// stack's cost under the sanitizers (docs/testing.md).
INSTANTIATE_TEST_SUITE_P(Library, CacheScenes,
                         ::testing::Values("contact/fcl_rotated_45.toml",
                                           "analytic/headon_e05.toml", "seed/edge_drop.toml",
                                           "mass/box_1x2x3.toml", "stress/mass_ratio_1e3.toml"));

TEST(ResultCache, OursAreNeverCached) {
  EXPECT_FALSE(ResultCache::caches("custom"));
  EXPECT_FALSE(ResultCache::caches("custom-seed"));
  EXPECT_FALSE(ResultCache::caches("exact"));
  EXPECT_TRUE(ResultCache::caches("bullet"));
}

TEST(ResultCache, AnotherReferenceCodeOrOtherInputsMiss) {
  const fs::path dir = temp_dir("cache_code");
  const Scene scene = parse_scene(
      "[[body]]\nname = \"A\"\n[[body]]\nname = \"B\"\nposition = [0.9, 0, 0]\n", "pair.toml");
  const std::vector<RigidBody> bodies = make_bodies(scene);
  const ResultCache before(dir.string(), "adapters 1111"), after(dir.string(), "adapters 2222");
  ContactResult r{
      Status::Ok, "note", {ContactPoint{Vec3(0.45, 0, 0), Vec3(-1, 0, 0), 0.1, "face"}}};
  const Timing timed{1.5e-6, 1.4e-6, 1.7e-6, 4200, 14, 3.1e-5};
  before.store(before.contact_key("fcl", bodies[0], bodies[1]), r, timed);
  const auto hit = before.load_contact(before.contact_key("fcl", bodies[0], bodies[1]));
  ASSERT_TRUE(hit);
  // The whole timing comes back as stored: the report's tables read it for a cached query.
  EXPECT_EQ(hit->timing.median_s, 1.5e-6);
  EXPECT_EQ(hit->timing.q25_s, 1.4e-6);
  EXPECT_EQ(hit->timing.q75_s, 1.7e-6);
  EXPECT_EQ(hit->timing.calls, 4200);
  EXPECT_EQ(hit->timing.rounds, 14);
  EXPECT_EQ(hit->timing.cold_s, 3.1e-5);
  ASSERT_EQ(hit->result.contacts.size(), 1u);
  EXPECT_EQ(hit->result.contacts[0].depth, 0.1);
  EXPECT_EQ(hit->result.message, "note");
  // An edited adapter (another source hash), another backend, other bodies: misses.
  EXPECT_FALSE(after.load_contact(after.contact_key("fcl", bodies[0], bodies[1])));
  EXPECT_FALSE(before.load_contact(before.contact_key("bullet", bodies[0], bodies[1])));
  std::vector<RigidBody> moved = bodies;
  moved[1].position.x() = std::nextafter(0.9, 1.0);
  EXPECT_FALSE(before.load_contact(before.contact_key("fcl", moved[0], moved[1])));
  // A truncated file is a miss, not a crash.
  for (const auto& e : fs::directory_iterator(dir))
    fs::resize_file(e.path(), fs::file_size(e.path()) - 3);
  EXPECT_FALSE(before.load_contact(before.contact_key("fcl", bodies[0], bodies[1])));
  fs::remove_all(dir);
}

// rbx report fills the cache without reading it (its timings are its own); rbx check, reading
// the same folder, finds what it stored.
TEST(ResultCache, AFillOnlyCacheStoresWhatItNeverReads) {
  const fs::path dir = temp_dir("cache_fill");
  const Scene scene = parse_scene(
      "[[body]]\nname = \"A\"\n[[body]]\nname = \"B\"\nposition = [0.9, 0, 0]\n", "pair.toml");
  const std::vector<RigidBody> bodies = make_bodies(scene);
  const ResultCache fill(dir.string(), "adapters 1111", false),
      check(dir.string(), "adapters 1111");
  const std::string key = fill.contact_key("fcl", bodies[0], bodies[1]);
  EXPECT_EQ(key, check.contact_key("fcl", bodies[0], bodies[1]));
  fill.store(key, ContactResult{Status::Ok, "", {}}, Timing::once(1e-6));
  EXPECT_FALSE(fill.load_contact(key));
  EXPECT_TRUE(check.load_contact(key));
  fill.store_derived(key, "toss errors", {1.0, 2.0});
  EXPECT_FALSE(fill.load_derived(key, "toss errors"));
  EXPECT_EQ(*check.load_derived(key, "toss errors"), std::vector<double>({1.0, 2.0}));
  fs::remove_all(dir);
}

// Explore's fixed samples read a library's answers from the cache the second time: the same
// metrics, and not one call to the library.
TEST(ResultCache, ExploreSamplesReadALibrarysAnswersBack) {
  const fs::path dir = temp_dir("cache_explore");
  const ResultCache cache(dir.string());
  std::vector<Backend> table = {*find_backend("exact"), *find_backend("fcl"),
                                *find_backend("bullet")};
  // Library calls run in a child process (isolate.h): each one leaves a byte in a file.
  const std::string log = (dir / "calls").string();
  const auto calls = [log] { return fs::exists(log) ? static_cast<int>(fs::file_size(log)) : 0; };
  const auto fcl = table[1].contact;
  table[1].contact = [fcl, log](const RigidBody& a, const RigidBody& b) {
    std::ofstream(log, std::ios::app) << 'x';
    return fcl(a, b);
  };
  const auto fcl_distance = table[1].distance;
  table[1].distance = [fcl_distance, log](const RigidBody& a, const RigidBody& b) {
    std::ofstream(log, std::ios::app) << 'x';
    return fcl_distance(a, b);
  };
  const auto bullet = table[2].dynamics;
  table[2].dynamics = [bullet, log](const WorldDefinition& s, const DynamicsOptions& o) {
    std::ofstream(log, std::ios::app) << 'x';
    return bullet(s, o);
  };
  ExploreCheckSet set;
  set.contact = 12;
  set.distance = 6;
  set.impact = 3;
  set.landing = set.slide = set.tunnel = set.toi = 0;
  const ParallelRun one(1);
  const auto first = explore_check_metrics({"fcl"}, {"bullet"}, set, &table, &one, &cache);
  EXPECT_EQ(calls(), 21);
  const auto second = explore_check_metrics({"fcl"}, {"bullet"}, set, &table, &one, &cache);
  EXPECT_EQ(calls(), 21);
  ASSERT_EQ(first.size(), second.size());
  for (size_t i = 0; i < first.size(); ++i) {
    EXPECT_EQ(first[i].metric.name, second[i].metric.name);
    EXPECT_EQ(first[i].metric.value, second[i].metric.value) << first[i].metric.name;
  }
  fs::remove_all(dir);
}

// The toi kind's library rows (the registry's: their queries and variants) are kept too: a run
// stores an answer per row and sample, and a second run stores nothing new and measures the same.
TEST(ResultCache, ExploreToiSamplesKeepALibrarysAnswers) {
  const fs::path dir = temp_dir("cache_explore_toi");
  const ResultCache cache(dir.string());
  const auto files = [&dir] {
    int n = 0;
    for (const auto& entry : fs::directory_iterator(dir)) n += entry.is_regular_file() ? 1 : 0;
    return n;
  };
  ExploreCheckSet set;
  set.contact = set.distance = set.impact = set.landing = set.slide = set.tunnel = 0;
  set.toi = 4;
  const ParallelRun one(1);
  const auto first = explore_check_metrics({"fcl"}, {}, set, nullptr, &one, &cache);
  const int stored = files();
  EXPECT_GE(stored, set.toi);  // fcl's rows on every sample the oracle settles
  const auto second = explore_check_metrics({"fcl"}, {}, set, nullptr, &one, &cache);
  EXPECT_EQ(files(), stored);
  ASSERT_EQ(first.size(), second.size());
  ASSERT_FALSE(first.empty());
  for (size_t i = 0; i < first.size(); ++i)
    EXPECT_EQ(first[i].metric.value, second[i].metric.value) << first[i].metric.name;
  fs::remove_all(dir);
}

// A timeout (the deadline of a loaded machine, not an answer of the inputs) is never kept, so the
// next run asks the library again; a library's error is kept like any answer.
TEST(ResultCache, TimeoutsAreNotKept) {
  const fs::path dir = temp_dir("cache_timeout");
  const Scene scene = parse_scene(
      "[[body]]\nname = \"A\"\n[[body]]\nname = \"B\"\nposition = [0.9, 0, 0]\n", "pair.toml");
  const std::vector<RigidBody> bodies = make_bodies(scene);
  const ResultCache cache(dir.string(), "adapters 1111");
  const std::string fcl = cache.contact_key("fcl", bodies[0], bodies[1]);
  const std::string ode = cache.contact_key("ode", bodies[0], bodies[1]);
  cache.store(fcl, ContactResult{Status::Timeout, "past the deadline", {}}, Timing::once(30.0));
  cache.store(ode, ContactResult{Status::Error, "aborted", {}}, Timing::once(0.1));
  EXPECT_FALSE(cache.load_contact(fcl));
  const auto kept = cache.load_contact(ode);
  ASSERT_TRUE(kept);
  EXPECT_EQ(kept->result.status, Status::Error);
  DynamicsResult slow;
  slow.status = Status::Timeout;
  const std::string run = cache.dynamics_key("bullet", scene, bodies, DynamicsOptions{});
  cache.store(run, slow, 600.0);
  EXPECT_FALSE(cache.load_dynamics(run));
  MassResult late;
  late.status = Status::Timeout;
  const std::string mass = cache.mass_key("mujoco", bodies[0]);
  cache.store(mass, late, 0.0);
  EXPECT_FALSE(cache.load_mass(mass));
  fs::remove_all(dir);
}

// The build-time half: the source hash (comparisons/hash_sources.cmake) changes with one byte
// of an adapter, so an edited adapter's cached results are never used.
TEST(ResultCache, EditingAnAdapterChangesTheSourceHash) {
  const fs::path dir = temp_dir("cache_hash");
  std::ofstream(dir / "fcl.cpp") << "int answer() { return 42; }\n";
  std::ofstream(dir / "ode.cpp") << "int other() { return 1; }\n";
  const auto hash = [&] {
    const std::string cmd = "cmake -DOUT='" + (dir / "h.h").string() +
                            "' '-DFILES=" + (dir / "fcl.cpp").string() + "|" +
                            (dir / "ode.cpp").string() + "' -DROOT='" + dir.string() +
                            "' -P '" RBX_SOURCE_DIR "/comparisons/hash_sources.cmake'";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
    std::ifstream in(dir / "h.h");
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const std::string first = hash();
  ASSERT_NE(first.find("RBX_REFERENCE_SOURCE_HASH"), std::string::npos) << first;
  EXPECT_EQ(hash(), first);  // deterministic
  std::ofstream(dir / "fcl.cpp") << "int answer() { return 43; }\n";
  EXPECT_NE(hash(), first);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rbx
