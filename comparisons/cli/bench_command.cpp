// `rbx bench`: the performance comparison of issue 6, on Google Benchmark.
//
// Three families of cases, each registered with benchmark::RegisterBenchmark and collected by a
// reporter that keeps the time per iteration (no console table):
//   - narrowphase: every contact backend through the registry's ContactFn, on the same convex
//     pairs (a unit box, and hulls of N random points on a sphere of diameter 1) at the same
//     poses (touching, deep, separated). One iteration is one query at each of the pose kind's
//     poses; ns_per_query is the time per iteration over the number of poses.
//   - broadphase: the engine's broad-phase methods finding the pairs of a crowd of cubes (a
//     fixed density, so the pairs per body stay constant), after a small motion of every body
//     per step (the motion is not timed).
//   - step: whole dynamics runs of scenes/many/ with the custom engine and Bullet. Each is run
//     for two durations; the difference in time over the difference in steps removes the set-up
//     (building worlds and shapes), leaving microseconds per body per step.
// Every case runs one untimed pass first (warm-up: caches, lazily built hierarchies, page
// faults), then Google Benchmark times iterations until the case's minimum time.
//
// Output, into --out (default reports/latest, beside `rbx report`'s files, which that command
// carries over when it replaces the folder), each file written atomically next to whatever the
// folder holds already: perf.md, perf.json, perf.csv and figures/perf_*.{png,svg}
// (comparisons/output/bench_plots.py, matplotlib). Without --out, reports/perf.md (the path
// CONTRACT.md names) gets a copy of perf.md whose figure links point into latest/.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "comparisons/cli/commands.h"
#include "comparisons/eval/json_io.h"
#include "comparisons/scene/mesh_io.h"
#include "comparisons/scene/repo_path.h"
#include "comparisons/scene/scene_file.h"
#include "engine/body.h"
#include "engine/broadphase.h"
#include "engine/world.h"
#include "reference/backend.h"
#include "reference/bullet.h"
#include "reference/custom.h"
#include "reference/fcl.h"

