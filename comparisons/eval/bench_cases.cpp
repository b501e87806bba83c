// `rbx bench`: the performance comparison of the contact query, the broad phase and the whole step.
//
// Five families of cases (the table kFamilies below), each built as groups of cases that are
// timed together (comparisons/eval/timing.h: rounds in turns, the first case rotating, until each
// has its minimum time and count of rounds):
//   - narrowphase: every contact backend through the registry's ContactFn, on the same convex
//     pairs (a unit box, and hulls of N random points on a sphere of diameter 1) at the same
//     poses (touching, deep, separated); a group is one shape size and pose kind. One call is
//     one query at each of the next poses of the cycle; ns_per_query is the time per call over
//     the number of poses.
//   - distance: every distance query (distance_backends()) on the narrow phase's shapes, B 1 %
//     and 20 % of the size beyond touching; a group is one shape size and gap.
//   - broadphase: the engine's broad-phase methods finding the pairs of a crowd of cubes (a
//     fixed density, so the pairs per body stay constant), after a small motion of every body
//     per step (the motion is not timed); a group is one crowd size.
//   - step: whole dynamics runs of scenes/many/ with the custom engine and Bullet, each for two
//     durations; a group is one scene. Each round's difference in time over the difference in
//     steps removes the set-up (building worlds and shapes), leaving microseconds per body per
//     step.
//   - explore: `rbx explore`'s contact samples per minute on one thread.
// Every case's warm-up runs first and alone, timed (its cold pass, reported apart: caches,
// lazily built hierarchies, page faults). Google Benchmark, which the bench used before, times
// one case after another and keeps the fastest repetition; it cannot take turns between cases,
// and a ratio of two cases timed minutes apart carried the machine's load between them.
// The pages (perf.md, perf.json, perf.csv, figures) are written by comparisons/output/.
#include "comparisons/eval/bench_cases.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <thread>
#include <utility>

#include "comparisons/eval/bench_detail.h"
#include "comparisons/eval/explore.h"
#include "comparisons/eval/explore_campaign.h"
#include "comparisons/eval/json_io.h"
#include "comparisons/eval/metrics.h"
#include "comparisons/eval/parallel.h"
#include "comparisons/scene/mesh_io.h"
#include "comparisons/scene/scene_file.h"
#include "engine/world.h"

