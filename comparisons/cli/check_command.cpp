// `rbx check`: reruns the scene library and compares every accuracy metric (names with "err")
// with the committed baseline; exit 1 on any regression. Timings never fail the check.
#include <cmath>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

#include "comparisons/cli/commands.h"
#include "comparisons/eval/harness.h"
#include "comparisons/scene/scene_file.h"
#include "comparisons/output/table.h"

namespace rbx {

namespace {

// Margins for a metric to count as worse: the same binary on the same machine reproduces every
// number exactly; these absorb the last-digit differences of another compiler or libm
// (relative 1e-9 of the value, and 1e-12 absolute for values that are round-off around zero).
constexpr double kRelativeMargin = 1e-9;
constexpr double kAbsoluteMargin = 1e-12;

std::string key_of(const std::string& scene, const Metric& m) {
  return scene + " | " + m.check + " | " + m.backend + (m.pair.empty() ? "" : " | " + m.pair) +
         " | " + m.name;
}

}  // namespace

int check_command(const ReportOptions& opt) {
  const std::string baseline_path = opt.baseline.empty() ? "reports/baseline.json" : opt.baseline;
  std::vector<Scene> scenes;
  for (const std::string& f : collect_scene_files(opt.inputs)) scenes.push_back(load_scene(f));

  // Current metrics: every error metric of every scene (no sweep: accuracy at the scene's dt).
  HarnessOptions hopt;
  hopt.backends = opt.backends;
  hopt.sweep = false;
  Stopwatch clock;
  std::map<std::string, double> now;
  for (const Scene& s : scenes)
    for (const Metric& m : evaluate_scene(s, hopt).metrics)
      if (m.name.find("err") != std::string::npos) now[key_of(scene_family(s.file) + "/" + s.name, m)] = m.value;
  const double runtime = clock.seconds();

  if (opt.update) {
    Json b;
    b["about"] = "rbx check baseline: accuracy metrics (names with err) per scene, check, backend";
    b["runtime_s"] = runtime;
    Json metrics = Json::object();
    for (const auto& [k, v] : now) metrics[k] = v;
    b["metrics"] = metrics;
    write_json(baseline_path, b);
    std::cout << "check: baseline " << baseline_path << " rewritten (" << now.size() << " metrics, "
              << fmt_num(runtime, 3) << " s)\n";
    return 0;
  }

  std::ifstream in(baseline_path);
  if (!in) throw InputError(baseline_path + ": cannot read the baseline (run rbx check --update)");
  Json base;
  try {
    in >> base;
  } catch (const std::exception& e) {
    throw InputError(baseline_path + ": not valid JSON: " + e.what());
  }
  if (!base.contains("metrics") || !base["metrics"].is_object())
    throw InputError(baseline_path + ": metrics: missing; run rbx check --update");

  int worse = 0, better = 0, missing = 0, added = 0;
  // Only scenes in this run are compared: a subset run checks its own scenes.
  std::map<std::string, bool> scene_in_run;
  for (const Scene& s : scenes) scene_in_run[scene_family(s.file) + "/" + s.name] = true;
  for (const auto& [k, v] : base["metrics"].items()) {
    const std::string scene = k.substr(0, k.find(" | "));
    if (!scene_in_run.count(scene)) continue;
    const double old = v.is_number() ? v.get<double>() : std::nan("");
    auto it = now.find(k);
    if (it == now.end()) {
      ++missing;
      std::cout << "worse: " << k << ": no longer measured (backend failed or check removed)\n";
      continue;
    }
    const double cur = it->second;
    const bool was_nan = std::isnan(old), is_nan = std::isnan(cur);
    if ((!was_nan && is_nan) || cur > old + kRelativeMargin * std::abs(old) + kAbsoluteMargin) {
      ++worse;
      // Every digit (17 significant: the double round-trips) and the relative change, so a
      // change beyond the margin never prints as two equal numbers.
      std::cout << "worse: " << k << ": " << fmt_num(old, 17) << " -> " << fmt_num(cur, 17) << " ("
                << fmt_num(old != 0 ? (cur - old) / std::abs(old) : HUGE_VAL, 3) << " relative)\n";
    } else if (cur < old - kRelativeMargin * std::abs(old) - kAbsoluteMargin) {
      ++better;
    }
  }
  for (const auto& [k, v] : now)
    if (!base["metrics"].contains(k)) ++added;
  const double base_rt = base.value("runtime_s", 0.0);
  std::cout << "check: " << now.size() << " metrics over " << scenes.size() << " scenes: " << worse + missing
            << " worse, " << better << " better, " << added << " new; run time " << fmt_num(runtime, 3)
            << " s (baseline " << fmt_num(base_rt, 3) << " s; timings never fail the check)\n";
  if (better > 0) std::cout << "check: some errors shrank; rbx check --update records them\n";
  return worse + missing > 0 ? 1 : 0;
}

}  // namespace rbx
