// `rbx check`: reruns the scene library and compares every accuracy metric (names with "err")
// with the committed baseline; exit 1 on any regression. Timings never fail the check.
// Every changed metric is named, worse and better, grouped by scene and backend; `--update`
// merges this run into the baseline and refuses while anything is worse (--accept-worse).
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

#include "comparisons/cli/commands.h"
#include "comparisons/eval/explore_check.h"
#include "comparisons/eval/harness.h"
#include "comparisons/eval/result_cache.h"
#include "comparisons/eval/select_backends.h"
#include "comparisons/output/table.h"
#include "comparisons/scene/repo_path.h"
#include "comparisons/scene/scene_file.h"

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

// The fields of a baseline key: scene | check | backend | [pair |] name.
struct KeyParts {
  std::string scene, backend, label;  // label: "check [pair] name"
};

KeyParts parse_key(const std::string& key) {
  std::vector<std::string> f;
  for (size_t at = 0;;) {
    const size_t next = key.find(" | ", at);
    f.push_back(key.substr(at, next == std::string::npos ? std::string::npos : next - at));
    if (next == std::string::npos) break;
    at = next + 3;
  }
  KeyParts p;
  p.scene = f[0];
  p.backend = f.size() > 2 ? f[2] : "";
  p.label = f.size() > 1 ? f[1] : "";
  for (size_t i = 3; i < f.size(); ++i) p.label += " " + f[i];
  return p;
}

// Unit of a metric, from its name ("" : relative or a count).
std::string unit_of(const std::string& label) {
  if (label.find("_deg") != std::string::npos) return " deg";
  if (label.find("depth_err") != std::string::npos) return " m";
  if (label.find("contact_time_err") != std::string::npos) return " s";
  if (label.find("_mps") != std::string::npos) return " m/s";
  return "";
}

// Old and new value with as few significant digits as tell them apart (at least 3), and the
// absolute change (3 digits) in the metric's unit.
std::string change_text(double old, double cur, const std::string& unit) {
  int digits = 3;
  while (digits < 17 && fmt_num(old, digits) == fmt_num(cur, digits)) ++digits;
  const double d = cur - old;
  return fmt_num(old, digits) + " -> " + fmt_num(cur, digits) + " (" + (d > 0 ? "+" : "") +
         fmt_num(d, 3) + unit + ")";
}

}  // namespace

