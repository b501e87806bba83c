#include "comparisons/output/perf_report.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
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

// A series' exponent, NaN where the run has none.
double exponent(const std::map<std::string, double>& exponents, const std::string& series) {
  const auto it = exponents.find(series);
  return it == exponents.end() ? NAN : it->second;
}

// A number for perf.json: null when not finite.
Json finite(double x) { return std::isfinite(x) ? Json(x) : Json(nullptr); }

// A timed row's figures for perf.json: the median (the row's key), its quartiles, counts and
// the cold pass.
void put_time(Json& row, const std::string& key, const BenchTime& t) {
  row[key] = finite(t.median);
  row["q25"] = finite(t.q25);
  row["q75"] = finite(t.q75);
  row["rounds"] = t.rounds;
  row["calls"] = t.calls;
  row["cold"] = finite(t.cold);
}

// A table cell: the median and half its 25-75 % range, relative ("4.1 µs ±1.2%").
std::string time_cell(const BenchTime& t, bool ns) {
  if (!std::isfinite(t.median)) return "—";
  std::string cell = ns ? fmt_duration_ns(t.median) : bench_num(t.median, 3);
  if (t.rounds > 1 && t.median > 0)
    cell += " ±" + bench_num(50.0 * (t.q75 - t.q25) / t.median, 2) + "%";
  return cell;
}

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
  for (const NarrowRow& r : results.narrow) {
    Json row = {{"kind", "narrowphase"},
                {"backend", r.backend},
                {"variant", r.variant},
                {"vertices", r.vertices},
                {"hull_vertices", r.hull_vertices},
                {"pose", r.pose},
                {"status", r.status}};
    put_time(row, "ns_per_query", r.ns_per_query);
    j["rows"].push_back(row);
  }
  for (const auto& [kind, family] :
       {std::pair<const char*, const std::vector<NarrowRow>*>{"distance", &results.distance},
        {"toi", &results.toi}})
    for (const NarrowRow& r : *family) {
      Json row = {{"kind", kind},
                  {"backend", r.backend},
                  {"variant", r.variant},
                  {"vertices", r.vertices},
                  {"hull_vertices", r.hull_vertices},
                  {"gap", r.pose},
                  {"status", r.status}};
      put_time(row, "ns_per_query", r.ns_per_query);
      j["rows"].push_back(row);
    }
  for (const BroadRow& r : results.broad) {
    Json row = {{"kind", "broadphase"},
                {"method", r.method},
                {"bodies", r.bodies},
                {"pairs_per_step", r.pairs_per_step}};
    put_time(row, "ns_per_step", r.ns_per_step);
    j["rows"].push_back(row);
  }
  for (const StepRow& r : results.step) {
    Json row = {{"kind", "step"},    {"backend", r.backend}, {"variant", r.variant},
                {"scene", r.scene},  {"bodies", r.bodies},   {"total_bodies", r.total_bodies},
                {"status", r.status}};
    put_time(row, "us_per_body_step", r.us_per_body_step);
    j["rows"].push_back(row);
  }
  for (const ExploreRow& r : results.explore) {
    Json row = {{"kind", "explore"}, {"backends", r.backends}, {"samples", r.samples}};
    put_time(row, "samples_per_minute", r.samples_per_minute);
    j["rows"].push_back(row);
  }
  j["goals"] = Json::array();
  for (const PerfGoal& g : goals) {
    Json ratios = Json::array();
    for (const GoalRatio& q : g.ratios)
      ratios.push_back({{"between", q.label},
                        {"median", finite(q.ratio.median)},
                        {"q25", finite(q.ratio.q25)},
                        {"q75", finite(q.ratio.q75)},
                        {"rounds", q.ratio.rounds}});
    j["goals"].push_back(
        {{"goal", g.goal}, {"measured", g.measured}, {"met", g.met}, {"ratios", ratios}});
  }
  j["exponents"] = Json::object();
  for (const NarrowBackend& b : nb)
    for (const PoseKind& k : kPoseKinds) {
      const std::string key = narrow_series(b.backend, b.variant, k.name);
      const double e = exponent(results.narrow_exponents, key);
      if (std::isfinite(e)) j["exponents"][key] = e;
    }

  return j;
}

