#include "comparisons/output/perf_report.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "comparisons/eval/json_io.h"
#include "comparisons/output/figure_script.h"
#include "engine/format.h"

namespace rbx {

namespace fs = std::filesystem;

namespace {

// A number with `digits` significant digits for the pages, "—" when not finite (and "-0" kept,
// as the stream formatting these pages were first written with).
std::string bench_num(double x, int digits = 3) {
  NumberFormat f;
  f.digits = digits;
  f.signed_zero = true;
  f.non_finite = "—";
  return format_number(x, f);
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

// The profiles behind the contact-query goals (perf and cachegrind, 2026-11-28, after the inner
// polytope, the region's centre and the scan on AVX; hulls of random points on a sphere), each a
// measured cause.
constexpr const char* kDetectorProfile =
    "touching, the tests no longer run for shapes the inner polytope proves to overlap: at N = 32 "
    "the shapes' vertex climbs (GJK's and EPA's supports, the candidates' overlaps) are about a "
    "quarter of the query, the narrowed search an eighth, EPA's own bookkeeping a tenth and the "
    "region's centre about a fifth.";
constexpr const char* kDeepProfile =
    "deep, small hulls: at N = 128 the shapes' supports (a scan of every vertex, four at a time) "
    "are about 3/10 of the query's instructions (about 15 EPA iterations, two supports each, "
    "before the polytope's nearest triangle lies on a face of the Minkowski difference), EPA's "
    "own bookkeeping (nearest triangle, seen triangles, new faces) about a quarter, the narrowed "
    "search about a fifth and the region's centre about a twentieth. FCL's convex pairs run "
    "libccd's MPR, which estimates the depth without certifying the least overlap.";

// The profile behind the whole-step goal (perf, 2026-11-28, many_1000 over the bench's first 60
// steps, with the broad phase's pairs kept from step to step), a measured cause.
constexpr const char* kStepProfile =
    "the whole step, many_1000: the separation proofs of the pairs passing the bounding check are "
    "about a third of the step (the seed's bounding spheres of neighbouring cubes overlap, so "
    "about 2,700 pairs pass it each step), the look-ahead's moves of every body about a sixth, "
    "the broad phase (its pairs kept from step to step) and the state check about a tenth each. "
    "On many_100 Bullet's own time varies by a quarter from run to run (0.26 to 0.33 µs per "
    "body-step).";

std::vector<PerfGoal> perf_goals(const BenchPlan& plan, const BenchResults& results) {
  std::vector<PerfGoal> goals;
  const double fast_exp = series_exponent(results.narrow, "custom", "accelerated", "touching");
  goals.push_back({"custom (accelerated), touching: time grows no faster than N^1.2",
                   "exponent " + bench_num(fast_exp) +
                       " (N = " + std::to_string(plan.hull_sizes.front()) + " to " +
                       std::to_string(plan.hull_sizes.back()) + ")",
                   std::isfinite(fast_exp) && fast_exp <= 1.2, ""});
  const double fast_2048 = find_time(results.narrow, "custom", "accelerated", "touching", 2048);
  // Against FCL with its shapes built once (custom keeps its hierarchies per shape too): the
  // per-call `fcl` row also pays for building fcl::Convex, which would flatter custom.
  const double fcl_2048 = find_time(results.narrow, "fcl", "prebuilt", "touching", 2048);
  goals.push_back(
      {"custom (accelerated) no slower than fcl (shapes prebuilt) at N = 2048, touching",
       fmt_duration_ns(fast_2048) + " vs " + fmt_duration_ns(fcl_2048) + ": ratio " +
           bench_num(fast_2048 / fcl_2048),
       fast_2048 <= fcl_2048, kDetectorProfile});
  const double fast_box = find_time(results.narrow, "custom", "accelerated", "touching", 8);
  const double fclbox = find_time(results.narrow, "fcl-box", "default", "touching", 8);
  goals.push_back({"custom (accelerated) within 1.5x of fcl-box on two boxes, touching",
                   fmt_duration_ns(fast_box) + " vs " + fmt_duration_ns(fclbox) + ": ratio " +
                       bench_num(fast_box / fclbox),
                   fast_box <= 1.5 * fclbox, ""});
  for (BroadPhaseMethod m : kBenchBroadPhaseMethods) {
    std::vector<std::pair<double, double>> pts;
    for (const BroadRow& r : results.broad)
      if (r.method == to_string(m) && std::isfinite(r.ns_per_step))
        pts.push_back({static_cast<double>(r.bodies), r.ns_per_step});
    if (m == BroadPhaseMethod::Tree) {
      const double e = fit_exponent(pts);
      goals.push_back(
          {"broad phase (tree, the world's default): pair finding grows no faster than "
           "N^1.2",
           "exponent " + bench_num(e) + " (" + std::to_string(plan.crowd_sizes.front()) + " to " +
               std::to_string(plan.crowd_sizes.back()) + " bodies)",
           std::isfinite(e) && e <= 1.2, ""});
    }
  }

  // Issues 11 and 24: the custom contact query (detector and contact plane) no slower than FCL
  // with prebuilt shapes at every hull size timed, touching (issue 11) and deep (issue 24).
  for (const char* pose : {"touching", "deep"}) {
    std::string measured;
    bool met = true;
    int compared = 0;
    for (int n : plan.hull_sizes) {
      const double c = find_time(results.narrow, "custom", "accelerated", pose, n);
      const double f = find_time(results.narrow, "fcl", "prebuilt", pose, n);
      if (!std::isfinite(c) || !std::isfinite(f)) continue;
      ++compared;
      met = met && c <= f;
      measured += (measured.empty() ? "" : ", ") + ("N = " + std::to_string(n) + ": ") +
                  bench_num(c / f, 2) + "x";
    }
    const bool touching = std::string(pose) == "touching";
    goals.push_back(
        {std::string("custom (accelerated) no slower than fcl (shapes prebuilt) at every hull "
                     "size timed, ") +
             pose + (touching ? " (issue 11)" : " (issue 24)"),
         measured.empty() ? "not measured" : measured, met && compared > 0,
         touching ? kDetectorProfile : kDeepProfile});
  }
  for (const char* scene : {"many_100", "many_1000"}) {
    double custom = NAN, bullet = NAN;
    for (const StepRow& r : results.step)
      if (r.scene == scene && r.variant != "faithful") {
        if (r.backend == "custom") custom = r.us_per_body_step;
        if (r.backend == "bullet") bullet = r.us_per_body_step;
      }
    const std::string measured = bench_num(custom, 3) + " µs vs " + bench_num(bullet, 3) +
                                 " µs: ratio " + bench_num(custom / bullet, 3);
    goals.push_back({std::string("whole custom step within 2x of Bullet per body-step on ") +
                         scene + " (issue 11)",
                     measured, custom <= 2.0 * bullet, ""});
    // Issue 24: with the time of impact of every new contact and the chosen plane.
    goals.push_back({std::string("whole custom step no slower than Bullet per body-step on ") +
                         scene + " (issue 24)",
                     measured, custom <= bullet, kStepProfile});
  }
  // Issue 15: the extended engine (friction, manifolds, time of impact) within 2x of the
  // seed's algorithm (the custom-seed backend) per body-step on many_1000.
  {
    double custom = NAN, seed = NAN;
    for (const StepRow& r : results.step)
      if (r.scene == "many_1000") {
        if (r.backend == "custom" && r.variant != "faithful") custom = r.us_per_body_step;
        if (r.backend == "custom-seed") seed = r.us_per_body_step;
      }
    goals.push_back({"custom step within 2x of custom-seed per body-step on many_1000 (issue 15)",
                     bench_num(custom, 3) + " µs vs " + bench_num(seed, 3) + " µs: ratio " +
                         bench_num(custom / seed, 3),
                     custom <= 2.0 * seed, ""});
  }
  // Issue 17: explore's contact samples per minute per core.
  for (const ExploreRow& r : results.explore)
    goals.push_back({"rbx explore: at least 50,000 contact samples per minute per core through " +
                         r.backends + " on hulls under 100 points (issue 17)",
                     bench_num(r.samples_per_minute, 3) + " per minute (one thread, " +
                         std::to_string(r.samples) +
                         " samples of seed 1, as `rbx explore --bench --threads 1`)",
                     r.samples_per_minute >= 50000.0, ""});
  return goals;
}

namespace {

// perf.json: the machine, the settings, every row, the goals and the fitted exponents.
Json perf_json(const BenchPlan& plan, const BenchResults& results,
               const std::vector<PerfGoal>& goals) {
  const std::vector<NarrowBackend> nb = narrow_backends();
  Json j;
  j["generated_by"] = "rbx bench";
  j["mode"] = plan.quick ? "quick" : "full";
  j["machine"] = {
      {"cpu", cpu_model()}, {"cpus", results.cpus}, {"mhz", results.mhz}, {"hostname", [] {
                                                                             char h[256] = {0};
                                                                             gethostname(
                                                                                 h, sizeof h - 1);
                                                                             return std::string(h);
                                                                           }()}};
  j["settings"] = {{"poses_per_kind", plan.poses},
                   {"poses_per_iteration", plan.poses_per_iteration},
                   {"min_time_s", plan.min_time},
                   {"shape_size_m", kBenchShapeSize},
                   {"touching_offset", kPoseKinds[0].offset},
                   {"deep_offset", kPoseKinds[1].offset},
                   {"separated_offset", kPoseKinds[2].offset}};
  j["rows"] = Json::array();
  for (const NarrowRow& r : results.narrow)
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
  for (const BroadRow& r : results.broad)
    j["rows"].push_back(
        {{"kind", "broadphase"},
         {"method", r.method},
         {"bodies", r.bodies},
         {"ns_per_step", std::isfinite(r.ns_per_step) ? Json(r.ns_per_step) : Json(nullptr)},
         {"pairs_per_step", r.pairs_per_step}});
  for (const StepRow& r : results.step)
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
  for (const PerfGoal& g : goals)
    j["goals"].push_back({{"goal", g.goal}, {"measured", g.measured}, {"met", g.met}});
  j["exponents"] = Json::object();
  for (const NarrowBackend& b : nb)
    for (const PoseKind& k : kPoseKinds) {
      const double e = series_exponent(results.narrow, b.backend, b.variant, k.name);
      if (std::isfinite(e)) j["exponents"][b.backend + "/" + b.variant + "/" + k.name] = e;
    }

  return j;
}

// perf.csv: one line per row.
std::string perf_csv(const BenchResults& results) {
  std::ostringstream csv;
  csv << "kind,backend,variant,method,scene,vertices,pose,bodies,value,unit\n";
  for (const NarrowRow& r : results.narrow)
    csv << "narrowphase," << r.backend << "," << r.variant << ",,," << r.vertices << "," << r.pose
        << ",," << bench_num(r.ns_per_query, 6) << ",ns_per_query\n";
  for (const BroadRow& r : results.broad)
    csv << "broadphase,,," << r.method << ",,,," << r.bodies << "," << bench_num(r.ns_per_step, 6)
        << ",ns_per_step\n";
  for (const StepRow& r : results.step)
    csv << "step," << r.backend << "," << r.variant << ",," << r.scene << ",,," << r.bodies << ","
        << bench_num(r.us_per_body_step, 6) << ",us_per_body_step\n";

  return csv.str();
}

// perf.md's head: how it was timed, the goals and why a goal is not met.
std::string goals_markdown(const BenchPlan& plan, const BenchResults& results,
                           const std::vector<PerfGoal>& goals, double timing_s) {
  std::ostringstream md;
  md << "# Performance: `rbx bench" << (plan.quick ? " --quick" : "") << "`\n\n";
  md << "Machine: " << cpu_model() << ", " << results.cpus << " CPUs (shared); Release build; "
     << (plan.quick ? "quick run (fewer sizes and poses, short times). " : "full run. ")
     << "Google Benchmark: every case runs one untimed warm-up pass, then is timed for at least "
     << plan.min_time << " s (narrow phase), " << plan.crowd_min_time << " s (broad phase), "
     << plan.step_min_time << " s (whole step); the broad phase, "
     << (plan.quick ? "" : "the whole steps, ")
     << "the narrow-phase cases of up to 128 vertices and those behind the goals run "
     << kBenchRepetitions
     << " times and keep the fastest (the machine is shared). Wall time of the timing: "
     << bench_num(timing_s, 3) << " s.\n\n";
  md << "## Goals\n\n| goal | measured | met |\n|---|---|---|\n";
  for (const PerfGoal& g : goals)
    md << "| " << g.goal << " | " << g.measured << " | " << (g.met ? "yes" : "**no**") << " |\n";
  // Behind each goal not met: its profile, as last measured.
  std::vector<std::string> behind;
  for (const PerfGoal& g : goals)
    if (!g.met && !g.behind.empty() &&
        std::find(behind.begin(), behind.end(), g.behind) == behind.end())
      behind.push_back(g.behind);
  for (const std::string& b : behind) md << "\nWhy not met: " << b << "\n";
  return md.str();
}

// The narrow phase: every contact backend per pose kind and size, with its exponent.
std::string narrow_markdown(const BenchPlan& plan, const BenchResults& results) {
  const std::vector<NarrowBackend> nb = narrow_backends();
  std::vector<int> sizes = {8};
  sizes.insert(sizes.end(), plan.hull_sizes.begin(), plan.hull_sizes.end());
  std::ostringstream md;
  md << "\n## Narrow phase\n\n"
     << "Every contact backend through the registry's `ContactFn` on the same pairs: two unit "
        "boxes (N = 8), and two hulls of N random points on a sphere of diameter 1 m (every "
        "point is a hull vertex). Poses: random orientations and a random direction; the "
        "touching distance along it is found by bisection with libccd, then B is placed "
     << -kPoseKinds[0].offset * 100 << "% of the size deep (*touching*), "
     << -kPoseKinds[1].offset * 100 << "% deep (*deep*) or with a " << kPoseKinds[2].offset * 100
     << "% gap (*separated*); " << plan.poses << " distinct poses per kind, taken in turn, "
     << plan.poses_per_iteration
     << " per timed iteration, so that no backend is timed on a few poses its processor's branch "
        "predictor has learned by heart (docs/bench.md); the time is the mean per query. Times "
        "include what each adapter "
        "does per call (the references build their library's shape from the hull on every "
        "query, as the adapters are written; `custom` caches its hierarchies per shape "
        "and reuses one detection cache per thread, as the world reuses one per pair; "
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
        caps.push_back("`" + b.backend + (b.variant != "default" ? " (" + b.variant + ")" : "") +
                       "` up to N = " + std::to_string(cap));
    }
    for (std::size_t i = 0; i < caps.size(); ++i) md << (i ? ", " : "") << caps[i];
    md << " (the seed loops cost about 16 N^2 primitive tests per query; bullet-sat rebuilds its "
          "polyhedral features on every call; DART collides the hulls as triangle meshes; "
          "`fcl-box` "
          "takes boxes only).\n\n";
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
        for (const NarrowRow& r : results.narrow)
          if (r.backend == b.backend && r.variant == b.variant && r.pose == k.name &&
              r.vertices == n) {
            t = r.ns_per_query;
            if (r.status != "ok") note = " (" + r.status.substr(0, r.status.find(':')) + ")";
          }
        md << " " << fmt_duration_ns(t) << note << " |";
      }
      md << " " << bench_num(series_exponent(results.narrow, b.backend, b.variant, k.name), 2)
         << " |\n";
    }
    md << "\n![narrow phase, " << k.name << "](figures/perf_narrowphase_" << k.name << ".png)\n\n";
  }
  return md.str();
}