namespace rbx {

namespace fs = std::filesystem;

BenchPlan bench_plan(bool quick) {
  BenchPlan p;
  p.quick = quick;
  if (quick) {
    p.hull_sizes = {32, 128, 512, 2048};
    p.poses = kBenchPoseCycle;
    p.poses_per_iteration = 3;
    p.min_time = 0.02;
    p.crowd_sizes = {1000, 2000, 5000};
    p.crowd_min_time = 0.05;
    p.steps_100 = {10, 60};
    p.steps_1000 = {2, 32};
    p.step_min_time = 0.1;
    p.step_rounds = 5;
    p.explore_samples = 500;
    p.explore_min_time = 0.5;
  } else {
    p.hull_sizes = {32, 128, 512, 2048, 8192};
    p.poses = kBenchPoseCycle;
    p.poses_per_iteration = 5;
    p.min_time = 0.2;
    p.crowd_sizes = {1000, 2000, 5000, 10000, 20000};
    p.crowd_min_time = 0.3;
    // The long runs are long enough that a round's difference (tens of milliseconds) stands
    // well above the noise of building the world.
    p.steps_100 = {20, 420};
    p.steps_1000 = {10, 310};
    p.step_min_time = 0.2;
    // The whole step's ratios carry goals: more rounds narrow their median.
    p.step_rounds = 15;
  }
  return p;
}

namespace {

using bench_detail::CaseSet;
using bench_detail::CaseTimes;
using bench_detail::distance_cases;
using bench_detail::narrowphase_cases;
using bench_detail::toi_cases;

// ---------------------------------------------------------------------------------------------
// Broad phase: every method of kBenchBroadPhaseMethods on crowds of growing size.

// Crowds per size, taken in turn (see broadphase_cases).
constexpr int kBenchCrowds = 16;

CaseSet broadphase_cases(const BenchPlan& plan, std::mt19937_64& rng) {
  struct State {
    BroadRow row;
    std::string name;
    BroadPhaseMethod method;
    std::shared_ptr<const std::vector<std::vector<RigidBody>>> crowds;
    long pairs = 0, steps = 0;
    // Working copies, so that every method starts from the same crowds and moves them by the
    // same jitter; each crowd with its own broad phase (sweep and prune keeps its order).
    // Several crowds taken in turn, not one: on one crowd moved by a millimetre the branch
    // predictor learns the outcomes of the small crowds and not of the large (measured, the
    // grid at 1,000 / 2,000 / 5,000 / 10,000 bodies: 86 / 95 / 195 / 251 ns per body on one
    // crowd, 209 / 219 / 230 / 227 on 16 crowds in turn), which bent the fitted exponent.
    std::vector<std::vector<RigidBody>> bodies;
    std::vector<std::unique_ptr<BroadPhase>> bp;
    std::mt19937_64 jitter;
    std::normal_distribution<double> g{0.0, 1e-3};  // m per step: 1 m/s at dt = 1 ms
  };
  CaseSet set;
  std::vector<std::shared_ptr<State>> states;
  for (int n : plan.crowd_sizes) {
    auto crowd = std::make_shared<std::vector<std::vector<RigidBody>>>();
    for (int k = 0; k < kBenchCrowds; ++k) crowd->push_back(cube_crowd(n, rng));
    BenchGroup group;
    group.name = "broadphase/" + std::to_string(n);
    group.plan.min_time_s = plan.crowd_min_time;
    for (BroadPhaseMethod m : kBenchBroadPhaseMethods) {
      auto c = std::make_shared<State>();
      c->row.method = to_string(m);
      c->row.bodies = n;
      c->name = "broadphase/" + c->row.method + "/" + std::to_string(n);
      c->method = m;
      c->crowds = crowd;
      states.push_back(c);
      BenchCase bc;
      bc.name = c->name;
      bc.warm_up = [c] {
        c->bodies = *c->crowds;
        c->bp.clear();
        for (const auto& crowd : c->bodies) {
          c->bp.push_back(std::make_unique<BroadPhase>(c->method));
          c->bp.back()->find_pairs(crowd);
        }
        c->jitter.seed(7);
        c->g.reset();
      };
      bc.set_up = [c] {
        for (RigidBody& b : c->bodies[c->steps % kBenchCrowds])
          b.position += Vec3(c->g(c->jitter), c->g(c->jitter), c->g(c->jitter));
      };
      bc.body = [c] {
        const int k = static_cast<int>(c->steps % kBenchCrowds);
        const long found = static_cast<long>(c->bp[k]->find_pairs(c->bodies[k]).size());
        c->pairs += found;
        ++c->steps;
      };
      group.cases.push_back(bc);
    }
    set.groups.push_back(std::move(group));
  }
  set.collect = [states](const CaseTimes& times, BenchResults& out) {
    for (const auto& c : states) {
      BroadRow r = c->row;
      r.ns_per_step = times.time(c->name, 1e9);
      if (c->steps > 0) r.pairs_per_step = static_cast<double>(c->pairs) / c->steps;
      out.broad.push_back(r);
    }
  };
  return set;
}

// ---------------------------------------------------------------------------------------------
// Whole step: scenes/many/ through each runner for two durations.

// A dynamics run of a scene: "" or an error message.
using SceneRun = std::string (*)(const Scene&);

std::string run_registry_backend(const std::string& name, const Scene& s) {
  const DynamicsResult r = find_backend(name)->dynamics(s, {});
  return r.status == Status::Ok ? std::string() : r.message;
}

// The runners timed, as a table: backend, variant, run.
struct StepRunner {
  const char* backend;
  const char* variant;
  SceneRun run;
};
const StepRunner kStepRunners[] = {
    {"custom", "default", [](const Scene& s) { return run_registry_backend("custom", s); }},
    {"custom", "faithful",
     [](const Scene& s) {
       // The `custom` backend's engine (extended contact model) on the faithful detector and
       // the all-pairs bounding check.
       World w(s.sim, make_bodies(s), ContactModel::Extended, Detector::Faithful,
               BroadPhaseMethod::AllPairs);
       const RunResult r = w.run();
       return r.ok ? std::string() : r.message;
     }},
    {"custom-seed", "default",
     [](const Scene& s) { return run_registry_backend("custom-seed", s); }},
    {"bullet", "default", [](const Scene& s) { return run_registry_backend("bullet", s); }},
};

CaseSet step_cases(const BenchPlan& plan, std::mt19937_64&) {
  struct State {
    StepRow row;
    std::string name;
    Scene scene;
    long steps = 0;
    SceneRun run;
    std::string status = "ok";
  };
  CaseSet set;
  std::vector<std::shared_ptr<State>> states;
  const std::string many_dir = std::string(RBX_DEFAULT_SOURCE_DIR) + "/scenes/many/";
  const std::pair<std::string, std::vector<long>> many[] = {{"many_100", plan.steps_100},
                                                            {"many_1000", plan.steps_1000}};
  for (const auto& [stem, steps] : many) {
    const std::string file = many_dir + stem + ".toml";
    if (!fs::exists(file)) {
      std::cerr << "bench: " << file << " not found; whole-step rows skipped\n";
      continue;
    }
    const Scene base = load_scene(file);
    int moving = 0;
    for (const BodySpec& b : base.bodies) moving += b.is_static ? 0 : 1;
    BenchGroup group;
    group.name = "step/" + stem;
    group.plan.min_time_s = plan.step_min_time;
    // Every engine gets all its rounds, however long a run takes: the goals' ratios are taken
    // round by round.
    group.plan.min_rounds = plan.step_rounds;
    group.plan.min_rounds_slow = plan.step_rounds;
    for (const StepRunner& runner : kStepRunners) {
      for (long k : steps) {
        auto c = std::make_shared<State>();
        c->scene = base;
        c->scene.sim.duration = static_cast<double>(k) * base.sim.dt;
        c->steps = c->scene.sim.steps();
        c->row.backend = runner.backend;
        c->row.variant = runner.variant;
        c->row.scene = stem;
        c->row.bodies = moving;
        c->row.total_bodies = static_cast<int>(base.bodies.size());
        c->row.status = "ok";
        c->name = "step/" + std::string(runner.backend) + "/" + runner.variant + "/" + stem + "/" +
                  std::to_string(k);
        c->run = runner.run;
        states.push_back(c);
        BenchCase bc;
        bc.name = c->name;
        bc.warm_up = [c] { c->run(c->scene); };
        bc.body = [c] {
          const std::string err = c->run(c->scene);
          if (!err.empty()) c->status = "error: " + err;
        };
        group.cases.push_back(bc);
      }
    }
    set.groups.push_back(std::move(group));
  }
  set.collect = [states](const CaseTimes& times, BenchResults& out) {
    for (std::size_t i = 0; i + 1 < states.size(); i += 2) {
      // Consecutive cases: the short and the long run of one backend and scene, timed in the
      // same turns, so each round gives its own difference.
      const State& a = *states[i];
      const State& b = *states[i + 1];
      StepRow r = a.row;
      r.status = a.status != "ok" ? a.status : b.status;
      const auto ra = times.rounds.find(a.name), rb = times.rounds.find(b.name);
      if (ra != times.rounds.end() && rb != times.rounds.end() && b.steps > a.steps) {
        const double per = 1e6 / static_cast<double>((b.steps - a.steps) * r.bodies);
        std::vector<double> v;
        const std::vector<double>&ta = ra->second.per_call_s, &tb = rb->second.per_call_s;
        for (std::size_t k = 0; k < std::min(ta.size(), tb.size()); ++k)
          v.push_back((tb[k] - ta[k]) * per);
        r.us_per_body_step = bench_time(v);
        r.us_per_body_step.calls = ra->second.per_round * static_cast<long>(ta.size()) +
                                   rb->second.per_round * static_cast<long>(tb.size());
        if (times.cold_s.count(a.name)) r.us_per_body_step.cold = times.cold_s.at(a.name) * 1e6;
      }
      if (times.errors.count(a.name)) r.status = "error: " + times.errors.at(a.name);
      if (times.errors.count(b.name)) r.status = "error: " + times.errors.at(b.name);
      // The extra steps cost less than the noise of the set-up: no measurement.
      if (!(r.us_per_body_step.median > 0.0) && r.status == "ok") {
        r.us_per_body_step = {};
        r.status = "extra steps within the timing noise of the set-up";
      }
      out.step.push_back(r);
    }
  };
  return set;
}

// ---------------------------------------------------------------------------------------------
// Explore throughput: `rbx explore --bench` on one thread, as `rbx explore` samples: the contact
// samples of the default seed whose shapes have fewer than 100 points, each through exact (the
// truth), custom and fcl, in one supervised child (reference/isolate.h) per block of samples.
// (Calling the sampler directly outside such a block would fork a child for every library call,
// from a process grown large by the cases before it, and time the forks.)

CaseSet explore_cases(const BenchPlan& plan, std::mt19937_64&) {
  auto settings = std::make_shared<ExploreSettings>();
  settings->count = plan.explore_samples;
  settings->backends = "custom,fcl";
  auto par = std::make_shared<ParallelRun>(1);
  auto done = std::make_shared<long>(0);
  const std::string name = "explore/contact/exact+custom+fcl";
  CaseSet set;
  BenchCase bc;
  bc.name = name;
  bc.warm_up = [] {};
  // One call is the whole block of samples.
  bc.body = [settings, par, done] { *done = explore_throughput(*settings, *par).done; };
  BenchGroup group{name, {}, {bc}};
  group.plan.min_time_s = plan.explore_min_time;
  group.plan.min_rounds = 3;
  set.groups.push_back(group);
  set.collect = [name, done](const CaseTimes& times, BenchResults& out) {
    ExploreRow r;
    r.backends = "exact, custom, fcl";
    r.samples = static_cast<int>(*done);
    // Samples per minute per round: a rate, so its median is the rate of the median round.
    const auto it = times.rounds.find(name);
    if (it != times.rounds.end() && *done > 0) {
      std::vector<double> v;
      for (double t : it->second.per_call_s) v.push_back(60.0 * static_cast<double>(*done) / t);
      r.samples_per_minute = bench_time(v);
      r.samples_per_minute.calls = it->second.per_round * r.samples_per_minute.rounds;
    }
    out.explore.push_back(r);
  };
  return set;
}

// The bench table: every family of cases and its builder, in the order they run and are written.
struct Family {
  const char* name;
  CaseSet (*build)(const BenchPlan& plan, std::mt19937_64& rng);
};
const Family kFamilies[] = {
    {"narrowphase", narrowphase_cases}, {"distance", distance_cases}, {"toi", toi_cases},
    {"broadphase", broadphase_cases},   {"step", step_cases},         {"explore", explore_cases},
};

}  // namespace

BenchTime bench_time(std::vector<double> per_round) {
  BenchTime t;
  t.per_round = per_round;
  std::sort(per_round.begin(), per_round.end());
  if (per_round.empty()) return t;
  t.median = sorted_quantile(per_round, 0.5);
  t.q25 = sorted_quantile(per_round, 0.25);
  t.q75 = sorted_quantile(per_round, 0.75);
  t.rounds = static_cast<int>(per_round.size());
  return t;
}

RatioSpread bench_ratio(const BenchTime& a, const BenchTime& b) {
  return paired_ratio(a.per_round, b.per_round);
}

namespace {

// The machine's clock as the kernel reports it (MHz of the first CPU listed), 0 if unknown.
double cpu_mhz() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("cpu MHz", 0) == 0) return std::atof(line.substr(line.find(':') + 1).c_str());
  return 0.0;
}

}  // namespace

