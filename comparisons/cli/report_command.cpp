// `rbx report`: runs a scene library through every check and backend it needs and writes
// report.md, results.json, CSV files and figures into one folder, atomically.
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <mutex>

#include "comparisons/cli/commands.h"
#include "comparisons/eval/ensemble.h"
#include "comparisons/eval/explore_check.h"
#include "comparisons/eval/parallel.h"
#include "comparisons/eval/regression_check.h"
#include "comparisons/eval/scene_batch.h"
#include "comparisons/eval/tosses.h"
#include "comparisons/output/query_report.h"
#include "comparisons/output/report_pages.h"
#include "comparisons/output/report_writer.h"
#include "comparisons/output/tosses_report.h"
#include "comparisons/output/view_page.h"
#include "comparisons/scene/repo_path.h"
#include "comparisons/scene/scene_collection.h"
#include "comparisons/scene/scene_file.h"

namespace fs = std::filesystem;

namespace rbx {

namespace {

// Progress on a terminal only; quiet in CI and when piped.
class Progress {
 public:
  explicit Progress(bool quiet)
      : on_(!quiet && isatty(STDERR_FILENO) && std::getenv("CI") == nullptr) {}
  void show(size_t i, size_t n, const std::string& what, double elapsed) {
    if (!on_) return;
    std::cerr << "\r\033[K[" << i << "/" << n << "] " << what << " (" << fmt_num(elapsed, 3)
              << " s)" << std::flush;
  }
  void done() {
    if (on_) std::cerr << "\r\033[K" << std::flush;
  }

 private:
  bool on_;
};

// Wall time of each part of a report, in the order they ran: where a slow report spends it.
class PartTimes {
 public:
  void end(const char* part) {
    const double now = clock_.seconds();
    if (!line_.empty()) line_ += ", ";
    line_ += std::string(part) + " " + fmt_num(now - last_, 3) + " s";
    last_ = now;
  }
  const std::string& line() const { return line_; }

