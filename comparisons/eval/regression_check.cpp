// `rbx check`'s measuring and comparing: reruns the scene library and compares every accuracy
// metric (names with "err") with the committed baseline; exit 1 on any regression. Timings never
// fail the check. Every changed metric is named, worse and better, grouped by scene and backend;
// `--update` merges this run into the baseline and refuses while anything is worse
// (--accept-worse).
#include "comparisons/eval/regression_check.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <map>
#include <sstream>

#include "comparisons/eval/explore_check.h"
#include "comparisons/eval/parallel.h"
#include "comparisons/eval/result_cache.h"
#include "comparisons/eval/scene_batch.h"
#include "comparisons/eval/select_backends.h"
#include "comparisons/eval/tosses.h"
#include "comparisons/scene/scene_file.h"
#include "engine/format.h"

namespace rbx {

namespace fs = std::filesystem;

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

// The engine a scene's known failure names ("custom: ..." or "custom-seed: ...", as the loader
// stores it), when that engine ran, bound the [expect] and has no violation left: it passes now.
bool known_failure_passes(const Scene& s, const SceneEvaluation& ev, std::string& subject) {
  subject = "custom";
  if (!s.expect || s.expect->known_failure.empty()) return false;
  const std::string& known = s.expect->known_failure;
  const std::string prefix = known.substr(0, known.find(':'));
  if (prefix == "custom" || prefix == "custom-seed") subject = prefix;
  const bool subject_ran =
      ev.json["backends"].contains(subject) && ev.json["backends"][subject]["status"] == "ok";
  return subject_ran && ev.json["expect"].value("checked", false) &&
         std::none_of(ev.expect_failures.begin(), ev.expect_failures.end(),
                      [&](const std::string& f) { return f.rfind(subject + ":", 0) == 0; });
}

// Explore's fixed random samples: what no scene of the library shows (random poses, impacts at
// a random phase). Every backend of the family (`selected` narrows it), the oracle aside.
void measure_explore(const CheckSettings& set, const ParallelRun& par, CheckRun& run) {
  const std::vector<Backend>& table = set.registry ? *set.registry : backends();
  std::vector<std::string> contact, impact;
  for (const Backend& b : table) {
    if (b.name == "exact" || !set.selected(b.name)) continue;
    if (b.contact) contact.push_back(b.name);
    if (b.dynamics) impact.push_back(b.name);
  }
  const ResultCache cache(run.cache_dir);  // "" (no cache): disabled
  add_explore_metrics(
      explore_check_metrics(contact, impact, set.explore_samples, set.registry, &par, &cache), set,
      run);
}

}  // namespace