BenchResults run_bench(const BenchPlan& plan) {
  std::mt19937_64 rng(20240606);
  std::vector<CaseSet> sets;
  for (const Family& f : kFamilies) sets.push_back(f.build(plan, rng));
  std::size_t total = 0, groups = 0;
  for (const CaseSet& set : sets)
    for (const BenchGroup& g : set.groups) {
      ++groups;
      total += g.cases.size();
    }
  std::cerr << "bench: " << total << " cases in " << groups << " groups timed together ("
            << (plan.quick ? "quick" : "full") << ")\n";

  // Per group: every case's warm-up, timed alone (its cold pass), then the rounds in turns.
  CaseTimes times;
  std::size_t done = 0;
  for (const CaseSet& set : sets)
    for (const BenchGroup& g : set.groups) {
      std::vector<TimedSubject> subjects;
      std::vector<const BenchCase*> timed;
      for (const BenchCase& bc : g.cases) {
        try {
          Stopwatch clock;
          bc.warm_up();
          times.cold_s[bc.name] = clock.seconds();
        } catch (const std::exception& e) {
          times.errors[bc.name] = e.what();
          continue;
        }
        subjects.push_back({bc.name, false, bc.body, 0.0, bc.set_up});
        timed.push_back(&bc);
      }
      TimingPlan plan = g.plan;
      plan.warmed_up = true;  // each case's warm-up ran just above
      const std::vector<Rounds> rounds = time_rounds(subjects, plan);
      for (std::size_t i = 0; i < timed.size(); ++i) {
        if (rounds[i].per_call_s.empty())
          times.errors[timed[i]->name] = "failed while being timed";
        else
          times.rounds[timed[i]->name] = rounds[i];
      }
      ++done;
      std::cerr << "bench [" << done << "/" << groups << "] " << g.name << ": " << timed.size()
                << " cases, " << (rounds.empty() ? 0 : timing_of(rounds.front()).rounds)
                << " rounds\n";
    }

  BenchResults out;
  out.cpus = static_cast<int>(std::thread::hardware_concurrency());
  out.mhz = cpu_mhz();
  out.cases = total;
  for (const CaseSet& set : sets) set.collect(times, out);
  fill_exponents(out);
  return out;
}

}  // namespace rbx
