// `rbx check`: every accuracy metric (names with "err") of a scene library, and of explore's
// fixed random samples, measured and compared with the committed baseline.
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

#include "comparisons/eval/explore_check.h"
#include "comparisons/eval/harness.h"
#include "comparisons/eval/json_io.h"
#include "comparisons/scene/scene.h"

namespace rbx {

/// What a check measures.
struct CheckSettings {
  std::vector<std::string> only;    // backends compared (and merged); empty: every one
  bool explore = false;             // also explore's fixed random samples
  ExploreCheckSet explore_samples;  // which samples (the baseline's set unless a test narrows it)
  bool tosses = false;              // also the measured cube tosses' test split (scenes/)
  bool use_cache = true;            // reference results from the cache
  int threads = 0;                  // threads the scenes spread over (0: every core)
  /// Backends to choose from (nullptr: the registry); tests pass a table with a broken engine.
  const std::vector<Backend>* registry = nullptr;
  /// True when `backend`'s metrics are compared.
  bool selected(const std::string& backend) const;
};

/// A scene whose known failure no longer fails.
struct NowPassing {
  std::string scene, file, engine;
};

/// The metrics of this run.
struct CheckRun {
  std::map<std::string, double> now;  // "scene | check | backend | [pair |] name" -> value
  std::set<std::string> scene_in_run;
  std::vector<NowPassing> now_passing;
  int cached = 0, cacheable = 0;  // reference runs read from the cache, of those cacheable
  std::string cache_dir;          // "" : no cache
  double runtime_s = 0.0;
  double scenes_s = 0.0, explore_s = 0.0, tosses_s = 0.0;  // the parts of runtime_s
};

/// Runs every scene (and, with `set.explore`, explore's fixed samples; with `set.tosses`, the
/// measured tosses).
CheckRun measure_check(const std::vector<Scene>& scenes, const CheckSettings& set);

/// The parts of a check, for a run whose scenes (or samples) were evaluated elsewhere (`rbx
/// report --check` compares its own runs): every error metric of the scenes' evaluations (and
/// the known failures that pass now), explore's fixed-sample metrics, and the measured tosses
/// (run here: the report's toss tables keep no per-toss errors).
void add_scene_metrics(const std::vector<Scene>& scenes, const std::vector<SceneEvaluation>& evs,
                       const CheckSettings& set, CheckRun& run);
void add_explore_metrics(const std::vector<ExploreCheckMetric>& metrics, const CheckSettings& set,
                         CheckRun& run);
void add_toss_metrics(const CheckSettings& set, CheckRun& run);

/// The baseline file (InputError when unreadable or malformed; an absent one is an empty
/// baseline when `may_be_absent`).
Json read_baseline(const std::string& path, bool may_be_absent);

/// What moved against the baseline, grouped scene -> backend -> lines ("worse   ..." /
/// "better  ..."); a baseline metric this run did not measure is `missing`.
struct CheckDiff {
  std::map<std::string, std::map<std::string, std::vector<std::string>>> changes;
  int worse = 0, better = 0, missing = 0, added = 0;
};
CheckDiff diff_check(const Json& base, const CheckRun& run, const CheckSettings& set);

/// The baseline with this run merged in (metrics of scenes and backends not run kept; `kept`
/// counts them). `whole`: a whole-library run, whose run time is recorded.
Json merged_baseline(const Json& base, const CheckRun& run, const CheckSettings& set, bool whole,
                     int& kept);

}  // namespace rbx