// The measured cube tosses' test split of every data set under scenes/: per dynamics backend at
// its stored (fitted) parameters, as the report's first toss table, the median and 90th
// percentile of the position error per toss and the median angle error, under the pseudo-scene
// "tosses/FOLDER". The simulations are deterministic, so the metrics are exact repeats.
void add_toss_metrics(const CheckSettings& set, CheckRun& run) {
  const std::vector<Backend>& table = set.registry ? *set.registry : backends();
  const ResultCache cache(run.cache_dir);  // "" (no cache): disabled
  for (const std::string& dir : find_toss_datasets({})) {
    const std::string split = toss_test_split(dir);
    const std::vector<Toss> all = read_tosses(split);
    const std::vector<Toss> tosses = without_energy_gains(all, energy_gains(all));
    const auto stored = read_params_file((fs::path(dir) / "params.json").string());
    const std::string scene = "tosses/" + fs::path(dir).filename().string();
    run.scene_in_run.insert(scene);
    std::ifstream data(split, std::ios::binary);
    std::ostringstream bytes;
    bytes << data.rdbuf();
    const std::string data_id = std::to_string(std::hash<std::string>{}(bytes.str()));
    // Each backend's errors per toss: position errors, then angle errors; empty when it failed.
    struct Job {
      const Backend* backend;
      ContactParams params;
      std::string key;
      std::vector<double> both;
    };
    std::vector<Job> jobs;
    for (const Backend& b : table) {
      if (!b.dynamics || !set.selected(b.name)) continue;
      Job job{&b, stored_params(stored, b.name), "", {}};
      // A library's errors per toss come from the cache (keyed by its code, the data's bytes
      // and the parameters; the toss code is in the derived hash); an engine's always run.
      if (cache.enabled() && ResultCache::caches(b.name)) {
        std::ostringstream k;
        k << std::setprecision(17) << ResultCache::code_fingerprint() << "; tosses " << b.name
          << " " << data_id << " e " << job.params.restitution << " mu " << job.params.friction;
        for (const auto& [name, value] : job.params.soft) k << " " << name << " " << value;
        job.key = k.str();
      }
      jobs.push_back(std::move(job));
    }
    // The backends that run (the engines, a library not cached), each cut into as many pieces
    // of the tosses as there are threads, the pieces side by side: two engines of unequal cost
    // no longer leave a core idle while the slower finishes.
    struct Piece {
      size_t job, lo, hi;
      bool ok = false;
      std::vector<double> position, angle;
    };
    std::vector<Piece> pieces;
    const size_t cuts = static_cast<size_t>(std::max(1, forking_threads(set.threads)));
    for (size_t i = 0; i < jobs.size(); ++i) {
      Job& job = jobs[i];
      if (auto hit = job.key.empty() ? std::nullopt : cache.load_derived(job.key, "toss errors")) {
        job.both = *hit;
        continue;
      }
      for (size_t c = 0; c < cuts; ++c)
        pieces.push_back(
            {i, tosses.size() * c / cuts, tosses.size() * (c + 1) / cuts, false, {}, {}});
    }
    run_jobs(pieces.size(), set.threads, [&](size_t k) {
      Piece& piece = pieces[k];
      const std::vector<Toss> some(tosses.begin() + static_cast<long>(piece.lo),
                                   tosses.begin() + static_cast<long>(piece.hi));
      const BackendTosses r =
          evaluate_backend(*jobs[piece.job].backend, some, jobs[piece.job].params);
      if (r.status != Status::Ok) return;  // a failed toss: its metrics go missing (worse)
      piece.ok = true;
      for (const TossErrors& e : r.tosses) {
        piece.position.push_back(e.position);
        piece.angle.push_back(e.orientation_deg);
      }
    });
    for (size_t i = 0; i < jobs.size(); ++i) {
      std::vector<double> position, angle;
      bool ran = false, ok = true;
      for (const Piece& piece : pieces) {
        if (piece.job != i) continue;
        ran = true;
        ok = ok && piece.ok;
        position.insert(position.end(), piece.position.begin(), piece.position.end());
        angle.insert(angle.end(), piece.angle.begin(), piece.angle.end());
      }
      if (!ran || !ok) continue;
      jobs[i].both = position;
      jobs[i].both.insert(jobs[i].both.end(), angle.begin(), angle.end());
      if (!jobs[i].key.empty()) cache.store_derived(jobs[i].key, "toss errors", jobs[i].both);
    }
    for (const Job& job : jobs) {
      if (job.both.empty()) continue;
      const auto half = job.both.begin() + static_cast<long>(job.both.size() / 2);
      const Spread p = spread_of({job.both.begin(), half}), a = spread_of({half, job.both.end()});
      for (const auto& [name, value] :
           {std::pair{"position_err_p50", p.median}, std::pair{"position_err_p90", p.p90},
            std::pair{"angle_err_deg_p50", a.median}})
        run.now[key_of(scene, {"tosses", job.backend->name, "", name, value, "measured"})] = value;
    }
  }
}

void add_scene_metrics(const std::vector<Scene>& scenes, const std::vector<SceneEvaluation>& evs,
                       const CheckSettings& set, CheckRun& run) {
  for (size_t i = 0; i < scenes.size() && i < evs.size(); ++i) {
    const Scene& s = scenes[i];
    const SceneEvaluation& ev = evs[i];
    const std::string scene = scene_family(s.file) + "/" + s.name;
    run.scene_in_run.insert(scene);
    for (const Metric& m : ev.metrics)
      if (m.name.find("err") != std::string::npos && set.selected(m.backend))
        run.now[key_of(scene, m)] = m.value;
    for (const auto& [name, bj] : ev.json["backends"].items())
      if (ResultCache::caches(name)) {
        ++run.cacheable;
        run.cached += bj.value("cached", false) ? 1 : 0;
      }
    std::string subject;
    if (known_failure_passes(s, ev, subject)) run.now_passing.push_back({scene, s.file, subject});
  }
}

void add_explore_metrics(const std::vector<ExploreCheckMetric>& metrics, const CheckSettings& set,
                         CheckRun& run) {
  for (const ExploreCheckMetric& m : metrics) {
    if (!set.selected(m.metric.backend)) continue;
    run.scene_in_run.insert(m.scene);
    run.now[key_of(m.scene, m.metric)] = m.metric.value;
  }
}

bool CheckSettings::selected(const std::string& backend) const {
  return only.empty() || std::find(only.begin(), only.end(), backend) != only.end();
}

