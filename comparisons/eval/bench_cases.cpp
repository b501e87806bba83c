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

// Every row timed is named in its registry entry (Backend::bench, QueryVariant::bench), in
// registry order, each backend's variants after it. The caps there keep the full run under ten
// minutes on two cores; each is named, with its reason, in perf.md: the seed loops' 16 N^2
// primitive tests, bullet-sat's polyhedral features rebuilt on every call, the exact oracle's,
// ODE's, MuJoCo's and DART's (triangle meshes) cost at the largest sizes, Bullet's and ODE's
// shapes built from 8,192 points on every call (about 2 s a query, 10 s a call of five poses).
std::vector<NarrowBackend> narrow_backends() {
  std::vector<NarrowBackend> rows;
  for (const Backend& b : backends()) {
    if (b.contact && b.bench.full > 0)
      rows.push_back({b.name, "default", b.contact, b.bench.full, b.bench.quick});
    for (const QueryVariant& v : query_variants())
      if (v.backend == b.name && v.bench.full > 0)
        rows.push_back({b.name, v.variant, v.contact, v.bench.full, v.bench.quick, v.boxes_only});
  }
  return rows;
}

std::vector<DistanceBackend> distance_backends() {
  // The libraries' plain rows build their shapes (MuJoCo its whole model) on every call, a
  // second or so a query at N = 8,192: they stop at 2,048, where custom and FCL's prebuilt row
  // go on (docs/bench.md).
  constexpr int kPerCallBuildCap = 2048;
  std::vector<DistanceBackend> rows;
  for (const Backend& b : backends()) {
    if (b.distance && b.bench.full > 0 && b.name != "exact")
      rows.push_back({b.name, "default", b.distance,
                      b.library ? std::min(b.bench.full, kPerCallBuildCap) : b.bench.full,
                      b.bench.quick});
    for (const QueryVariant& v : query_variants())
      if (v.backend == b.name && v.distance && v.bench.full > 0)
        rows.push_back({b.name, v.variant, v.distance, v.bench.full, v.bench.quick});
  }
  return rows;
}