namespace rbx {

namespace fs = std::filesystem;

namespace {

// ---------------------------------------------------------------------------------------------
// Plan: sizes, caps and times for the full and the quick run.

// The pose kinds and their offsets from the touching distance along the placement direction,
// as fractions of the shape size (1 m here): touching = 0.5% of the size deep (within 1%), deep
// = 20% deep, separated = a 5% gap.
struct PoseKind {
  const char* name;
  double offset;  // fraction of the size; negative: penetrating
};
constexpr PoseKind kPoseKinds[] = {{"touching", -0.005}, {"deep", -0.2}, {"separated", 0.05}};

// One contact backend as benchmarked.
struct NarrowBackend {
  std::string backend;  // registry name
  std::string variant;  // "fast" | "seed" for custom; "default" otherwise
  ContactFn contact;
  int max_vertices_full;   // largest hull size timed in the full run
  int max_vertices_quick;  // in the quick run
  bool boxes_only = false;
};

// What a run measures.
struct Plan {
  bool quick = false;
  std::vector<int> hull_sizes;              // vertices of the hulls (the box is always included)
  int poses = 3;                            // poses per kind
  double min_time = 0.2;                    // s, minimum timed time per case
  std::vector<int> crowd_sizes;             // bodies in the broad-phase crowds
  double crowd_min_time = 0.2;              // s
  std::vector<long> steps_100, steps_1000;  // step counts of the two runs per scene
  double step_min_time = 0.1;               // s
};

Plan make_plan(bool quick) {
  Plan p;
  p.quick = quick;
  if (quick) {
    p.hull_sizes = {32, 128, 512, 2048};
    p.poses = 3;
    p.min_time = 0.02;
    p.crowd_sizes = {1000, 2000, 5000};
    p.crowd_min_time = 0.05;
    p.steps_100 = {10, 60};
    p.steps_1000 = {2, 8};
    p.step_min_time = 0.05;
  } else {
    p.hull_sizes = {32, 128, 512, 2048, 8192};
    p.poses = 5;
    p.min_time = 0.2;
    p.crowd_sizes = {1000, 2000, 5000, 10000, 20000};
    p.crowd_min_time = 0.3;
    p.steps_100 = {20, 120};
    p.steps_1000 = {10, 60};
    p.step_min_time = 0.2;
  }
  return p;
}

// Every contact backend with the sizes it is timed at. The caps keep the full run under ten
// minutes on two cores; each is named in perf.md. Measured on the development machine (one
// touching query): the seed loops ~0.3 s at N = 2048 separated (16 N^2 primitive tests),
// bullet-sat ~7.5 s at N = 2048 (its polyhedral features are rebuilt per call), exact ~0.1 s
// at N = 2048, ode ~1 s and mujoco ~0.5 s at N = 8192.
std::vector<NarrowBackend> narrow_backends() {
  auto registry = [](const std::string& name) { return find_backend(name)->contact; };
  return {
      {"custom", "fast", registry("custom"), 8192, 2048},
      {"custom", "seed", custom_seed_contact, 2048, 512},
      {"exact", "default", registry("exact"), 2048, 512},
      {"fcl", "default", registry("fcl"), 8192, 2048},
      {"fcl", "prebuilt", fcl_contact_prebuilt, 8192, 2048},
      {"fcl-epa", "default", registry("fcl-epa"), 8192, 2048},
      {"libccd", "default", registry("libccd"), 8192, 2048},
      {"bullet", "default", registry("bullet"), 8192, 2048},
      {"bullet-sat", "default", registry("bullet-sat"), 512, 128},
      {"mujoco", "default", registry("mujoco"), 8192, 512},
      {"ode", "default", registry("ode"), 8192, 512},
      {"fcl-box", "default", registry("fcl"), 8, 8, true},
  };
}

// ---------------------------------------------------------------------------------------------
// Shapes and poses.

// Repetitions of the cheap cases and of those behind the goals (the fastest is kept).
constexpr int kRepetitions = 3;

// Size (m) of every benchmark shape: the unit box and hulls of points on a sphere of radius 0.5.
constexpr double kSize = 1.0;

// The hull of n random points on the sphere of radius 0.5 (all of them are hull vertices).
ConvexPolyhedron sphere_hull(int n, std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Vec3> points;
  while (static_cast<int>(points.size()) < n) {
    const Vec3 v(g(rng), g(rng), g(rng));
    if (v.norm() > 1e-9) points.push_back(0.5 * kSize * v.normalized());
  }
  return convex_hull(points);
}

RigidBody body_of(const std::string& name, const ConvexPolyhedron& shape, bool box) {
  BodySpec spec;
  spec.name = name;
  spec.shape_kind = box ? ShapeKind::Box : ShapeKind::Convex;
  spec.box_size = Vec3::Constant(kSize);
  spec.shape = std::make_shared<const ConvexPolyhedron>(shape);
  return make_body(spec);
}

Quat random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  return Quat(g(rng), g(rng), g(rng), g(rng)).normalized();
}

// One pair of bodies at several poses of one kind.
struct PosedPair {
  RigidBody a, b;
  std::vector<Pose> poses_a, poses_b;
};

// Poses of one kind for a pair of copies of `shape`: random orientations and a random direction
// d; the touching distance t* along d is found by bisection with libccd (MPR, tolerance
// 1e-10 m), and B is placed at t* + offset * size along d from A.
PosedPair make_poses(const ConvexPolyhedron& shape, bool box, const PoseKind& kind, int count,
                     std::mt19937_64& rng) {
  PosedPair p{body_of("A", shape, box), body_of("B", shape, box), {}, {}};
  const ContactFn ccd = find_backend("libccd")->contact;
  for (int k = 0; k < count; ++k) {
    p.a.position = Vec3::Zero();
    p.a.orientation = random_rotation(rng);
    p.b.orientation = random_rotation(rng);
    const Vec3 d = random_rotation(rng) * Vec3::UnitX();
    double lo = 0.0, hi = 2.0 * kSize * std::sqrt(3.0);  // overlapping at lo, apart at hi
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      p.b.position = mid * d;
      (ccd(p.a, p.b).contacts.empty() ? hi : lo) = mid;
    }
    p.b.position = (lo + kind.offset * kSize) * d;
    p.poses_a.push_back(p.a.pose());
    p.poses_b.push_back(p.b.pose());
  }
  return p;
}

// ---------------------------------------------------------------------------------------------
// Collecting Google Benchmark's results.

class Collector : public benchmark::BenchmarkReporter {
 public:
  explicit Collector(std::size_t total) : total_(total) {}
  bool ReportContext(const Context& context) override {
    cpus = context.cpu_info.num_cpus;
    mhz = context.cpu_info.cycles_per_second / 1e6;
    return true;
  }
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      if (r.run_type != Run::RT_Iteration) continue;
      const std::string name = r.run_name.function_name;
      ++done_;
      if (r.error_occurred) {
        errors[name] = r.error_message;
      } else {
        // Repeated cases keep their fastest repetition: the one least disturbed by other load
        // on a shared machine.
        const double t = r.real_accumulated_time / static_cast<double>(r.iterations);
        if (!seconds.count(name) || t < seconds[name]) {
          seconds[name] = t;
          iterations[name] = static_cast<long>(r.iterations);
        }
      }
      std::cerr << "bench [" << done_ << "/" << total_ << "] " << name << ": "
                << (r.error_occurred ? "error: " + r.error_message
                                     : std::to_string(seconds[name] * 1e6) + " us/iteration")
                << "\n";
    }
  }
  int cpus = 0;
  double mhz = 0.0;
  std::map<std::string, double> seconds;  // per iteration
  std::map<std::string, long> iterations;
  std::map<std::string, std::string> errors;

 private:
  std::size_t total_;
  std::size_t done_ = 0;
};