// perf.csv: one line per row.
std::string perf_csv(const BenchResults& results) {
  std::ostringstream csv;
  auto figures = [](const BenchTime& t) {
    return bench_num(t.median, 6) + "," + bench_num(t.q25, 6) + "," + bench_num(t.q75, 6) + "," +
           std::to_string(t.rounds) + "," + std::to_string(t.calls) + "," + bench_num(t.cold, 6);
  };
  csv << "kind,backend,variant,method,scene,vertices,pose,bodies,value,q25,q75,rounds,calls,cold,"
         "unit\n";
  for (const NarrowRow& r : results.narrow)
    csv << "narrowphase," << r.backend << "," << r.variant << ",,," << r.vertices << "," << r.pose
        << ",," << figures(r.ns_per_query) << ",ns_per_query\n";
  for (const NarrowRow& r : results.distance)
    csv << "distance," << r.backend << "," << r.variant << ",,," << r.vertices << "," << r.pose
        << ",," << figures(r.ns_per_query) << ",ns_per_query\n";
  for (const NarrowRow& r : results.toi)
    csv << "toi," << r.backend << "," << r.variant << ",,," << r.vertices << "," << r.pose << ",,"
        << figures(r.ns_per_query) << ",ns_per_query\n";
  for (const BroadRow& r : results.broad)
    csv << "broadphase,,," << r.method << ",,,," << r.bodies << "," << figures(r.ns_per_step)
        << ",ns_per_step\n";
  for (const StepRow& r : results.step)
    csv << "step," << r.backend << "," << r.variant << ",," << r.scene << ",,," << r.bodies << ","
        << figures(r.us_per_body_step) << ",us_per_body_step\n";

  return csv.str();
}

// perf.md's head: how it was timed, the goals and why a goal is not met.
std::string goals_markdown(const BenchPlan& plan, const BenchResults& results,
                           const std::vector<PerfGoal>& goals, double timing_s) {
  std::ostringstream md;
  md << "# Performance: `rbx bench" << (plan.quick ? " --quick" : "") << "`\n\n";
  md << "Machine: " << cpu_model() << ", " << results.cpus << " CPUs (shared); Release build; "
     << (plan.quick ? "quick run (fewer sizes and poses, short times). " : "full run. ")
     << "Every case runs its warm-up first, timed alone (its cold pass, in perf.json and "
        "perf.csv). The cases compared with each other (the backends on one shape size and pose "
        "kind, the broad-phase methods on one crowd, the engines on one scene) are timed "
        "together, in rounds taken in turns with the first case rotating, until each has at "
        "least "
     << plan.min_time << " s (narrow phase), " << plan.crowd_min_time << " s (broad phase), "
     << plan.step_min_time << " s and " << plan.step_rounds
     << " rounds (whole step) and 7 rounds, so a passing load of the shared machine falls on "
        "them alike (docs/bench.md). A time is the median over rounds, ± half its 25-75 % "
        "range; a ratio is taken round by round, its median with the 25-75 % range of the "
        "rounds' ratios. Wall time of the timing: "
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
        "predictor has learned by heart (docs/bench.md); the time is the median over rounds of the "
        "mean per query in a round, ± half the 25-75 % range of the rounds. Times "
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
          "polyhedral features on every call; DART collides the hulls as triangle meshes; Bullet "
          "and ODE build their shapes from the points on every call, about 2 s a query at "
          "N = 8192; `fcl (boxes)` is fcl on box bodies only).\n\n";
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
        BenchTime t;
        std::string note;
        for (const NarrowRow& r : results.narrow)
          if (r.backend == b.backend && r.variant == b.variant && r.pose == k.name &&
              r.vertices == n) {
            t = r.ns_per_query;
            if (r.status != "ok") note = " (" + r.status.substr(0, r.status.find(':')) + ")";
          }
        md << " " << time_cell(t, true) << note << " |";
      }
      md << " "
         << bench_num(
                exponent(results.narrow_exponents, narrow_series(b.backend, b.variant, k.name)), 2)
         << " |\n";
    }
    md << "\n![narrow phase, " << k.name << "](figures/perf_narrowphase_" << k.name << ".png)\n\n";
  }
  return md.str();
}

