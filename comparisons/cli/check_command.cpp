// `rbx check`: reruns the scene library and compares every accuracy metric (names with "err")
// with the committed baseline; exit 1 on any regression. Timings never fail the check.
// Every changed metric is named, worse and better, grouped by scene and backend; `--update`
// merges this run into the baseline and refuses while anything is worse (--accept-worse).
#include <iostream>

#include "comparisons/cli/commands.h"
#include "comparisons/eval/regression_check.h"
#include "comparisons/eval/select_backends.h"
#include "comparisons/scene/repo_path.h"
#include "comparisons/scene/scene_file.h"
#include "engine/format.h"

namespace rbx {

namespace {

// The changes, grouped by scene and backend, and the known failures that pass now.
void print_changes(const CheckDiff& d, const CheckRun& run) {
  for (const auto& [scene, by_backend] : d.changes) {
    std::cout << scene << "\n";
    for (const auto& [backend, lines] : by_backend) {
      std::cout << "  " << backend << "\n";
      for (const std::string& line : lines) std::cout << "    " << line << "\n";
    }
  }
  for (const NowPassing& p : run.now_passing)
    std::cout << p.scene << ": " << p.engine
              << " now meets [expect], a known failure: remove known_failure from " << p.file
              << "\n";
}

}  // namespace

std::string check_baseline_path(const ReportOptions& opt) {
  return opt.baseline.empty() ? default_repo_path("reports/baseline.json") : opt.baseline;
}

CheckDiff print_check(const Json& base, const CheckRun& run, const CheckSettings& set,
                      size_t scenes) {
  const CheckDiff d = diff_check(base, run, set);
  print_changes(d, run);
  const double base_rt = base.value("runtime_s", 0.0);
  std::cout << "check: " << run.now.size() << " metrics over " << scenes
            << " scenes: " << d.worse + d.missing << " worse, " << d.better << " better, "
            << d.added << " new; run time " << fmt_num(run.runtime_s, 3) << " s (scenes "
            << fmt_num(run.scenes_s, 3) << " s, explore " << fmt_num(run.explore_s, 3)
            << " s, tosses " << fmt_num(run.tosses_s, 3) << " s; baseline " << fmt_num(base_rt, 3)
            << " s; timings never fail the check";
  if (!run.cache_dir.empty() && run.cacheable > 0)
    std::cout << "; " << run.cached << " of " << run.cacheable << " reference runs from the cache, "
              << run.cache_dir;
  std::cout << ")\n";
  if (d.better > 0 && d.worse + d.missing == 0)
    std::cout << "check: some errors shrank; rbx check --update records them\n";
  return d;
}

int check_command(const ReportOptions& opt) {
  const std::string baseline_path = check_baseline_path(opt);
  std::vector<Scene> scenes;
  for (const std::string& f : collect_scene_files(opt.inputs)) scenes.push_back(load_scene(f));
  // With --backends only those backends' metrics are compared (and merged by --update).
  CheckSettings set;
  const std::vector<Backend>& table = opt.registry ? *opt.registry : backends();
  if (opt.backends != "all") set.only = parse_backend_list(opt.backends, table);
  set.explore = opt.explore || opt.inputs.empty();
  set.explore_samples = opt.explore_samples;
  // The measured tosses when the whole library is checked.
  set.tosses = opt.tosses || opt.inputs.empty();
  set.use_cache = !opt.no_cache;
  set.threads = opt.threads;
  set.registry = opt.registry;

  const CheckRun run = measure_check(scenes, set);
  const Json base = read_baseline(baseline_path, opt.update);
  const CheckDiff d = print_check(base, run, set, scenes.size());
  const int worse = d.worse + d.missing;
  if (!opt.update) return worse > 0 ? 1 : 0;
  // --update: refused while anything is worse, unless the researcher accepts it explicitly.
  if (worse > 0 && !opt.accept_worse) {
    std::cout
        << "check: --update refused: " << worse
        << " metrics are worse (listed above); the baseline is unchanged. Fix them, or record "
           "them as the new truth with --update --accept-worse\n";
    return 1;
  }
  int kept = 0;
  const Json b = merged_baseline(base, run, set, opt.inputs.empty() && set.only.empty(), kept);
  write_json(baseline_path, b);
  std::cout << "check: baseline " << baseline_path << " updated: " << run.now.size()
            << " metrics from this run, " << kept << " kept from scenes or backends not run ("
            << b["metrics"].size() << " in all)\n";
  return 0;
}

}  // namespace rbx