CheckRun measure_check(const std::vector<Scene>& scenes, const CheckSettings& set) {
  // Every error metric of every scene (no dt study: accuracy at the scene's dt). Every scene runs
  // its own backends even with --backends: which metrics a backend gets can depend on the
  // others' results (angular metrics where any backend's bodies rotate), so only a whole run
  // measures each metric as the baseline did. The references come from the cache.
  CheckRun run;
  HarnessOptions hopt;
  hopt.studies = false;
  hopt.timing_budget_s = 0.0;  // timings never fail the check: the answers only
  hopt.registry = set.registry;
  // A test's own table may name a broken copy like a library: it never reads or fills the cache.
  if (set.use_cache && !set.registry) run.cache_dir = hopt.cache_dir = ResultCache::default_dir();
  Stopwatch clock;
  // Scenes spread over threads as the report spreads them; the evaluations come back in scene
  // order, so the run is the same for any number of threads.
  ParallelRun par(set.threads);
  const std::vector<SceneEvaluation> evs = evaluate_scenes(par, scenes, hopt, [](size_t) {});
  add_scene_metrics(scenes, evs, set, run);
  run.scenes_s = clock.seconds();
  if (set.explore) measure_explore(set, par, run);
  run.explore_s = clock.seconds() - run.scenes_s;
  if (set.tosses) add_toss_metrics(set, run);
  run.runtime_s = clock.seconds();
  run.tosses_s = run.runtime_s - run.scenes_s - run.explore_s;
  return run;
}

Json read_baseline(const std::string& path, bool may_be_absent) {
  Json base = Json::object();
  std::ifstream in(path);
  if (!in && !may_be_absent)
    throw InputError(path + ": cannot read the baseline (run rbx check --update)");
  if (!in) {
    base["metrics"] = Json::object();
    return base;
  }
  try {
    in >> base;
  } catch (const std::exception& e) {
    throw InputError(path + ": not valid JSON: " + e.what());
  }
  if (!base.contains("metrics") || !base["metrics"].is_object())
    throw InputError(path + ": metrics: missing; run rbx check --update");
  return base;
}

CheckDiff diff_check(const Json& base, const CheckRun& run, const CheckSettings& set) {
  // Only scenes (and backends) of this run count.
  CheckDiff d;
  for (const auto& [k, v] : base["metrics"].items()) {
    const KeyParts p = parse_key(k);
    if (!run.scene_in_run.count(p.scene) || !set.selected(p.backend)) continue;
    const double old = v.is_number() ? v.get<double>() : std::nan("");
    auto it = run.now.find(k);
    if (it == run.now.end()) {
      ++d.missing;
      d.changes[p.scene][p.backend].push_back("worse   " + p.label + ": " + fmt_num(old, 3) +
                                              " -> not measured (backend failed or check removed)");
      continue;
    }
    const double cur = it->second;
    const bool was_nan = std::isnan(old), is_nan = std::isnan(cur);
    if ((!was_nan && is_nan) || cur > old + kRelativeMargin * std::abs(old) + kAbsoluteMargin) {
      ++d.worse;
      d.changes[p.scene][p.backend].push_back("worse   " + p.label + ": " +
                                              change_text(old, cur, unit_of(p.label)));
    } else if ((was_nan && !is_nan) ||
               cur < old - kRelativeMargin * std::abs(old) - kAbsoluteMargin) {
      ++d.better;
      d.changes[p.scene][p.backend].push_back("better  " + p.label + ": " +
                                              change_text(old, cur, unit_of(p.label)));
    }
  }
  for (const auto& [k, v] : run.now)
    if (!base["metrics"].contains(k)) ++d.added;
  return d;
}

Json merged_baseline(const Json& base, const CheckRun& run, const CheckSettings& set, bool whole,
                     int& kept) {
  // Metrics of scenes (and, with --backends, backends) not in this run stay as they were; all
  // in key order, so that a partial update changes only the lines of the metrics it changed.
  std::map<std::string, Json> sorted;
  kept = 0;
  for (const auto& [k, v] : base["metrics"].items()) {
    const KeyParts p = parse_key(k);
    if (run.scene_in_run.count(p.scene) && set.selected(p.backend)) continue;
    sorted[k] = v;
    ++kept;
  }
  for (const auto& [k, v] : run.now) sorted[k] = v;
  Json metrics = Json::object();
  for (const auto& [k, v] : sorted) metrics[k] = v;
  Json b;
  b["about"] = "rbx check baseline: accuracy metrics (names with err) per scene, check, backend";
  // The run time is that of a whole-library run; a partial update keeps the recorded one.
  b["runtime_s"] =
      whole || !base.contains("runtime_s") ? run.runtime_s : base.value("runtime_s", 0.0);
  b["metrics"] = metrics;
  return b;
}

}  // namespace rbx