int check_command(const ReportOptions& opt) {
  const std::string baseline_path =
      opt.baseline.empty() ? default_repo_path("reports/baseline.json") : opt.baseline;
  std::vector<Scene> scenes;
  for (const std::string& f : collect_scene_files(opt.inputs)) scenes.push_back(load_scene(f));
  // With --backends only those backends' metrics are compared (and merged by --update).
  const std::vector<Backend>& table = opt.registry ? *opt.registry : backends();
  const std::vector<std::string> only =
      opt.backends == "all" ? std::vector<std::string>{} : parse_backend_list(opt.backends, table);
  const auto selected = [&](const std::string& backend) {
    return only.empty() || std::find(only.begin(), only.end(), backend) != only.end();
  };

  // Current metrics: every error metric of every scene (no sweep: accuracy at the scene's dt).
  // Every scene runs its own backends even with --backends: which metrics a backend gets can
  // depend on the others' results (angular metrics where any backend's bodies rotate), so only
  // a whole run measures each metric as the baseline did. The references come from the cache.
  HarnessOptions hopt;
  hopt.sweep = false;
  hopt.registry = opt.registry;
  // A test's own table may name a broken copy like a library: it never reads or fills the cache.
  if (!opt.no_cache && !opt.registry) hopt.cache_dir = ResultCache::default_dir();
  Stopwatch clock;
  std::map<std::string, double> now;
  std::set<std::string> scene_in_run;
  // Known failures that no longer fail: scene name -> file.
  std::vector<std::pair<std::string, std::pair<std::string, std::string>>>
      now_passing;  // scene, (file, engine)
  int cached = 0, cacheable = 0;
  for (const Scene& s : scenes) {
    const std::string scene = scene_family(s.file) + "/" + s.name;
    scene_in_run.insert(scene);
    const SceneEvaluation ev = evaluate_scene(s, hopt);
    for (const Metric& m : ev.metrics)
      if (m.name.find("err") != std::string::npos && selected(m.backend))
        now[key_of(scene, m)] = m.value;
    for (const auto& [name, bj] : ev.json["backends"].items())
      if (ResultCache::caches(name)) {
        ++cacheable;
        cached += bj.value("cached", false) ? 1 : 0;
      }
    // A known failure of the engine it names ("custom: ..." or "custom-seed: ..."; no prefix:
    // custom) that passes now: that engine ran and bound the [expect], and none of its
    // violations is left.
    std::string subject = "custom";
    if (s.expect) {
      const std::string& known = s.expect->known_failure;
      const std::string prefix = known.substr(0, known.find(':'));
      if (prefix == "custom" || prefix == "custom-seed") subject = prefix;
    }
    const bool subject_ran =
        ev.json["backends"].contains(subject) && ev.json["backends"][subject]["status"] == "ok";
    if (s.expect && !s.expect->known_failure.empty() && subject_ran &&
        ev.json["expect"].value("checked", false) &&
        std::none_of(ev.expect_failures.begin(), ev.expect_failures.end(),
                     [&](const std::string& f) { return f.rfind(subject + ":", 0) == 0; }))
      now_passing.emplace_back(scene, std::make_pair(s.file, subject));
  }
  // Explore's fixed random samples: what no scene of the library shows (random poses, impacts
  // at a random phase). Every backend of the family (--backends narrows it), the oracle aside.
  if (opt.explore || opt.inputs.empty()) {
    std::vector<std::string> contact, impact;
    for (const Backend& b : table) {
      if (b.name == "exact" || !selected(b.name)) continue;
      if (b.contact) contact.push_back(b.name);
      if (b.dynamics) impact.push_back(b.name);
    }
    for (const ExploreCheckMetric& m :
         explore_check_metrics(contact, impact, ExploreCheckSet{}, opt.registry)) {
      scene_in_run.insert(m.scene);
      now[key_of(m.scene, m.metric)] = m.metric.value;
    }
  }
  const double runtime = clock.seconds();

  Json base = Json::object();
  std::ifstream in(baseline_path);
  if (!in && !opt.update)
    throw InputError(baseline_path + ": cannot read the baseline (run rbx check --update)");
  if (in) {
    try {
      in >> base;
    } catch (const std::exception& e) {
      throw InputError(baseline_path + ": not valid JSON: " + e.what());
    }
    if (!base.contains("metrics") || !base["metrics"].is_object())
      throw InputError(baseline_path + ": metrics: missing; run rbx check --update");
  } else {
    base["metrics"] = Json::object();
  }

  // Changes, grouped: scene -> backend -> lines. Only scenes (and backends) of this run count.
  std::map<std::string, std::map<std::string, std::vector<std::string>>> changes;
  int worse = 0, better = 0, missing = 0, added = 0;
  for (const auto& [k, v] : base["metrics"].items()) {
    const KeyParts p = parse_key(k);
    if (!scene_in_run.count(p.scene) || !selected(p.backend)) continue;
    const double old = v.is_number() ? v.get<double>() : std::nan("");
    auto it = now.find(k);
    if (it == now.end()) {
      ++missing;
      changes[p.scene][p.backend].push_back("worse   " + p.label + ": " + fmt_num(old, 3) +
                                            " -> not measured (backend failed or check removed)");
      continue;
    }
    const double cur = it->second;
    const bool was_nan = std::isnan(old), is_nan = std::isnan(cur);
    if ((!was_nan && is_nan) || cur > old + kRelativeMargin * std::abs(old) + kAbsoluteMargin) {
      ++worse;
      changes[p.scene][p.backend].push_back("worse   " + p.label + ": " +
                                            change_text(old, cur, unit_of(p.label)));
    } else if ((was_nan && !is_nan) ||
               cur < old - kRelativeMargin * std::abs(old) - kAbsoluteMargin) {
      ++better;
      changes[p.scene][p.backend].push_back("better  " + p.label + ": " +
                                            change_text(old, cur, unit_of(p.label)));
    }
  }
  for (const auto& [k, v] : now)
    if (!base["metrics"].contains(k)) ++added;
  for (const auto& [scene, by_backend] : changes) {
    std::cout << scene << "\n";
    for (const auto& [backend, lines] : by_backend) {
      std::cout << "  " << backend << "\n";
      for (const std::string& line : lines) std::cout << "    " << line << "\n";
    }
  }
  for (const auto& [scene, passing] : now_passing)
    std::cout << scene << ": " << passing.second
              << " now meets [expect], a known failure: remove known_failure from " << passing.first
              << "\n";
  const double base_rt = base.value("runtime_s", 0.0);
  std::cout << "check: " << now.size() << " metrics over " << scenes.size()
            << " scenes: " << worse + missing << " worse, " << better << " better, " << added
            << " new; run time " << fmt_num(runtime, 3) << " s (baseline " << fmt_num(base_rt, 3)
            << " s; timings never fail the check";
  if (hopt.cache_dir.size() && cacheable > 0)
    std::cout << "; " << cached << " of " << cacheable << " reference runs from the cache, "
              << ResultCache::default_dir();
  std::cout << ")\n";

  if (!opt.update) {
    if (better > 0 && worse + missing == 0)
      std::cout << "check: some errors shrank; rbx check --update records them\n";
    return worse + missing > 0 ? 1 : 0;
  }
  // --update: refused while anything is worse, unless the researcher accepts it explicitly.
  if (worse + missing > 0 && !opt.accept_worse) {
    std::cout
        << "check: --update refused: " << worse + missing
        << " metrics are worse (listed above); the baseline is unchanged. Fix them, or record "
           "them as the new truth with --update --accept-worse\n";
    return 1;
  }
  // Merge: metrics of scenes (and, with --backends, backends) not in this run stay as they were.
  Json metrics = Json::object();
  int kept = 0;
  for (const auto& [k, v] : base["metrics"].items()) {
    const KeyParts p = parse_key(k);
    if (scene_in_run.count(p.scene) && selected(p.backend)) continue;
    metrics[k] = v;
    ++kept;
  }
  for (const auto& [k, v] : now) metrics[k] = v;
  Json b;
  b["about"] = "rbx check baseline: accuracy metrics (names with err) per scene, check, backend";
  // The run time is that of a whole-library run; a partial update keeps the recorded one.
  const bool whole = opt.inputs.empty() && only.empty();
  b["runtime_s"] = whole || !base.contains("runtime_s") ? runtime : base_rt;
  b["metrics"] = metrics;
  write_json(baseline_path, b);
  std::cout << "check: baseline " << baseline_path << " updated: " << now.size()
            << " metrics from this run, " << kept << " kept from scenes or backends not run ("
            << metrics.size() << " in all)\n";
  return 0;
}

}  // namespace rbx