// The broad phase: every method per crowd size.
std::string broad_markdown(const BenchPlan& plan, const BenchResults& results) {
  std::ostringstream md;
  md << "## Broad phase\n\nFinding the pairs that pass the seed's bounding-sphere check in a crowd "
        "of 0.2 m cubes at random positions, one per 0.125 m^3 (so the pairs per body stay "
        "constant), after a small random motion of every body per step (not timed). Every method "
        "returns the same pairs (tests/engine/broadphase_test.cpp). Sweep and prune and the tree "
        "keep their pairs from step to step while no centre has moved more than a tenth of the "
        "median bounding radius (here about 1 mm per axis per step against 17 mm of room, so most "
        "steps "
        "reuse them); all-pairs, the oracle, tests every pair on every step.\n\n| method |";
  for (int n : plan.crowd_sizes) md << " " << n << " |";
  md << " exponent | pairs per step |\n|---|";
  for (std::size_t i = 0; i < plan.crowd_sizes.size(); ++i) md << "---:|";
  md << "---:|---:|\n";
  for (BroadPhaseMethod m : kBenchBroadPhaseMethods) {
    md << "| " << to_string(m) << " |";
    std::vector<std::pair<double, double>> pts;
    double pairs = 0.0;
    for (int n : plan.crowd_sizes)
      for (const BroadRow& r : results.broad)
        if (r.method == to_string(m) && r.bodies == n) {
          md << " " << fmt_duration_ns(r.ns_per_step) << " |";
          if (std::isfinite(r.ns_per_step)) pts.push_back({static_cast<double>(n), r.ns_per_step});
          pairs = r.pairs_per_step;
        }
    md << " " << bench_num(fit_exponent(pts), 2) << " | " << bench_num(pairs, 4) << " (at "
       << plan.crowd_sizes.back() << ") |\n";
  }
  md << "\n![broad phase](figures/perf_broadphase.png)\n\n";
  return md.str();
}