// A query family's tables, one per gap kind: every row per size, then `ratio`'s row (custom's
// time over another row's, the median of the ratios round by round, ± half their 25-75 % range)
// when it names one.
std::string gap_tables(const BenchPlan& plan,
                       const std::vector<std::pair<std::string, std::string>>& rows,
                       const std::vector<NarrowRow>& results,
                       const std::pair<std::string, std::string>& ratio_to,
                       const std::vector<PoseKind>& kinds) {
  std::vector<int> sizes = {8};
  sizes.insert(sizes.end(), plan.hull_sizes.begin(), plan.hull_sizes.end());
  std::ostringstream md;
  auto find = [&](const std::string& backend, const std::string& variant, const char* gap,
                  int n) -> const NarrowRow* {
    for (const NarrowRow& r : results)
      if (r.backend == backend && r.variant == variant && r.pose == gap && r.vertices == n)
        return &r;
    return nullptr;
  };
  for (const PoseKind& k : kinds) {
    md << "### " << k.name << "\n\n| backend | variant |";
    for (int n : sizes) md << (n == 8 ? " box" : " N = " + std::to_string(n)) << " |";
    md << "\n|---|---|";
    for (std::size_t i = 0; i < sizes.size(); ++i) md << "---:|";
    md << "\n";
    for (const auto& [backend, variant] : rows) {
      md << "| " << backend << " | " << variant << " |";
      for (int n : sizes) {
        const NarrowRow* r = find(backend, variant, k.name, n);
        std::string note;
        if (r && r->status != "ok") note = " (" + r->status.substr(0, r->status.find(':')) + ")";
        md << " " << (r ? time_cell(r->ns_per_query, true) : std::string("—")) << note << " |";
      }
      md << "\n";
    }
    if (!ratio_to.first.empty()) {
      md << "| **custom / " << ratio_to.first << " (" << ratio_to.second << ")** | |";
      for (int n : sizes) {
        const NarrowRow* c = find("custom", "default", k.name, n);
        const NarrowRow* f = find(ratio_to.first, ratio_to.second, k.name, n);
        if (!c || !f) {
          md << " — |";
          continue;
        }
        const RatioSpread q = bench_ratio(c->ns_per_query, f->ns_per_query);
        md << " " << bench_num(q.median, 3);
        if (q.rounds > 1 && q.median > 0)
          md << " ±" << bench_num(50.0 * (q.q75 - q.q25) / q.median, 2) << "%";
        md << " |";
      }
      md << "\n";
    }
    md << "\n";
  }
  return md.str();
}

// The gaps of kGapKinds, as prose: "1% or 20% of the size".
std::string gap_prose() {
  std::ostringstream md;
  for (size_t k = 0; k < std::size(kGapKinds); ++k)
    md << (k ? " or " : "") << kGapKinds[k].offset * 100 << "% of the size";
  return md.str();
}

// The distance queries: every one per gap and size, and custom's time over FCL's prebuilt one.
std::string distance_markdown(const BenchPlan& plan, const BenchResults& results) {
  if (results.distance.empty()) return "";
  std::vector<std::pair<std::string, std::string>> rows;
  for (const DistanceBackend& b : distance_backends()) rows.push_back({b.backend, b.variant});
  std::ostringstream md;
  md << "\n## Distance query\n\n"
     << "Every distance query (`rbx distance`, docs/distance.md) on the narrow phase's shapes, "
        "placed as its poses are but with B beyond touching by "
     << gap_prose() << " along the placement direction (*" << kGapKinds[0].name << "*, *"
     << kGapKinds[1].name
     << "*); timed as the narrow phase is, each adapter doing what it does per call (`fcl "
        "(prebuilt)` with each fcl::Box or Convex built once, the fair comparison for custom). "
        "The last row of each table is custom's time over FCL's prebuilt one, the median of the "
        "ratios round by round, ± half their 25-75 % range.\n\n";
  md << gap_tables(plan, rows, results.distance, {"fcl", "prebuilt"},
                   {std::begin(kGapKinds), std::end(kGapKinds)});
  return md.str();
}