 private:
  Stopwatch clock_;
  double last_ = 0.0;
  std::string line_;
};

// `--check`: the regression check from this report's own runs, the same metrics rbx check
// measures (the scenes at their own step, explore's fixed samples, and the tosses when the whole
// library ran), compared and printed as rbx check prints them; 1 when any is worse.
int check_report_run(const ReportOptions& opt, const Json& baseline,
                     const std::vector<Scene>& scenes, const std::vector<SceneEvaluation>& evs,
                     const std::vector<ExploreCheckMetric>& explore, const Stopwatch& clock) {
  CheckSettings set;
  set.explore = opt.explore || opt.inputs.empty();
  set.tosses = opt.inputs.empty();
  CheckRun run;
  add_scene_metrics(scenes, evs, set, run);
  add_explore_metrics(explore, set, run);
  if (set.tosses) add_toss_metrics(set, run);
  run.runtime_s = clock.seconds();
  const CheckDiff d = print_check(baseline, run, set, scenes.size());
  return d.worse + d.missing > 0 ? 1 : 0;
}

// --check: the baseline, read before anything runs (a bad one is bad input); every backend runs,
// as the baseline's metrics were measured (one backend's metrics can depend on the others': rbx
// check runs them all too).
Json check_baseline_first(const ReportOptions& opt) {
  if (!opt.check) return Json();
  if (!opt.backends.empty() && opt.backends != "all")
    throw InputError(
        "rbx report: --check compares every backend's metrics; drop --backends (or "
        "run rbx check --backends LIST)");
  return read_baseline(check_baseline_path(opt), false);
}

// The run's verdict in counts: scenes where a backend disagrees, and [expect] misses apart as
// undocumented (each a finding) and documented (a scene's known_failure says why).
std::string verdict_counts(const std::vector<SceneEvaluation>& evs) {
  int undocumented = 0, documented = 0, disagreeing = 0;
  for (const SceneEvaluation& ev : evs) {
    if (!ev.expect_failures.empty()) (ev.expect_known ? documented : undocumented) += 1;
    disagreeing += ev.disagreements.empty() ? 0 : 1;
  }
  return std::to_string(disagreeing) + " scenes with a disagreeing backend; [expect] missed on " +
         std::to_string(undocumented) + " undocumented, " + std::to_string(documented) +
         " documented (known_failure)";
}

// Explore's fixed random samples for the report, through every chosen backend but the oracle
// (`backends_option`: the --backends list, "" or "all" for every one), into `in`; the libraries'
// answers fill the cache at `cache_dir` that rbx check reads.
void run_report_explore(const std::string& backends_option, const std::string& cache_dir,
                        ParallelRun& par, SummaryInputs& in) {
  const std::vector<std::string> chosen = backends_option.empty() || backends_option == "all"
                                              ? std::vector<std::string>{}
                                              : parse_backend_list(backends_option);
  std::vector<std::string> contact, impact;
  for (const Backend& b : backends()) {
    if (b.name == "exact" ||
        (!chosen.empty() && std::find(chosen.begin(), chosen.end(), b.name) == chosen.end()))
      continue;
    if (b.contact) contact.push_back(b.name);
    if (b.dynamics) impact.push_back(b.name);
  }
  const ResultCache fill(cache_dir, ResultCache::code_fingerprint(), false);
  in.explore =
      explore_check_metrics(contact, impact, in.explore_set, nullptr, &par, &fill, &in.queries);
}

}  // namespace

int report_command(const ReportOptions& opt) {
  const std::vector<std::string> files = collect_scene_files(opt.inputs);
  // Every scene is read and validated before anything runs or is written.
  std::vector<Scene> scenes;
  for (const std::string& f : files) scenes.push_back(load_scene(f));
  const std::string out = opt.out.empty() ? default_repo_path("reports/latest") : opt.out;
  const Json baseline = check_baseline_first(opt);

  HarnessOptions hopt;
  hopt.backends = opt.backends;
  hopt.cache_dir = ResultCache::default_dir();  // filled for rbx check, never read: own timings
  hopt.cache_reads = false;
  hopt.timing_budget_s = opt.timing_budget_s;
  // Scenes spread over MPI ranks (under mpirun) and threads, results back in scene order on
  // rank 0 (eval/parallel.h): the report is the same for any number of ranks and threads.
  ParallelRun par(opt.threads);
  Progress progress(opt.quiet || !par.root());
  std::mutex progress_mutex;
  size_t finished = 0;
  Stopwatch clock;
  PartTimes parts;
  std::vector<SceneEvaluation> evs = evaluate_scenes(par, scenes, hopt, [&](size_t i) {
    const std::lock_guard<std::mutex> lock(progress_mutex);
    progress.show(++finished, scenes.size(), scenes[i].file, clock.seconds());
  });
  progress.done();
  parts.end("scenes");
  // The Predictability section: the nudged copies of every scene with an [ensemble] table.
  run_scene_ensembles(scenes, opt.backends, evs, par);
  parts.end("ensembles");
  // Explore's fixed random samples (the whole library, or --explore), on every rank.
  SummaryInputs in;
  if (opt.explore || opt.inputs.empty()) {
    run_report_explore(opt.backends, hopt.cache_dir, par, in);
    parts.end("explore");
  }
  if (!par.root()) return 0;  // rank 0 writes everything
  // The contact pictures draw the bodies at t = 0.
  for (size_t i = 0; i < scenes.size(); ++i)
    if (scenes[i].has_check(CheckKind::Contact)) evs[i].json["geometry"] = geometry_json(scenes[i]);

  // Everything goes into a temporary folder beside the target, renamed into place at the end.
  const fs::path target(out);
  if (target.has_parent_path()) fs::create_directories(target.parent_path());
  const fs::path tmp = target.string() + ".tmp-" + std::to_string(getpid());
  fs::remove_all(tmp);
  fs::create_directories(tmp / "figures");
  try {
    write_report_tables(tmp.string(), scenes, evs);
    if (!in.queries.empty())  // the distance and toi sections' figures are drawn from it
      write_text((tmp / "queries.json").string(),
                 query_families_json(in.queries, in.explore_set).dump(1) + "\n");
    parts.end("tables");
    std::string figures_msg;
    const bool figures_ok = draw_report_figures(tmp.string(), par.threads(), figures_msg);
    parts.end("figures");
    // --- replay pages (view-report): views/SLUG.html ---
    bool views_ok = true;
    try {
      write_report_views(tmp.string(), scenes, evs);
    } catch (const std::exception& e) {
      views_ok = false;
      std::cerr << "report: no replay pages: " << e.what() << "\n";
    }
    // --- end replay pages ---
    parts.end("views");
    // report.md is the summary (with the real tosses), details.md every table; index.html and
    // details.html are the same as pages.
    in.report_dir = tmp.string();
    in.total_s = clock.seconds();
    in.figures_ok = figures_ok;
    in.figures_msg = figures_msg;
    in.views_ok = views_ok;
    // Real impacts: every tosses data set under the inputs (comparisons/output/tosses_report.cpp).
    for (const std::string& dir : find_toss_datasets(opt.inputs))
      in.tosses += tosses_report_section(run_toss_report_study(dir, opt.backends, par.threads()),
                                         tmp.string());
    parts.end("tosses");
    const std::string summary = report_summary_markdown(scenes, evs, in);
    const std::string details = report_details_markdown(scenes, evs, tmp.string(), figures_ok,
                                                        views_ok, opt.timing_budget_s) +
                                explore_details_markdown(in.explore, in.explore_set);
    write_text((tmp / "report.md").string(), summary);
    write_text((tmp / "details.md").string(), details);
    write_report_pages(tmp.string(), scenes, evs, summary, details, views_ok);
    parts.end("pages");
    // `rbx bench` output in the old folder is kept (its own command, not this report's).
    std::error_code ec;
    for (const char* f : {"perf.md", "perf.json", "perf.csv"})
      if (fs::exists(target / f, ec)) fs::rename(target / f, tmp / f);
    if (fs::is_directory(target / "figures", ec))
      for (const auto& entry : fs::directory_iterator(target / "figures", ec))
        if (entry.path().filename().string().rfind("perf_", 0) == 0)
          fs::rename(entry.path(), tmp / "figures" / entry.path().filename());
    fs::remove_all(target);
    fs::rename(tmp, target);
  } catch (...) {
    fs::remove_all(tmp);
    throw;
  }
  std::cout << "report: " << (target / "report.md").string() << " (" << scenes.size() << " scenes, "
            << fmt_num(clock.seconds(), 3) << " s; " << verdict_counts(evs) << "; " << par.ranks()
            << " rank(s) x " << par.threads() << " thread(s))\n";
  if (!opt.quiet) std::cout << "report: time by part: " << parts.line() << "\n";
  return opt.check ? check_report_run(opt, baseline, scenes, evs, in.explore, clock) : 0;
}

}  // namespace rbx