// ---------------------------------------------------------------------------------------------
// Results.

struct NarrowRow {
  std::string backend, variant, pose, status;
  int vertices = 0;       // nominal: 8 for the box, else the hull's point count
  int hull_vertices = 0;  // as built
  double ns_per_query = NAN;
  long iterations = 0;
};

struct BroadRow {
  std::string method;
  int bodies = 0;
  double ns_per_step = NAN;
  double pairs_per_step = 0.0;
};

struct StepRow {
  std::string backend, variant, scene;
  int bodies = 0;        // moving bodies
  int total_bodies = 0;  // including static walls
  double us_per_body_step = NAN;
  std::string status;
};

// Least-squares slope of log(time) against log(size): the exponent of time against size.
double fit_exponent(const std::vector<std::pair<double, double>>& points) {
  if (points.size() < 2) return NAN;
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const auto& [n, t] : points) {
    const double x = std::log(n), y = std::log(t);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  const double m = static_cast<double>(points.size());
  return (m * sxy - sx * sy) / (m * sxx - sx * sx);
}

// A duration in the unit that reads best in a table (ns, µs, ms, s).
std::string fmt_time(double ns) {
  if (!std::isfinite(ns)) return "—";
  std::ostringstream s;
  s << std::setprecision(3);
  if (ns < 1e3)
    s << ns << " ns";
  else if (ns < 1e6)
    s << ns / 1e3 << " µs";
  else if (ns < 1e9)
    s << ns / 1e6 << " ms";
  else
    s << ns / 1e9 << " s";
  return s.str();
}

std::string fmt(double x, int digits = 3) {
  if (!std::isfinite(x)) return "—";
  std::ostringstream s;
  s << std::setprecision(digits) << x;
  return s.str();
}

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown CPU";
}

// The exponent fit of one series (hull sizes only, the box excluded).
double series_exponent(const std::vector<NarrowRow>& rows, const std::string& backend,
                       const std::string& variant, const std::string& pose) {
  std::vector<std::pair<double, double>> pts;
  for (const NarrowRow& r : rows)
    if (r.backend == backend && r.variant == variant && r.pose == pose && r.vertices > 8 &&
        std::isfinite(r.ns_per_query))
      pts.push_back({static_cast<double>(r.vertices), r.ns_per_query});
  return fit_exponent(pts);
}

double find_time(const std::vector<NarrowRow>& rows, const std::string& backend,
                 const std::string& variant, const std::string& pose, int vertices) {
  for (const NarrowRow& r : rows)
    if (r.backend == backend && r.variant == variant && r.pose == pose && r.vertices == vertices)
      return r.ns_per_query;
  return NAN;
}

}  // namespace