// The time-of-impact queries: every one per gap and size, and custom's time over Bullet's
// prebuilt hulls' (FCL's libccd rows miss the exact landings these poses are).
std::string toi_markdown(const BenchPlan& plan, const BenchResults& results) {
  if (results.toi.empty()) return "";
  std::vector<std::pair<std::string, std::string>> rows;
  for (const ToiBackend& b : toi_backends()) rows.push_back({b.backend, b.variant});
  std::ostringstream md;
  md << "\n## Time-of-impact query\n\n"
     << "Every time-of-impact query (`rbx toi`, docs/time_of_impact.md) on the distance "
        "queries' poses (B beyond touching by "
     << gap_prose()
     << "), B moving onto A by the centres' offset over an interval of 1 s, in pure translation "
        "(so that the translation-only casts answer the same question), and at the wider gap "
        "turning by "
     << kToiKinds[2].turn << " rad on its way as well (*" << kToiKinds[2].name
     << "*; the casts answer only translation); a library's plain row "
        "builds its shapes on every call, as the plain distance rows do, its `prebuilt` row "
        "once (the same answers). A row that does not answer ok is noted (Bullet's "
        "btGjkConvexCast misses exact landings, FCL's libccd rows some: docs/time_of_impact.md). "
        "The last row of each table is custom's time over Bullet's prebuilt hulls' (conservative "
        "advancement too, and an answer on every pose).\n\n";
  md << gap_tables(plan, rows, results.toi, {"bullet-hull", "prebuilt"},
                   {std::begin(kToiKinds), std::end(kToiKinds)});
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
        "reuse them); all-pairs, the reference, tests every pair on every step.\n\n| method |";
  for (int n : plan.crowd_sizes) md << " " << n << " |";
  md << " exponent | pairs per step |\n|---|";
  for (std::size_t i = 0; i < plan.crowd_sizes.size(); ++i) md << "---:|";
  md << "---:|---:|\n";
  for (BroadPhaseMethod m : kBenchBroadPhaseMethods) {
    md << "| " << to_string(m) << " |";
    double pairs = 0.0;
    for (int n : plan.crowd_sizes)
      for (const BroadRow& r : results.broad)
        if (r.method == to_string(m) && r.bodies == n) {
          md << " " << time_cell(r.ns_per_step, true) << " |";
          pairs = r.pairs_per_step;
        }
    md << " " << bench_num(exponent(results.broad_exponents, to_string(m)), 2) << " | "
       << bench_num(pairs, 4) << " (at " << plan.crowd_sizes.back() << ") |\n";
  }
  md << "\n![broad phase](figures/perf_broadphase.png)\n\n";
  return md.str();
}

// The whole step per scene and engine.
std::string step_markdown(const BenchResults& results) {
  std::ostringstream md;
  md << "## Whole step\n\nscenes/many/ through each engine for two durations; microseconds per "
        "moving body per step = (time of the long run - time of the short run) / (extra steps x "
        "moving bodies), so building the world and the shapes cancels. `custom` is the "
        "registry's dynamics (accelerated detector, tree broad phase); `custom (faithful)` is the "
        "same engine (friction, manifolds, time of impact) on the faithful detector (the seed's "
        "loops) with the all-pairs check; "
        "`custom-seed` is the seed's algorithm as the custom-seed backend runs it (first hit, "
        "single-point frictionless impulse).\n\n"
        "Each round runs the short and the long run of every engine in turn; its difference "
        "gives that round's figure.\n\n"
        "| scene | moving bodies | backend | variant | µs per body per step | 25-75 % | rounds "
        "| status |\n"
        "|---|---:|---|---|---:|---|---:|---|\n";
  for (const StepRow& r : results.step)
    md << "| " << r.scene << " | " << r.bodies << " (" << r.total_bodies << " in all) | "
       << r.backend << " | " << r.variant << " | " << bench_num(r.us_per_body_step.median, 3)
       << " | " << bench_num(r.us_per_body_step.q25, 3) << "-"
       << bench_num(r.us_per_body_step.q75, 3) << " | " << r.us_per_body_step.rounds << " | "
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
     << distance_markdown(plan, results) << toi_markdown(plan, results)
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