namespace {

// ---------------------------------------------------------------------------------------------
// What the groups' timings gave, per case name.

struct CaseTimes {
  std::map<std::string, Rounds> rounds;  // per call, seconds
  std::map<std::string, double> cold_s;  // the warm-up pass, timed alone
  std::map<std::string, std::string> errors;
  // A case's time in a row's unit (`scale` per second of a call), or an error.
  BenchTime time(const std::string& name, double scale) const {
    const auto it = rounds.find(name);
    if (it == rounds.end() || it->second.per_call_s.empty()) return {};
    std::vector<double> v;
    for (double t : it->second.per_call_s) v.push_back(t * scale);
    BenchTime out = bench_time(v);
    out.calls = it->second.per_round * out.rounds;
    if (cold_s.count(name)) out.cold = cold_s.at(name) * scale;
    return out;
  }
};

// A family's groups, and how it turns their timings into its rows once they have run.
struct CaseSet {
  std::vector<BenchGroup> groups;
  std::function<void(const CaseTimes&, BenchResults&)> collect;
};

// ---------------------------------------------------------------------------------------------
// Narrow phase: every backend of narrow_backends() on every shape size and pose kind.

// One query of a timed row on a pair at its pose: "" when the answer is ok, else its status and
// message.
using PairQuery = std::function<std::string(const RigidBody& a, const RigidBody& b)>;

// A row of a query family: what is timed and up to which size.
struct QueryRow {
  std::string backend, variant;
  PairQuery query;
  int max_full = 0, max_quick = 0;
  bool boxes_only = false;
};

// A query family's groups: every row on every shape size and pose kind of `kinds` (one group
// each, named "<family>/<size>/<kind>"), the rows going to `into` (ns per query).
CaseSet query_cases(const BenchPlan& plan, const std::string& family,
                    const std::vector<QueryRow>& rows, const std::vector<PoseKind>& kinds,
                    std::vector<NarrowRow> BenchResults::*into) {
  struct State {
    NarrowRow row;
    std::shared_ptr<PosedPair> pair;
    PairQuery query;
    std::string name;
    std::string status = "ok";
    std::size_t next = 0;  // the pose the next query takes (modulo the cycle)
  };
  CaseSet set;
  std::vector<std::shared_ptr<State>> states;
  std::vector<int> sizes = {8};
  sizes.insert(sizes.end(), plan.hull_sizes.begin(), plan.hull_sizes.end());
  std::cerr << "bench: building shapes and poses (" << family << ")\n";
  for (int n : sizes) {
    const bool box = n == 8;
    // One generator per shape and per pose kind, seeded by them: the quick run times the first
    // poses of the full run's, on the same hulls.
    std::mt19937_64 shape_rng(1000003ull * static_cast<unsigned>(n));
    const ConvexPolyhedron shape =
        box ? make_box(Vec3::Constant(kBenchShapeSize)) : sphere_hull(n, shape_rng);
    for (const PoseKind& kind : kinds) {
      // The seed of the narrow phase's pose kind at the same place in kPoseKinds; a gap kind,
      // past them, its own.
      std::mt19937_64 pose_rng(1000003ull * static_cast<unsigned>(n) +
                               static_cast<unsigned>(&kind - kinds.data()) + 1 +
                               (family == "narrowphase" ? 0u : 100u));
      auto pair = std::make_shared<PosedPair>(make_poses(shape, box, kind, plan.poses, pose_rng));
      BenchGroup group;
      group.name = family + "/" + std::to_string(n) + "/" + kind.name;
      group.plan.min_time_s = plan.min_time;
      for (const QueryRow& b : rows) {
        if (b.boxes_only && !box) continue;
        if (n > (plan.quick ? b.max_quick : b.max_full)) continue;
        auto c = std::make_shared<State>();
        c->row.backend = b.backend;
        c->row.variant = b.variant;
        c->row.pose = kind.name;
        c->row.vertices = n;
        c->row.hull_vertices = static_cast<int>(shape.vertices().size());
        c->name =
            family + "/" + b.backend + "/" + b.variant + "/" + std::to_string(n) + "/" + kind.name;
        c->pair = pair;
        c->query = b.query;
        states.push_back(c);
        // One query at pose k of the pair.
        auto query = [c](std::size_t k) {
          k %= c->pair->poses_a.size();
          PosedPair& p = *c->pair;
          p.a.position = p.poses_a[k].position;
          p.a.orientation = p.poses_a[k].orientation;
          p.b.position = p.poses_b[k].position;
          p.b.orientation = p.poses_b[k].orientation;
          return c->query(p.a, p.b);
        };
        BenchCase bc;
        bc.name = c->name;
        // Warm-up: one call's poses (caches, lazily built hierarchies), the cold pass.
        const std::size_t per_iteration = static_cast<std::size_t>(plan.poses_per_iteration);
        bc.warm_up = [c, query, per_iteration] {
          for (std::size_t k = 0; k < per_iteration; ++k) query(k);
        };
        // Each call the next poses of the cycle: a sequence as long as the cycle is not one
        // a branch predictor learns, as it learns a few poses repeated (docs/bench.md). Every
        // status that is not ok is kept.
        bc.body = [c, query, per_iteration] {
          for (std::size_t k = 0; k < per_iteration; ++k) {
            const std::string status = query(c->next++);
            if (!status.empty()) c->status = status;
          }
        };
        group.cases.push_back(bc);
      }
      set.groups.push_back(std::move(group));
    }
  }
  set.collect = [states, poses = plan.poses_per_iteration, into](const CaseTimes& times,
                                                                 BenchResults& out) {
    for (const auto& c : states) {
      NarrowRow r = c->row;
      r.status = c->status;
      // A call queries `poses` poses: the row's unit is ns per query.
      r.ns_per_query = times.time(c->name, 1e9 / static_cast<double>(poses));
      if (times.errors.count(c->name)) r.status = "error: " + times.errors.at(c->name);
      (out.*into).push_back(r);
    }
  };
  return set;
}

// Narrow phase: every backend of narrow_backends() on every shape size and pose kind.
CaseSet narrowphase_cases(const BenchPlan& plan, std::mt19937_64&) {
  std::vector<QueryRow> rows;
  for (const NarrowBackend& b : narrow_backends()) {
    const ContactFn contact = b.contact;
    rows.push_back({b.backend, b.variant,
                    [contact](const RigidBody& a, const RigidBody& bb) {
                      const ContactResult r = contact(a, bb);
                      return r.status == Status::Ok
                                 ? std::string()
                                 : std::string(to_string(r.status)) + ": " + r.message;
                    },
                    b.max_vertices_full, b.max_vertices_quick, b.boxes_only});
  }
  return query_cases(plan, "narrowphase", rows,
                     std::vector<PoseKind>(std::begin(kPoseKinds), std::end(kPoseKinds)),
                     &BenchResults::narrow);
}

// Distance: every query of distance_backends() on every shape size, 1 % and 20 % apart.
CaseSet distance_cases(const BenchPlan& plan, std::mt19937_64&) {
  std::vector<QueryRow> rows;
  for (const DistanceBackend& b : distance_backends()) {
    const DistanceFn distance = b.distance;
    rows.push_back({b.backend, b.variant,
                    [distance](const RigidBody& a, const RigidBody& bb) {
                      const DistanceResult r = distance(a, bb);
                      if (r.status != Status::Ok)
                        return std::string(to_string(r.status)) + ": " + r.message;
                      return r.overlapping ? std::string("said overlapping") : std::string();
                    },
                    b.max_vertices_full, b.max_vertices_quick});
  }
  return query_cases(plan, "distance", rows,
                     std::vector<PoseKind>(std::begin(kGapKinds), std::end(kGapKinds)),
                     &BenchResults::distance);
}

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
       World w(s.sim, make_bodies(s), ContactModel::Extended, DetectorVariant::Faithful,
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
    {"narrowphase", narrowphase_cases}, {"distance", distance_cases},
    {"broadphase", broadphase_cases},   {"step", step_cases},
    {"explore", explore_cases},
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
  return out;
}

}  // namespace rbx