int bench_command(const BenchOptions& opt) {
  const Plan plan = make_plan(opt.quick);
  const std::string out = opt.out.empty() ? default_repo_path("reports/latest") : opt.out;
  Stopwatch clock;
  std::mt19937_64 rng(20240606);

  // ---- Narrow phase: shapes, poses and cases -------------------------------------------------
  struct NarrowCase {
    std::string name;
    NarrowRow row;
    std::shared_ptr<PosedPair> pair;
    ContactFn contact;
    std::string status = "ok";
    int repetitions = 1;
  };
  std::vector<std::shared_ptr<NarrowCase>> narrow;
  std::vector<int> sizes = {8};
  sizes.insert(sizes.end(), plan.hull_sizes.begin(), plan.hull_sizes.end());
  const std::vector<NarrowBackend> nb = narrow_backends();
  std::cerr << "bench: building shapes and poses\n";
  for (int n : sizes) {
    const bool box = n == 8;
    // One generator per shape and per pose kind, seeded by them: the quick run times the first
    // poses of the full run's, on the same hulls.
    std::mt19937_64 shape_rng(1000003ull * static_cast<unsigned>(n));
    const ConvexPolyhedron shape =
        box ? make_box(Vec3::Constant(kSize)) : sphere_hull(n, shape_rng);
    for (const PoseKind& kind : kPoseKinds) {
      std::mt19937_64 pose_rng(1000003ull * static_cast<unsigned>(n) +
                               static_cast<unsigned>(&kind - kPoseKinds) + 1);
      auto pair = std::make_shared<PosedPair>(make_poses(shape, box, kind, plan.poses, pose_rng));
      for (const NarrowBackend& b : nb) {
        if (b.boxes_only && !box) continue;
        if (n > (plan.quick ? b.max_vertices_quick : b.max_vertices_full)) continue;
        auto c = std::make_shared<NarrowCase>();
        c->row = {b.backend, b.variant, kind.name, "", n, static_cast<int>(shape.vertices().size()),
                  NAN,       0};
        c->name = "narrowphase/" + b.backend + "/" + b.variant + "/" + std::to_string(n) + "/" +
                  kind.name;
        c->pair = pair;
        c->contact = b.contact;
        // The cases behind the goals, and every cheap one, are repeated (fastest kept).
        const bool goal = (b.backend == "custom" && b.variant == "fast") ||
                          b.backend == "fcl-box" || (b.backend == "fcl" && n == 2048);
        c->repetitions = goal || n <= 128 ? kRepetitions : 1;
        narrow.push_back(c);
      }
    }
  }
  for (const auto& c : narrow) {
    benchmark::RegisterBenchmark(c->name.c_str(),
                                 [c](benchmark::State& state) {
                                   PosedPair& p = *c->pair;
                                   const std::size_t count = p.poses_a.size();
                                   auto query = [&](std::size_t k) {
                                     p.a.position = p.poses_a[k].position;
                                     p.a.orientation = p.poses_a[k].orientation;
                                     p.b.position = p.poses_b[k].position;
                                     p.b.orientation = p.poses_b[k].orientation;
                                     return c->contact(p.a, p.b);
                                   };
                                   // Warm-up: one untimed pass (also records the status of every
                                   // pose).
                                   for (std::size_t k = 0; k < count; ++k) {
                                     const ContactResult r = query(k);
                                     if (r.status != Status::Ok)
                                       c->status =
                                           std::string(to_string(r.status)) + ": " + r.message;
                                   }
                                   for (auto _ : state)
                                     for (std::size_t k = 0; k < count; ++k)
                                       benchmark::DoNotOptimize(query(k));
                                 })
        ->MinTime(plan.min_time)
        ->Unit(benchmark::kMicrosecond)
        ->Repetitions(c->repetitions);
  }

  // ---- Broad phase ---------------------------------------------------------------------------
  struct BroadCase {
    std::string name;
    BroadRow row;
    std::shared_ptr<std::vector<RigidBody>> bodies;
    long pairs = 0, steps = 0;
  };
  std::vector<std::shared_ptr<BroadCase>> broad;
  const BroadPhaseMethod methods[] = {BroadPhaseMethod::AllPairs, BroadPhaseMethod::SweepAndPrune,
                                      BroadPhaseMethod::Tree};
  for (int n : plan.crowd_sizes) {
    // Cubes of 0.2 m at uniformly random points, one per 0.125 m^3 (the grid spacing of
    // scenes/many/many_100), so each cube has about the same number of neighbours at any n.
    auto bodies = std::make_shared<std::vector<RigidBody>>();
    const double side = 0.5 * std::cbrt(static_cast<double>(n));
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const auto cube = std::make_shared<const ConvexPolyhedron>(make_box(Vec3::Constant(0.2)));
    for (int i = 0; i < n; ++i) {
      BodySpec spec;
      spec.name = "c" + std::to_string(i);
      spec.box_size = Vec3::Constant(0.2);
      spec.shape = cube;
      spec.position = side * Vec3(unit(rng), unit(rng), unit(rng));
      spec.orientation = random_rotation(rng);
      bodies->push_back(make_body(spec));
    }
    for (BroadPhaseMethod m : methods) {
      auto c = std::make_shared<BroadCase>();
      c->row.method = to_string(m);
      c->row.bodies = n;
      c->name = "broadphase/" + c->row.method + "/" + std::to_string(n);
      c->bodies = bodies;
      broad.push_back(c);
      benchmark::RegisterBenchmark(
          c->name.c_str(),
          [c, m](benchmark::State& state) {
            BroadPhase bp(m);
            // A private copy per run, so that every method starts from the same crowd and moves it
            // by the same jitter.
            std::vector<RigidBody> bodies = *c->bodies;
            std::mt19937_64 jitter(7);
            std::normal_distribution<double> g(0.0, 1e-3);  // m per step: 1 m/s at dt = 1 ms
            bp.find_pairs(bodies);                          // warm-up
            for (auto _ : state) {
              state.PauseTiming();
              for (RigidBody& b : bodies) b.position += Vec3(g(jitter), g(jitter), g(jitter));
              state.ResumeTiming();
              const long found = static_cast<long>(bp.find_pairs(bodies).size());
              c->pairs += found;
              ++c->steps;
            }
          })
          ->MinTime(plan.crowd_min_time)
          ->Unit(benchmark::kMillisecond)
          ->Repetitions(kRepetitions);
    }
  }

  // ---- Whole step ----------------------------------------------------------------------------
  struct StepCase {
    std::string name;
    StepRow row;
    std::shared_ptr<Scene> scene;
    long steps = 0;
    std::function<std::string(const Scene&)> run;  // returns "" or an error message
    std::string status = "ok";
  };
  std::vector<std::shared_ptr<StepCase>> step_cases;
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
    struct Runner {
      std::string backend, variant;
      std::function<std::string(const Scene&)> run;
    };
    const std::vector<Runner> runners = {
        {"custom", "fast",
         [](const Scene& s) {
           const DynamicsResult r = find_backend("custom")->dynamics(s, {});
           return r.status == Status::Ok ? std::string() : r.message;
         }},
        {"custom", "seed",
         [](const Scene& s) {
           // The seed's detector and all-pairs bounding check.
           World w(s.sim, make_bodies(s), DetectorVariant::Faithful, BroadPhaseMethod::AllPairs);
           const RunResult r = w.run();
           return r.ok ? std::string() : r.message;
         }},
        {"bullet", "default",
         [](const Scene& s) {
           const DynamicsResult r = find_backend("bullet")->dynamics(s, {});
           return r.status == Status::Ok ? std::string() : r.message;
         }},
    };
    for (const Runner& runner : runners) {
      for (long k : steps) {
        auto c = std::make_shared<StepCase>();
        c->scene = std::make_shared<Scene>(base);
        c->scene->sim.duration = static_cast<double>(k) * base.sim.dt;
        c->steps = c->scene->sim.steps();
        c->row = {runner.backend,
                  runner.variant,
                  stem,
                  moving,
                  static_cast<int>(base.bodies.size()),
                  NAN,
                  "ok"};
        c->name =
            "step/" + runner.backend + "/" + runner.variant + "/" + stem + "/" + std::to_string(k);
        c->run = runner.run;
        step_cases.push_back(c);
        benchmark::RegisterBenchmark(c->name.c_str(),
                                     [c](benchmark::State& state) {
                                       std::string err = c->run(*c->scene);  // warm-up
                                       for (auto _ : state) err = c->run(*c->scene);
                                       if (!err.empty()) c->status = "error: " + err;
                                     })
            ->MinTime(plan.step_min_time)
            ->Unit(benchmark::kMillisecond);
      }
    }
  }

  // ---- Run everything ------------------------------------------------------------------------
  const std::size_t total = narrow.size() + broad.size() + step_cases.size();
  std::size_t runs = broad.size() * kRepetitions + step_cases.size();
  for (const auto& c : narrow) runs += static_cast<std::size_t>(c->repetitions);
  std::cerr << "bench: " << total << " cases, " << runs << " runs ("
            << (plan.quick ? "quick" : "full") << ")\n";
  Collector collector(runs);
  benchmark::RunSpecifiedBenchmarks(&collector);
  benchmark::ClearRegisteredBenchmarks();

  std::vector<NarrowRow> nrows;
  for (const auto& c : narrow) {
    NarrowRow r = c->row;
    r.status = c->status;
    if (collector.seconds.count(c->name)) {
      r.ns_per_query = collector.seconds[c->name] * 1e9 / static_cast<double>(plan.poses);
      r.iterations = collector.iterations[c->name];
    } else if (collector.errors.count(c->name)) {
      r.status = "error: " + collector.errors[c->name];
    }
    nrows.push_back(r);
  }
  std::vector<BroadRow> brows;
  for (const auto& c : broad) {
    BroadRow r = c->row;
    if (collector.seconds.count(c->name)) r.ns_per_step = collector.seconds[c->name] * 1e9;
    if (c->steps > 0) r.pairs_per_step = static_cast<double>(c->pairs) / c->steps;
    brows.push_back(r);
  }
  std::vector<StepRow> srows;
  for (std::size_t i = 0; i + 1 < step_cases.size(); i += 2) {
    // Consecutive cases: the short and the long run of one backend and scene.
    const StepCase& a = *step_cases[i];
    const StepCase& b = *step_cases[i + 1];
    StepRow r = a.row;
    r.status = a.status != "ok" ? a.status : b.status;
    if (collector.seconds.count(a.name) && collector.seconds.count(b.name) && b.steps > a.steps)
      r.us_per_body_step = (collector.seconds[b.name] - collector.seconds[a.name]) * 1e6 /
                           static_cast<double>((b.steps - a.steps) * r.bodies);
    // The extra steps cost less than the noise of the set-up: no measurement.
    if (!(r.us_per_body_step > 0.0) && r.status == "ok") {
      r.us_per_body_step = NAN;
      r.status = "extra steps within the timing noise of the set-up";
    }
    srows.push_back(r);
  }

  // ---- Goals ---------------------------------------------------------------------------------
  struct Goal {
    std::string goal, measured;
    bool met = false;
  };
  std::vector<Goal> goals;
  const double fast_exp = series_exponent(nrows, "custom", "fast", "touching");
  goals.push_back({"custom (fast), touching: time grows no faster than N^1.2",
                   "exponent " + fmt(fast_exp) +
                       " (N = " + std::to_string(plan.hull_sizes.front()) + " to " +
                       std::to_string(plan.hull_sizes.back()) + ")",
                   std::isfinite(fast_exp) && fast_exp <= 1.2});
  const double fast_2048 = find_time(nrows, "custom", "fast", "touching", 2048);
  // Against FCL with its shapes built once (custom keeps its hierarchies per shape too): the
  // per-call `fcl` row also pays for building fcl::Convex, which would flatter custom.
  const double fcl_2048 = find_time(nrows, "fcl", "prebuilt", "touching", 2048);
  goals.push_back(
      {"custom (fast) no slower than fcl (shapes prebuilt) at N = 2048, touching",
       fmt_time(fast_2048) + " vs " + fmt_time(fcl_2048) + ": ratio " + fmt(fast_2048 / fcl_2048),
       fast_2048 <= fcl_2048});
  const double fast_box = find_time(nrows, "custom", "fast", "touching", 8);
  const double fclbox = find_time(nrows, "fcl-box", "default", "touching", 8);
  goals.push_back(
      {"custom (fast) within 1.5x of fcl-box on two boxes, touching",
       fmt_time(fast_box) + " vs " + fmt_time(fclbox) + ": ratio " + fmt(fast_box / fclbox),
       fast_box <= 1.5 * fclbox});
  for (BroadPhaseMethod m : methods) {
    std::vector<std::pair<double, double>> pts;
    for (const BroadRow& r : brows)
      if (r.method == to_string(m) && std::isfinite(r.ns_per_step))
        pts.push_back({static_cast<double>(r.bodies), r.ns_per_step});
    if (m == BroadPhaseMethod::Tree) {
      const double e = fit_exponent(pts);
      goals.push_back(
          {"broad phase (tree, the world's default): pair finding grows no faster than "
           "N^1.2",
           "exponent " + fmt(e) + " (" + std::to_string(plan.crowd_sizes.front()) + " to " +
               std::to_string(plan.crowd_sizes.back()) + " bodies)",
           std::isfinite(e) && e <= 1.2});
    }
  }

  // ---- Write ---------------------------------------------------------------------------------
  Json j;
  j["generated_by"] = "rbx bench";
  j["mode"] = plan.quick ? "quick" : "full";
  j["machine"] = {{"cpu", cpu_model()},
                  {"cpus", collector.cpus},
                  {"mhz", collector.mhz},
                  {"hostname", [] {
                     char h[256] = {0};
                     gethostname(h, sizeof h - 1);
                     return std::string(h);
                   }()}};
  j["settings"] = {{"poses_per_kind", plan.poses},
                   {"min_time_s", plan.min_time},
                   {"shape_size_m", kSize},
                   {"touching_offset", kPoseKinds[0].offset},
                   {"deep_offset", kPoseKinds[1].offset},
                   {"separated_offset", kPoseKinds[2].offset}};
  j["rows"] = Json::array();
  for (const NarrowRow& r : nrows)
    j["rows"].push_back(
        {{"kind", "narrowphase"},
         {"backend", r.backend},
         {"variant", r.variant},
         {"vertices", r.vertices},
         {"hull_vertices", r.hull_vertices},
         {"pose", r.pose},
         {"ns_per_query", std::isfinite(r.ns_per_query) ? Json(r.ns_per_query) : Json(nullptr)},
         {"iterations", r.iterations},
         {"status", r.status}});
  for (const BroadRow& r : brows)
    j["rows"].push_back(
        {{"kind", "broadphase"},
         {"method", r.method},
         {"bodies", r.bodies},
         {"ns_per_step", std::isfinite(r.ns_per_step) ? Json(r.ns_per_step) : Json(nullptr)},
         {"pairs_per_step", r.pairs_per_step}});
  for (const StepRow& r : srows)
    j["rows"].push_back(
        {{"kind", "step"},
         {"backend", r.backend},
         {"variant", r.variant},
         {"scene", r.scene},
         {"bodies", r.bodies},
         {"total_bodies", r.total_bodies},
         {"us_per_body_step",
          std::isfinite(r.us_per_body_step) ? Json(r.us_per_body_step) : Json(nullptr)},
         {"status", r.status}});
  j["goals"] = Json::array();
  for (const Goal& g : goals)
    j["goals"].push_back({{"goal", g.goal}, {"measured", g.measured}, {"met", g.met}});
  j["exponents"] = Json::object();
  for (const NarrowBackend& b : nb)
    for (const PoseKind& k : kPoseKinds) {
      const double e = series_exponent(nrows, b.backend, b.variant, k.name);
      if (std::isfinite(e)) j["exponents"][b.backend + "/" + b.variant + "/" + k.name] = e;
    }

  std::ostringstream csv;
  csv << "kind,backend,variant,method,scene,vertices,pose,bodies,value,unit\n";
  for (const NarrowRow& r : nrows)
    csv << "narrowphase," << r.backend << "," << r.variant << ",,," << r.vertices << "," << r.pose
        << ",," << fmt(r.ns_per_query, 6) << ",ns_per_query\n";
  for (const BroadRow& r : brows)
    csv << "broadphase,,," << r.method << ",,,," << r.bodies << "," << fmt(r.ns_per_step, 6)
        << ",ns_per_step\n";
  for (const StepRow& r : srows)
    csv << "step," << r.backend << "," << r.variant << ",," << r.scene << ",,," << r.bodies << ","
        << fmt(r.us_per_body_step, 6) << ",us_per_body_step\n";

  // perf.md
  std::ostringstream md;
  md << "# Performance: `rbx bench" << (plan.quick ? " --quick" : "") << "`\n\n";
  md << "Machine: " << cpu_model() << ", " << collector.cpus << " CPUs (shared); Release build; "
     << (plan.quick ? "quick run (fewer sizes and poses, short times). " : "full run. ")
     << "Google Benchmark: every case runs one untimed warm-up pass, then is timed for at least "
     << plan.min_time << " s (narrow phase), " << plan.crowd_min_time << " s (broad phase), "
     << plan.step_min_time
     << " s (whole step); the broad phase, the narrow-phase cases of up to "
        "128 vertices and those behind the goals run "
     << kRepetitions
     << " times and keep the fastest (the machine is shared). Wall time of the timing: "
     << fmt(clock.seconds(), 3) << " s.\n\n";
  md << "## Goals (issue 6)\n\n| goal | measured | met |\n|---|---|---|\n";
  for (const Goal& g : goals)
    md << "| " << g.goal << " | " << g.measured << " | " << (g.met ? "yes" : "**no**") << " |\n";
  md << "\n## Narrow phase\n\n"
     << "Every contact backend through the registry's `ContactFn` on the same pairs: two unit "
        "boxes (N = 8), and two hulls of N random points on a sphere of diameter 1 m (every "
        "point is a hull vertex). Poses: random orientations and a random direction; the "
        "touching distance along it is found by bisection with libccd, then B is placed "
     << -kPoseKinds[0].offset * 100 << "% of the size deep (*touching*), "
     << -kPoseKinds[1].offset * 100 << "% deep (*deep*) or with a " << kPoseKinds[2].offset * 100
     << "% gap (*separated*); " << plan.poses
     << " poses per kind, the time is the mean per query. Times include what each adapter "
        "does per call (the references build their library's shape from the hull on every "
        "query, as the adapters are written; `custom` caches its hierarchies per shape; "
        "`fcl (prebuilt)` is the same FCL query with each fcl::Convex built once, the fair "
        "comparison for custom, and the difference between the two fcl rows is FCL's set-up). The "
        "exponent is the least-squares slope of log(time) against log(N) over the hull sizes "
        "(the box excluded).\n\n";
  md << "Caps (sizes not timed, to keep the run short): ";
  {
    std::vector<std::string> caps;
    for (const NarrowBackend& b : nb) {
      const int cap = plan.quick ? b.max_vertices_quick : b.max_vertices_full;
      if (!b.boxes_only && cap < plan.hull_sizes.back())
        caps.push_back("`" + b.backend + (b.backend == "custom" ? " (" + b.variant + ")" : "") +
                       "` up to N = " + std::to_string(cap));
    }
    for (std::size_t i = 0; i < caps.size(); ++i) md << (i ? ", " : "") << caps[i];
    md << " (the seed loops cost about 16 N^2 primitive tests per query; bullet-sat rebuilds its "
          "polyhedral features on every call; `fcl-box` takes boxes only).\n\n";
  }
  for (const PoseKind& k : kPoseKinds) {
    md << "### " << k.name << "\n\n| backend | variant |";
    for (int n : sizes) md << (n == 8 ? " box" : " N = " + std::to_string(n)) << " |";
    md << " exponent |\n|---|---|";
    for (std::size_t i = 0; i < sizes.size(); ++i) md << "---:|";
    md << "---:|\n";
    for (const NarrowBackend& b : nb) {
      md << "| " << b.backend << " | " << b.variant << " |";
      for (int n : sizes) {
        double t = NAN;
        std::string note;
        for (const NarrowRow& r : nrows)
          if (r.backend == b.backend && r.variant == b.variant && r.pose == k.name &&
              r.vertices == n) {
            t = r.ns_per_query;
            if (r.status != "ok") note = " (" + r.status.substr(0, r.status.find(':')) + ")";
          }
        md << " " << fmt_time(t) << note << " |";
      }
      md << " " << fmt(series_exponent(nrows, b.backend, b.variant, k.name), 2) << " |\n";
    }
    md << "\n![narrow phase, " << k.name << "](figures/perf_narrowphase_" << k.name << ".png)\n\n";
  }
  md << "## Broad phase\n\nFinding the pairs that pass the seed's bounding-sphere check in a crowd "
        "of 0.2 m cubes at random positions, one per 0.125 m^3 (so the pairs per body stay "
        "constant), after a small random motion of every body per step (not timed). Every method "
        "returns the same pairs (tests/engine/broadphase_test.cpp).\n\n| method |";
  for (int n : plan.crowd_sizes) md << " " << n << " |";
  md << " exponent | pairs per step |\n|---|";
  for (std::size_t i = 0; i < plan.crowd_sizes.size(); ++i) md << "---:|";
  md << "---:|---:|\n";
  for (BroadPhaseMethod m : methods) {
    md << "| " << to_string(m) << " |";
    std::vector<std::pair<double, double>> pts;
    double pairs = 0.0;
    for (int n : plan.crowd_sizes)
      for (const BroadRow& r : brows)
        if (r.method == to_string(m) && r.bodies == n) {
          md << " " << fmt_time(r.ns_per_step) << " |";
          if (std::isfinite(r.ns_per_step)) pts.push_back({static_cast<double>(n), r.ns_per_step});
          pairs = r.pairs_per_step;
        }
    md << " " << fmt(fit_exponent(pts), 2) << " | " << fmt(pairs, 4) << " (at "
       << plan.crowd_sizes.back() << ") |\n";
  }
  md << "\n![broad phase](figures/perf_broadphase.png)\n\n";
  md << "## Whole step\n\nscenes/many/ through each engine for two durations; microseconds per "
        "moving body per step = (time of the long run - time of the short run) / (extra steps x "
        "moving bodies), so building the world and the shapes cancels. `custom (fast)` is the "
        "registry's dynamics (fast detector, tree broad phase); `custom (seed)` is the seed's "
        "detector with the all-pairs check.\n\n"
        "| scene | moving bodies | backend | variant | µs per body per step | status |\n"
        "|---|---:|---|---|---:|---|\n";
  for (const StepRow& r : srows)
    md << "| " << r.scene << " | " << r.bodies << " (" << r.total_bodies << " in all) | "
       << r.backend << " | " << r.variant << " | " << fmt(r.us_per_body_step, 3) << " | "
       << r.status << " |\n";
  md << "\n";

  // Everything is built in a temporary folder, figures drawn there, then each file moved into
  // the output folder (other files there, such as `rbx report`'s, are kept).
  const fs::path target(out);
  fs::create_directories(target / "figures");
  const fs::path tmp = target / (".bench-tmp-" + std::to_string(getpid()));
  fs::remove_all(tmp);
  fs::create_directories(tmp / "figures");
  std::vector<std::string> files = {"perf.json", "perf.csv", "perf.md"};
  try {
    write_json((tmp / "perf.json").string(), j);
    write_text((tmp / "perf.csv").string(), csv.str());
    const std::string script = std::string(RBX_DEFAULT_SOURCE_DIR) + "/comparisons/output/bench_plots.py";
    std::string figures_note;
    if (!fs::exists("/usr/bin/python3")) {
      figures_note = "Figures not drawn: /usr/bin/python3 not found.";
    } else {
      const std::string cmd = "/usr/bin/python3 '" + script + "' '" + tmp.string() + "' > '" +
                              (tmp / "figures.log").string() + "' 2>&1";
      if (std::system(cmd.c_str()) != 0) {
        std::ifstream log(tmp / "figures.log");
        std::stringstream text;
        text << log.rdbuf();
        figures_note = "Figures not drawn: bench_plots.py failed:\n\n```\n" + text.str() + "```";
      }
    }
    if (!figures_note.empty()) md << figures_note << "\n";
    write_text((tmp / "perf.md").string(), md.str());
    for (const auto& entry : fs::directory_iterator(tmp / "figures"))
      files.push_back("figures/" + entry.path().filename().string());
    for (const std::string& f : files) fs::rename(tmp / f, target / f);
    fs::remove_all(tmp);
  } catch (...) {
    fs::remove_all(tmp);
    throw;
  }
  // The contract's reports/perf.md: the same page, its figure links relative to reports/.
  if (opt.out.empty()) {
    std::string page = md.str();
    for (size_t at = 0; (at = page.find("](figures/", at)) != std::string::npos; at += 17)
      page.replace(at, 10, "](latest/figures/");
    write_text((target.parent_path() / "perf.md").string(), page);
  }
  std::cout << "bench: " << (target / "perf.md").string() << " (" << total << " cases, "
            << fmt(clock.seconds(), 3) << " s)\n";
  for (const Goal& g : goals)
    std::cout << "  " << (g.met ? "met    " : "NOT MET") << "  " << g.goal << ": " << g.measured
              << "\n";
  return 0;
}

}  // namespace rbx
