// The harness: a backend that throws or returns an error is reported as such, and every other
// backend still runs and is measured.
#include "comparisons/eval/harness.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "comparisons/eval/metrics.h"
#include "comparisons/scene/scene_file.h"
#include "reference/backend.h"

namespace rbx {
namespace {

// The registry's custom and exact backends, between one that throws from every call (first, so
// the others run after it) and one that returns status error.
std::vector<Backend> table_with_failing_backends() {
  Backend thrower{"thrower", "test: throws from every call",
                  [](const RigidBody&, const RigidBody&) -> ContactResult {
                    throw std::runtime_error("thrower: contact query failed");
                  },
                  [](const WorldDefinition&, const DynamicsOptions&) -> DynamicsResult {
                    throw std::runtime_error("thrower: dynamics run failed");
                  }};
  Backend failer{"failer", "test: returns error from every call",
                 [](const RigidBody&, const RigidBody&) {
                   return ContactResult{Status::Error, "failer: gave up", {}};
                 },
                 [](const WorldDefinition&, const DynamicsOptions&) {
                   return DynamicsResult{Status::Error, "failer: diverged", {}, {}, {}, {}, {}};
                 }};
  return {thrower, *find_backend("custom"), *find_backend("exact"), failer};
}

// The scene evaluated with table_with_failing_backends(), no dt study.
SceneEvaluation evaluate_beside_failing_backends(const Scene& scene) {
  const std::vector<Backend> table = table_with_failing_backends();
  HarnessOptions opt;
  opt.registry = &table;
  opt.studies = false;
  return evaluate_scene(scene, opt);
}

// True when some metric of `backend` is named `name`.
bool has_metric(const SceneEvaluation& ev, const std::string& backend, const std::string& name) {
  return std::any_of(ev.metrics.begin(), ev.metrics.end(),
                     [&](const Metric& m) { return m.backend == backend && m.name == name; });
}

TEST(Harness, AThrowingContactBackendDoesNotStopTheOthers) {
  // Two unit cubes overlapping by 0.1 along x: every working backend finds the contact.
  const Scene scene = parse_scene(
      "checks = [\"contact\"]\n[sim]\nduration = 0\n[[body]]\nname = \"A\"\n"
      "[[body]]\nname = \"B\"\nposition = [0.9, 0, 0]\n",
      "pair.toml");
  const SceneEvaluation ev = evaluate_beside_failing_backends(scene);
  const Json& b = ev.json["backends"];
  EXPECT_EQ(b["thrower"]["status"], "error");
  EXPECT_EQ(b["thrower"]["message"], "thrower: contact query failed");
  EXPECT_EQ(b["failer"]["status"], "error");
  EXPECT_EQ(b["failer"]["message"], "failer: gave up");
  for (const char* name : {"custom", "exact"}) {
    EXPECT_EQ(b[name]["status"], "ok") << name << ": " << b[name]["message"];
    EXPECT_FALSE(b[name]["contacts"].empty()) << name;
    EXPECT_TRUE(has_metric(ev, name, "depth_err")) << name;
  }
  EXPECT_FALSE(has_metric(ev, "thrower", "depth_err"));
}

TEST(Harness, AThrowingDynamicsBackendDoesNotStopTheOthers) {
  // The seed's face-face pair, shortened: custom runs and gets its conservation metrics.
  const Scene scene = parse_scene(
      "checks = [\"impulse\"]\n[sim]\nduration = 0.6\n[[body]]\nname = \"A\"\n"
      "position = [-1, 0, 0]\nvelocity = [1, 0, 0]\n[[body]]\nname = \"B\"\n"
      "position = [1, 0, 0]\nvelocity = [-1, 0, 0]\n",
      "face_face.toml");
  const SceneEvaluation ev = evaluate_beside_failing_backends(scene);
  const Json& b = ev.json["backends"];
  EXPECT_EQ(b["thrower"]["status"], "error");
  EXPECT_EQ(b["thrower"]["message"], "thrower: dynamics run failed");
  EXPECT_EQ(b["failer"]["status"], "error");
  EXPECT_EQ(b["failer"]["message"], "failer: diverged");
  EXPECT_EQ(b["custom"]["status"], "ok") << b["custom"]["message"];
  EXPECT_TRUE(has_metric(ev, "custom", "energy_err"));
  // exact has no dynamics: selected by default only where it serves, so it is not listed.
  EXPECT_FALSE(b.contains("exact"));
}

TEST(Harness, TheTypedRunsAndStabilityRowsSayWhatTheJsonSays) {
  // A cube dropped on a static slab, checked for stability, with a throwing and a failing
  // backend beside custom: ev.runs and ev.stability (what the pages render) carry each backend's
  // status, message, run time and stability rows as the scene's JSON has them, and a row
  // written back is its JSON entry, key for key.
  const Scene scene = parse_scene(
      "checks = [\"stability\"]\n[sim]\nduration = 0.2\ngravity = [0, 0, -9.81]\n"
      "[[body]]\nname = \"floor\"\nstatic = true\nsize = [4, 4, 0.2]\n"
      "position = [0, 0, -0.1]\n[[body]]\nname = \"cube\"\nposition = [0, 0, 0.6]\n",
      "drop.toml");
  const SceneEvaluation ev = evaluate_beside_failing_backends(scene);
  const Json& b = ev.json["backends"];
  ASSERT_EQ(ev.runs.size(), b.size());
  for (const BackendRun& r : ev.runs) {
    ASSERT_TRUE(b.contains(r.backend)) << r.backend;
    EXPECT_EQ(to_string(r.status), b[r.backend]["status"]) << r.backend;
    EXPECT_EQ(r.message, b[r.backend]["message"]) << r.backend;
    ASSERT_TRUE(r.runtime_s.has_value()) << r.backend;
    EXPECT_EQ(*r.runtime_s, b[r.backend]["runtime_s"].get<double>()) << r.backend;
  }
  ASSERT_NE(ev.run_of("thrower"), nullptr);
  EXPECT_EQ(ev.run_of("thrower")->status, Status::Error);
  EXPECT_EQ(ev.run_of("thrower")->message, "thrower: dynamics run failed");
  EXPECT_EQ(ev.run_of("nobody"), nullptr);
  const Json& stability = ev.json["stability"];
  ASSERT_TRUE(stability.contains("custom"));
  EXPECT_EQ(ev.run_of("custom")->stability, stability["custom"]["verdict"]);
  size_t rows = 0;
  for (const StabilityRow& row : ev.stability) {
    ASSERT_FALSE(row.study_step);  // the scene names no dt study
    ASSERT_TRUE(stability.contains(row.backend)) << row.backend;
    EXPECT_EQ(stability_json(row), stability[row.backend]) << row.backend;
    ++rows;
  }
  EXPECT_EQ(rows, stability.size());
  ASSERT_GE(rows, 1u);
}

TEST(Harness, ContactPhasesAndTheGeometryReadBackTyped) {
  // The face-face pair of the seed with its closed form: custom is rerun with first contact
  // 1/3 and 2/3 of a step later; the typed rows carry the JSON's numbers, a failed phase's
  // message, and nothing for a backend whose phases did not run.
  const Scene scene = parse_scene(
      "checks = [\"impulse\"]\n[sim]\nduration = 0.6\nrestitution = 1.0\n[[body]]\n"
      "name = \"A\"\nposition = [-1, 0, 0]\nvelocity = [1, 0, 0]\n[[body]]\nname = \"B\"\n"
      "position = [1, 0, 0]\nvelocity = [-1, 0, 0]\n[expect]\n[expect.body.A]\n"
      "velocity = [-1, 0, 0]\n[expect.body.B]\nvelocity = [1, 0, 0]\n",
      "face_face.toml");
  HarnessOptions opt;
  opt.backends = "custom";
  opt.studies = false;
  opt.timing_budget_s = 0.0;
  SceneEvaluation ev = evaluate_scene(scene, opt);
  ASSERT_NE(ev.run_of("custom"), nullptr);
  ASSERT_TRUE(ev.run_of("custom")->contact_phase.has_value());
  const Json& p = ev.json["backends"]["custom"]["contact_phase"];
  const ContactPhaseRow& row = *ev.run_of("custom")->contact_phase;
  EXPECT_EQ(row.written.error, p["written"].get<double>());
  EXPECT_EQ(row.one_third.error, p["1_3"].get<double>());
  EXPECT_EQ(row.worst.error, p["worst"].get<double>());
  EXPECT_FALSE(ev.has_geometry);  // no contact check
  // A phase that failed, and a contact check's geometry, as another process would send them.
  ev.json["backends"]["custom"]["contact_phase"]["2_3"] = "error: diverged";
  ev.json["geometry"] = {{"pair", "A-B"}};
  read_runs(ev);
  EXPECT_FALSE(ev.run_of("custom")->contact_phase->two_thirds.error.has_value());
  EXPECT_EQ(ev.run_of("custom")->contact_phase->two_thirds.failure, "error: diverged");
  EXPECT_TRUE(ev.has_geometry);
}

TEST(Harness, AStabilityNumberWrittenAsNullReadsBackAsNaN) {
  // A run whose energy overflowed has a non-finite drift, which JSON writes as null once the
  // evaluation crosses processes: reading it back gives NaN for the pages to show, not a throw.
  SceneEvaluation ev;
  ev.json = Json::parse(R"({"backends": {"b": {"status": "ok", "message": "", "runtime_s": 0.5}},
    "stability": {"b": {"status": "ok", "dt": 0.001, "restitution": 1, "nonfinite": true,
      "energy_growth_rel": null, "energy_drift_rel": null, "energy_change_rel": null,
      "max_penetration_rel": 0, "rest_penetration_rel": 0, "tunnelled_pairs": 0,
      "verdict": "unstable", "why": ["non-finite state"]}}})");
  read_runs(ev);
  ASSERT_EQ(ev.stability.size(), 1u);
  EXPECT_TRUE(std::isnan(ev.stability[0].energy_drift_rel));
  EXPECT_EQ(ev.stability[0].dt, 0.001);
  EXPECT_EQ(ev.run_of("b")->stability, "unstable");
}

TEST(Harness, BodiesThatStartStillAreJudgedAgainstTheMotionTheRunMade) {
  // Two free unit cubes (0.3 and 0.7 kg) placed at the same spot, at rest, no gravity, and a
  // backend that throws them apart with equal and opposite momenta (12 kg m/s, 1 kg m^2/s, each
  // to its round-off) and energy made from nothing. With no motion at the start to scale
  // against, the drifts are measured against the momenta the run made (round-off, not 1e135
  // against a floor of 1e-300) and the energy growth against the most kinetic energy it reached
  // (1: all of it made).
  const Scene scene = parse_scene(
      "checks = [\"impulse\", \"stability\"]\n[sim]\ndt = 0.01\nduration = 0.02\n"
      "gravity = [0, 0, 0]\n[[body]]\nname = \"A\"\nmass = 0.3\n[[body]]\nname = \"B\"\n"
      "mass = 0.7\n",
      "same_spot.toml");
  const auto state = [](const char* name, double mass, double sign, double t) {
    const double v = sign * 12 / mass, w = sign * 6 / mass;  // I = m / 6 for a unit cube
    return BodyFinal{name, Vec3(v * t, 0, 0), Quat::Identity(), Vec3(v, 0, 0), Vec3(0, 0, w)};
  };
  Backend apart{"apart", "test: throws two bodies apart", nullptr,
                [&](const WorldDefinition&, const DynamicsOptions&) {
                  DynamicsResult r;
                  for (double t : {0.01, 0.02})
                    r.samples.push_back({t, {state("A", 0.3, 1, t), state("B", 0.7, -1, t)}});
                  r.finals = r.samples.back().bodies;
                  return r;
                }};
  apart.library = false;
  const std::vector<Backend> table = {apart};
  HarnessOptions opt;
  opt.registry = &table;
  opt.studies = false;
  const SceneEvaluation ev = evaluate_scene(scene, opt);
  const auto value = [&](const std::string& name) {
    for (const Metric& m : ev.metrics)
      if (m.backend == "apart" && m.name == name) return m.value;
    ADD_FAILURE() << "no metric " << name;
    return -1.0;
  };
  EXPECT_LT(value("momentum_drift_err"), 1e-15);
  EXPECT_LT(value("angular_momentum_drift_err"), 1e-15);
  EXPECT_DOUBLE_EQ(value("energy_growth_err"), 1.0);
}

TEST(Harness, ATouchingAnswerIsTimedLikeAnyOther) {
  // Two cubes face to face at zero depth: libccd's MPR answers "touching, no normal". The answer
  // is timed like any (a query the fastest library could be), its error the depth it is scored
  // at (0 here: right).
  const Scene scene =
      load_scene(std::string(RBX_SOURCE_DIR) + "/scenes/contact/touching_zero_depth.toml");
  HarnessOptions opt;
  opt.backends = "libccd-mpr";
  opt.studies = false;
  const SceneEvaluation ev = evaluate_scene(scene, opt);
  ASSERT_EQ(ev.json["backends"]["libccd-mpr"]["status"], "touching");
  int points = 0;
  for (const ErrorRuntimePoint& p : ev.error_vs_runtime) {
    if (p.backend != "libccd-mpr" || p.kind != "contact-touching") continue;
    ++points;
    EXPECT_GT(p.timing.rounds, 0);
    EXPECT_EQ(p.error, 0.0);
  }
  EXPECT_EQ(points, 1);
}

TEST(Harness, ADynamicsRunIsTimedAgainWarmAndItsAnsweringRunReportedApart) {
  // The face-face pair, shortened, run by the engine (in process) and by ODE (isolated).
  const Scene scene = parse_scene(
      "checks = [\"impulse\"]\n[sim]\nduration = 0.2\n[[body]]\nname = \"A\"\n"
      "position = [-1, 0, 0]\nvelocity = [1, 0, 0]\n[[body]]\nname = \"B\"\n"
      "position = [1, 0, 0]\nvelocity = [-1, 0, 0]\n",
      "face_face.toml");
  for (const double budget : {0.0, 0.002}) {
    HarnessOptions opt;
    opt.backends = "custom,ode";
    opt.studies = false;
    opt.timing_budget_s = budget;
    const SceneEvaluation ev = evaluate_scene(scene, opt);
    for (const char* name : {"custom", "ode"}) {
      const Json& b = ev.json["backends"][name];
      ASSERT_EQ(b["status"], "ok") << name << ": " << b["message"];
      ASSERT_TRUE(b.contains("timing")) << name;
      const Json& t = b["timing"];
      const double median = b["runtime_s"].get<double>();
      EXPECT_GT(t["cold_s"].get<double>(), 0.0) << name;
      if (budget == 0.0) {
        // Untimed (rbx check): the answering run is the one run, and says so.
        EXPECT_EQ(t["rounds"], 1) << name;
        EXPECT_EQ(t["calls"], 1) << name;
        EXPECT_EQ(median, t["cold_s"].get<double>()) << name;
        continue;
      }
      // Timed: at least the plan's rounds for a slow call, the median inside its quartiles.
      EXPECT_GE(t["rounds"].get<int>(), TimingPlan{}.min_rounds_slow) << name;
      EXPECT_GE(t["calls"].get<long>(), t["rounds"].get<long>()) << name;
      EXPECT_LE(t["q25_s"].get<double>(), median) << name;
      EXPECT_LE(median, t["q75_s"].get<double>()) << name;
      const std::optional<double> typed =
          ev.run_of(name) ? ev.run_of(name)->runtime_s : std::nullopt;
      EXPECT_EQ(typed, median) << name << ": the typed run reads the median";
    }
  }
}
TEST(Harness, BodiesOverlappingAtRestThroughEveryBackendAreJudgedInFiniteNumbers) {
  // Two free cubes (0.3 and 0.7 kg) overlapping by 80 % at rest, no gravity: nothing in the scene
  // has energy. Every backend's conservation metrics are finite and small where momentum is kept
  // (a library pushing them apart pushes both ways); a backend that throws them apart is marked
  // unstable with the energy it made from nothing, one that leaves them still is not.
  const Scene scene = parse_scene(
      "checks = [\"stability\"]\n[sim]\ndt = 0.001\nduration = 0.2\ngravity = [0, 0, 0]\n"
      "[[body]]\nname = \"A\"\nmass = 0.3\n[[body]]\nname = \"B\"\nmass = 0.7\n"
      "position = [0.2, 0, 0]\n",
      "overlap_at_rest.toml");
  HarnessOptions opt;
  opt.studies = false;
  const SceneEvaluation ev = evaluate_scene(scene, opt);
  int judged = 0;
  for (const auto& [name, st] : ev.json["stability"].items()) {
    ++judged;
    double growth = -1.0;
    for (const Metric& m : ev.metrics) {
      if (m.backend != name || m.check != "stability") continue;
      EXPECT_TRUE(std::isfinite(m.value)) << name << " " << m.name;
      // Momentum is kept to round-off of the momenta the run made (1e-10: a soft contact's
      // iterative solve over 200 steps).
      if (m.name == "momentum_drift_err" || m.name == "angular_momentum_drift_err") {
        EXPECT_LT(m.value, 1e-10) << name << " " << m.name;
      }
      if (m.name == "energy_growth_err") growth = m.value;
    }
    ASSERT_GE(growth, 0.0) << name;
    const std::string why = st["why"].dump();
    if (growth > kUnstableEnergyGrowth) {
      EXPECT_EQ(st["verdict"], "unstable") << name;
      EXPECT_NE(why.find("energy from nothing"), std::string::npos) << name << " " << why;
    } else {
      EXPECT_EQ(why.find("energy"), std::string::npos) << name << " " << why;
    }
  }
  EXPECT_GE(judged, 4);
}

TEST(Harness, WithoutATableTheRegistryIsUsed) {
  // The seam changes nothing by default: --backends names come from the registry.
  const Scene scene = parse_scene("checks = [\"contact\"]\n[[body]]\nname = \"A\"\n", "one.toml");
  HarnessOptions opt;
  opt.backends = "thrower";
  EXPECT_THROW(evaluate_scene(scene, opt), InputError);
  opt.backends = "exact";
  EXPECT_NO_THROW(evaluate_scene(scene, opt));
}

TEST(HarnessExpect, AnEngineRunThatStopsFailsItsExpectationAndReferencesDoNotBindIt) {
  // Head-on equal masses, e = 1: they swap velocities (A ends at -1 m/s), as [expect] says.
  const Scene scene = parse_scene(
      "checks = [\"impulse\"]\n[[body]]\nname = \"A\"\nposition = [-1, 0, 0]\nvelocity = [1, 0, "
      "0]\n"
      "[[body]]\nname = \"B\"\nposition = [1, 0, 0]\nvelocity = [-1, 0, 0]\n"
      "[expect]\n[expect.body.A]\nvelocity = [-1, 0, 0]\n",
      "headon.toml");
  HarnessOptions opt;
  opt.studies = false;
  // The engine: checked and passed.
  opt.backends = "custom";
  SceneEvaluation ev = evaluate_scene(scene, opt);
  EXPECT_TRUE(ev.json["expect"]["checked"].get<bool>());
  EXPECT_TRUE(ev.json["expect"]["passed"].get<bool>()) << ev.json["expect"];
  // An engine whose run stops early: failed, not passed and not "not checked".
  std::vector<Backend> table = {*find_backend("custom")};
  table[0].dynamics = [](const WorldDefinition&, const DynamicsOptions&) {
    DynamicsResult r;
    r.status = Status::Error;
    r.message = "energy grew past the guard";
    return r;
  };
  opt.registry = &table;
  ev = evaluate_scene(scene, opt);
  EXPECT_TRUE(ev.json["expect"]["checked"].get<bool>());
  EXPECT_FALSE(ev.json["expect"]["passed"].get<bool>());
  ASSERT_EQ(ev.expect_failures.size(), 1u);
  EXPECT_NE(ev.expect_failures[0].find("energy grew past the guard"), std::string::npos);
  // Only a reference: nothing binds [expect.body].
  opt.registry = nullptr;
  opt.backends = "bullet";
  ev = evaluate_scene(scene, opt);
  EXPECT_FALSE(ev.json["expect"]["checked"].get<bool>());
  EXPECT_FALSE(ev.json["expect"]["passed"].get<bool>());
}

TEST(HarnessExpect, ItBindsTheEnginesItNamesTheCustomEngineByDefault) {
  // Head-on equal masses, e = 1: A ends at -1 m/s. The real custom engine meets it; a stand-in
  // for the seed's algorithm leaves A still (as the seed leaves a box sliding where friction
  // would stop it): marked as any backend is, but failing the scene only where [expect] binds it.
  const std::string text =
      "checks = [\"impulse\"]\n[[body]]\nname = \"A\"\nposition = [-1, 0, 0]\nvelocity = [1, 0, "
      "0]\n[[body]]\nname = \"B\"\nposition = [1, 0, 0]\nvelocity = [-1, 0, 0]\n[expect]\n";
  const std::string body = "[expect.body.A]\nvelocity = [-1, 0, 0]\n";
  std::vector<Backend> table = {*find_backend("custom"), *find_backend("custom-seed")};
  table[1].dynamics = [](const WorldDefinition& s, const DynamicsOptions&) {
    DynamicsResult r;
    for (const BodySpec& b : s.bodies)
      r.finals.push_back({b.name, b.position, b.orientation, Vec3::Zero(), Vec3::Zero()});
    return r;
  };
  HarnessOptions opt;
  opt.studies = false;
  opt.registry = &table;
  const auto run = [&](const std::string& expect) {
    return evaluate_scene(parse_scene(text + expect + body, "headon.toml"), opt);
  };
  SceneEvaluation ev = run("");
  EXPECT_TRUE(ev.json["expect"]["passed"].get<bool>()) << ev.json["expect"];
  EXPECT_EQ(ev.json["expect"]["engines"], Json({"custom"}));
  const std::string marks = ev.json["disagreements"].dump();
  EXPECT_NE(marks.find("custom-seed"), std::string::npos) << marks;
  ev = run("engines = [\"custom\", \"custom-seed\"]\n");
  ASSERT_EQ(ev.expect_failures.size(), 1u);
  EXPECT_EQ(ev.expect_failures[0].rfind("custom-seed: ", 0), 0u) << ev.expect_failures[0];
  EXPECT_FALSE(ev.expect_known);
  ev = run(
      "engines = [\"custom\", \"custom-seed\"]\nknown_failure = \"custom-seed: stands still\"\n");
  EXPECT_TRUE(ev.expect_known);
  // Binding only the seed's algorithm: the custom engine is marked, not bound.
  ev = run("engines = [\"custom-seed\"]\n");
  ASSERT_EQ(ev.expect_failures.size(), 1u);
  EXPECT_EQ(ev.expect_failures[0].rfind("custom-seed: ", 0), 0u);
}

TEST(HarnessExpect, AStatedPatchBindsTheOracleAndTheEnginesAcrossTheNormal) {
  // FCL's all-contacts case: a unit cube turned 45 deg about y, its lowest edge 0.707 m into a
  // size-3 cube's top face. The patch is that edge's segment, x = 0, -0.5 <= y <= 0.5, stated
  // at the height FCL publishes (z = -sqrt(2)/4); it is compared across the normal (+z), so
  // that height is not the oracle's own (midway) nor the seed's.
  const std::string text =
      "checks = [\"contact\"]\n[[body]]\nname = \"A\"\nrotation = [0, 45, 0]\n[[body]]\n"
      "name = \"B\"\nsize = [3, 3, 3]\nposition = [0, 0, -1.5]\n[expect]\ntolerance = 1e-9\n";
  const auto patch = [](double x) {
    return "[expect.contact]\npatch = [[" + std::to_string(x) + ", -0.5, -0.35355339059327373], [" +
           std::to_string(x) + ", 0.5, -0.35355339059327373]]\n";
  };
  std::vector<Backend> table = {*find_backend("custom")};
  HarnessOptions opt;
  opt.studies = false;
  opt.registry = &table;
  const auto run = [&](const std::string& expect, double x) {
    return evaluate_scene(parse_scene(text + expect + patch(x), "patch.toml"), opt);
  };
  // The oracle's and custom's points span the segment and lie on it.
  SceneEvaluation ev = run("", 0.0);
  EXPECT_TRUE(ev.expect_failures.empty()) << ev.json["expect"];
  // A stand-in for custom answering with its one point only cannot span it: bound, it falls
  // short by half the segment.
  std::vector<Backend> one_point = {*find_backend("custom")};
  one_point[0].contact = [](const RigidBody& a, const RigidBody& b) {
    ContactResult r = find_backend("custom")->contact(a, b);
    r.contacts.resize(1);
    return r;
  };
  opt.registry = &one_point;
  ev = run("", 0.0);
  ASSERT_EQ(ev.expect_failures.size(), 1u) << ev.json["expect"];
  EXPECT_EQ(ev.expect_failures[0],
            "custom: 1 contact point falls short of the [expect.contact] patch by 0.5 m");
  opt.registry = &table;
  // A patch stated 0.1 m off: the oracle and custom both fall short by 0.1 and lie 0.1 off it.
  ev = run("", 0.1);
  ASSERT_EQ(ev.expect_failures.size(), 4u) << ev.json["expect"];
  for (const std::string& f : ev.expect_failures) {
    EXPECT_TRUE(f.rfind("exact: ", 0) == 0 || f.rfind("custom: ", 0) == 0) << f;
    EXPECT_NE(f.find("0.1 m"), std::string::npos) << f;
  }
}

TEST(HarnessExpect, AKnownFailureExcusesAnEngineItBinds) {
  const std::string text = "[[body]]\nname = \"A\"\n[expect]\n";
  // Plain text, as the format's example shows it, excuses the custom engine.
  EXPECT_EQ(parse_scene(text + "known_failure = \"no friction\"\n", "t.toml").expect->known_failure,
            "custom: no friction");
  EXPECT_EQ(parse_scene(text + "known_failure = \"custom: no friction\"\n", "t.toml")
                .expect->known_failure,
            "custom: no friction");
  const auto message = [&](const std::string& expect) {
    try {
      parse_scene(text + expect, "t.toml");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(message("known_failure = \"custom-seed: no friction\"\n"),
            "t.toml:4: expect.known_failure: excuses custom-seed, which [expect] does not bind "
            "(engines = [\"custom\"]); write engines = [\"custom\", \"custom-seed\"] in [expect]");
  EXPECT_EQ(message("engines = [\"custom-seed\"]\nknown_failure = \"why\"\n"),
            "t.toml:5: expect.known_failure: excuses custom, which [expect] does not bind (engines "
            "= [\"custom-seed\"]); write engines = [\"custom-seed\", \"custom\"] in [expect]");
  EXPECT_EQ(message("known_failure = \"\"\n"),
            "t.toml:4: expect.known_failure: is empty; say why the engine misses the closed form, "
            "e.g. known_failure = \"no friction\"");
  EXPECT_EQ(message("engines = []\n"),
            "t.toml:4: expect.engines: lists no engine; write engines = [\"custom\"] (the default) "
            "or [\"custom\", \"custom-seed\"]");
  EXPECT_NE(message("engines = [\"bullet\"]\n").find("t.toml:4: expect.engines: "),
            std::string::npos);
}

}  // namespace
}  // namespace rbx

namespace rbx {
namespace {

TEST(Harness, TheThinWallGetsAVerdictAtEveryStepOfItsDtStudy) {
  // stress/tunnel_thin_wall names its own dt study (1e-2 .. 5e-5 s): the stability verdict is
  // given at each step. The custom engine's time of impact keeps the plate from passing the
  // wall at every one; the seed's algorithm passes through at the written 1e-2 s.
  const Scene scene =
      load_scene(std::string(RBX_SOURCE_DIR) + "/scenes/stress/tunnel_thin_wall.toml");
  HarnessOptions opt;
  opt.backends = "custom,custom-seed";
  const SceneEvaluation ev = evaluate_scene(scene, opt);
  ASSERT_TRUE(ev.json.contains("stability_dt_study"));
  const Json& others = ev.json["stability_dt_study"]["custom"];
  ASSERT_EQ(others.size(), scene.dt_study.size() - 1);  // every step but the scene's own
  std::vector<double> dts;
  for (const Json& s : others) {
    dts.push_back(s["dt"].get<double>());
    EXPECT_EQ(s["tunnelled_pairs"].get<int>(), 0) << "custom at dt = " << s["dt"];
  }
  for (double dt : scene.dt_study) {
    if (dt == scene.sim.dt) continue;
    EXPECT_NE(std::find(dts.begin(), dts.end(), dt), dts.end()) << dt;
  }
  EXPECT_EQ(ev.json["stability"]["custom"]["tunnelled_pairs"].get<int>(), 0);
  EXPECT_EQ(ev.json["stability"]["custom-seed"]["tunnelled_pairs"].get<int>(), 1);
}

}  // namespace
}  // namespace rbx

namespace rbx {
namespace {

// Two unit cubes overlapping by 0.1 along x ([-0.5, 0.5] and [0.4, 1.4]), with a stated point.
SceneEvaluation with_stated_point(const std::string& point) {
  const Scene scene = parse_scene(
      "checks = [\"contact\"]\n[sim]\nduration = 0\n[[body]]\nname = \"A\"\n"
      "[[body]]\nname = \"B\"\nposition = [0.9, 0, 0]\n"
      "[expect]\ntolerance = 1e-6\n[expect.contact]\ntouching = true\nnormal = [-1, 0, 0]\n"
      "depth = 0.1\npoint = " +
          point + "\n",
      "stated_point.toml");
  HarnessOptions opt;
  opt.backends = "exact";
  opt.studies = false;
  return evaluate_scene(scene, opt);
}

TEST(HarnessExpect, AStatedContactPointMustLieInTheTrueContactRegion) {
  // Inside both cubes (the overlap slab x in [0.4, 0.5]), on its face, or at a corner of the
  // patch: right, whichever model's representative point it is.
  for (const char* inside : {"[0.45, 0, 0]", "[0.5, 0.2, -0.3]", "[0.4, 0.5, 0.5]"}) {
    const SceneEvaluation ev = with_stated_point(inside);
    EXPECT_TRUE(ev.expect_failures.empty()) << inside << ": " << ev.expect_failures.front();
    EXPECT_TRUE(ev.expect_checked) << inside;
  }
  // Outside B by 0.02 (x = 0.38), or beyond the patch sideways: the stated point is wrong, and
  // the line says by how much.
  for (const char* outside : {"[0.38, 0, 0]", "[0.45, 0.7, 0]"}) {
    const SceneEvaluation ev = with_stated_point(outside);
    ASSERT_EQ(ev.expect_failures.size(), 1u) << outside;
    EXPECT_NE(ev.expect_failures.front().find("from the true contact region"), std::string::npos)
        << ev.expect_failures.front();
  }
}

TEST(HarnessExpect, MetricsNameTheTruthTheExpectBlockHolds) {
  // The same stated contact, as a closed form and as the oracle's answer written down (what
  // `rbx explore` writes into a shrunk scene): each metric names that truth.
  for (const std::string truth : {"analytic", "exact"}) {
    const Scene scene = parse_scene(
        "checks = [\"contact\"]\n[sim]\nduration = 0\n[[body]]\nname = \"A\"\n"
        "[[body]]\nname = \"B\"\nposition = [0.9, 0, 0]\n[expect]\ntruth = \"" +
            truth + "\"\n[expect.contact]\ntouching = true\nnormal = [-1, 0, 0]\ndepth = 0.1\n",
        "truth.toml");
    HarnessOptions opt;
    opt.backends = "custom";
    opt.studies = false;
    const SceneEvaluation ev = evaluate_scene(scene, opt);
    int named = 0;
    for (const Metric& m : ev.metrics)
      if (m.backend == "custom" &&
          (m.name == "normal_err_deg" || m.name == "depth_err" || m.name == "touching_err")) {
        EXPECT_EQ(m.against, truth) << m.name;
        ++named;
      }
    EXPECT_EQ(named, 3) << truth;
  }
}

}  // namespace
}  // namespace rbx