// The whole step per scene and engine.
std::string step_markdown(const BenchResults& results) {
  std::ostringstream md;
  md << "## Whole step\n\nscenes/many/ through each engine for two durations; microseconds per "
        "moving body per step = (time of the long run - time of the short run) / (extra steps x "
        "moving bodies), so building the world and the shapes cancels. `custom (accelerated)` is "
        "the "
        "registry's dynamics (accelerated detector, tree broad phase); `custom (faithful)` is the "
        "same engine (friction, manifolds, time of impact) on the faithful detector (the seed's "
        "loops) with the all-pairs check; "
        "`custom-seed` is the seed's algorithm as the custom-seed backend runs it (first hit, "
        "single-point frictionless impulse).\n\n"
        "| scene | moving bodies | backend | variant | µs per body per step | status |\n"
        "|---|---:|---|---|---:|---|\n";
  for (const StepRow& r : results.step)
    md << "| " << r.scene << " | " << r.bodies << " (" << r.total_bodies << " in all) | "
       << r.backend << " | " << r.variant << " | " << bench_num(r.us_per_body_step, 3) << " | "
       << r.status << " |\n";
  md << "\n";

  return md.str();
}

}  // namespace

void write_perf_pages(const BenchPlan& plan, const BenchResults& results,
                      const std::vector<PerfGoal>& goals, double timing_s, const std::string& out,
                      bool contract_copy) {
  const Json j = perf_json(plan, results, goals);
  std::ostringstream csv;
  csv << perf_csv(results);
  std::ostringstream md;
  md << goals_markdown(plan, results, goals, timing_s) << narrow_markdown(plan, results)
     << broad_markdown(plan, results) << step_markdown(results);
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
    std::string figures_note, why;
    const int rc =
        run_figure_script("bench_plots.py", {tmp.string()}, (tmp / "figures.log").string(), &why);
    if (rc < 0) {
      figures_note = "Figures not drawn: " + why + ".";
    } else if (rc != 0) {
      std::ifstream log(tmp / "figures.log");
      std::stringstream text;
      text << log.rdbuf();
      figures_note = "Figures not drawn: bench_plots.py failed:\n\n```\n" + text.str() + "```";
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
  if (contract_copy) {
    std::string page = md.str();
    for (size_t at = 0; (at = page.find("](figures/", at)) != std::string::npos; at += 17)
      page.replace(at, 10, "](latest/figures/");
    write_text((target.parent_path() / "perf.md").string(), page);
  }
}

}  // namespace rbx
