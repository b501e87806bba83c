// The `rbx` subcommands. Each returns the process exit code: 0 success, 1 a check failed or a
// regression was found, 2 bad input (InputError, thrown to main, which prints its one line).
#pragma once

#include <string>
#include <vector>

#include "comparisons/eval/explore_check.h"
#include "comparisons/eval/harness.h"
#include "comparisons/eval/regression_check.h"
#include "comparisons/eval/select_backends.h"
#include "comparisons/scene/scene.h"
#include "comparisons/scene/scene_collection.h"

namespace rbx {

/// The whole `rbx` command line (argv[0] is the program's name): parses, runs the subcommand,
/// prints as the executable does and returns its exit code (0, 1 a check failed, 2 bad input).
int command_line(int argc, char** argv);

/// Options shared by the scene commands.
struct SceneCommandOptions {
  std::vector<std::string> scenes;  // scene files (compare takes several)
  std::string json;                 // --json FILE|- ("" : none)
  std::vector<std::string> sets;    // --set KEY=VALUE
  std::string backends;             // --backends LIST ("" : the scene's, or every one)
  bool force = false;               // --force: accept absurd step counts
  std::string at;                   // contacts --at: "" (t = 0) | "first-contact"
  long sample_every = 0;            // run --sample-every N: the trajectory, every N steps
  double interval = 0.0;            // toi --interval S: the query's interval (0: the scene's dt)
};

/// Loads a scene applying --set and --force (InputError on bad input).
Scene load_scene_for_command(const std::string& path, const SceneCommandOptions& opt);

/// `rbx run SCENE`: the custom engine (and dynamics references named by --backends).
int run_command(const SceneCommandOptions& opt);
/// `rbx contacts SCENE`: contact queries at the t = 0 poses, every backend, side by side.
int contacts_command(const SceneCommandOptions& opt);
/// `rbx distance SCENE`: distance queries at the t = 0 poses, every backend, side by side.
int distance_command(const SceneCommandOptions& opt);
/// `rbx toi SCENE`: time-of-impact queries over an interval, every backend, side by side.
int toi_command(const SceneCommandOptions& opt);

}  // namespace rbx

namespace rbx {

/// `rbx compare SCENE...`: each scene's checks, side by side; exit 1 on a violated [expect],
/// unless every violation is the custom engine's and the scene sets expect.known_failure.
int compare_command(const SceneCommandOptions& opt);

/// Options of `rbx report` and `rbx check`.
struct ReportOptions {
  std::vector<std::string> inputs;  // scene files or folders ("" : scenes/)
  std::string out;                  // report folder (report) ("" : reports/latest)
  std::string baseline;             // baseline file (check) ("" : reports/baseline.json)
  bool update = false;              // check --update: merge this run into the baseline
  bool accept_worse = false;        // check --update --accept-worse: record worse metrics too
  bool no_cache = false;            // check --no-cache: rerun every reference library
  // check, report: also run explore's fixed random samples (always when no scene is named).
  bool explore = false;
  /// Backends to choose from (nullptr: the registry); tests pass a table with a broken engine.
  const std::vector<Backend>* registry = nullptr;
  /// check: explore's fixed sample set; tests narrow it (the sanitizer build is ~15x slower).
  ExploreCheckSet explore_samples;
  bool tosses = false;   // check: also the measured tosses (always when no scene is named)
  std::string backends;  // --backends LIST
  bool quiet = false;    // no progress line
  int threads = 0;       // report: threads per rank (0: the cores of the node, divided among ranks)
  bool check = false;    // report --check: also compare this run with the baseline (rbx check)
  /// report: each contact query and main dynamics run of the scenes timed at least this long
  /// (HarnessOptions::timing_budget_s); 0: one call each, the answers unchanged. Tests that
  /// check a report's answers, not its timings, pass 0.
  double timing_budget_s = HarnessOptions{}.timing_budget_s;
};

/// `rbx report`: accuracy report over a scene library.
int report_command(const ReportOptions& opt);
/// `rbx check`: regression check of every accuracy metric against the baseline.
int check_command(const ReportOptions& opt);
/// The baseline a check compares with: --baseline, else reports/baseline.json.
std::string check_baseline_path(const ReportOptions& opt);
/// Compares a check's run with the baseline and prints what `rbx check` prints: every changed
/// metric under its scene and backend, then the one-line verdict (`rbx check`, `rbx report
/// --check`).
CheckDiff print_check(const Json& base, const CheckRun& run, const CheckSettings& set,
                      size_t scenes);

/// The scene library as a markdown table (family, scene, description, checks, backends).
std::string scene_table_markdown(const std::vector<std::string>& inputs);
/// `rbx scenes`: prints scene_table_markdown.
int scenes_command(const std::vector<std::string>& inputs);

}  // namespace rbx

namespace rbx {

/// Options of `rbx bench`.
struct BenchOptions {
  std::string out;     // output folder ("" : reports/latest, plus reports/perf.md)
  bool quick = false;  // --quick: fewer sizes and shorter runs (under a minute)
};

/// `rbx bench`: narrow phase of every contact backend, broad phase and whole step, each group of
/// compared cases timed in turns (docs/bench.md); writes perf.md, perf.json, perf.csv and log-log
/// figures to the folder.
int bench_command(const BenchOptions& opt);

}  // namespace rbx

namespace rbx {

/// Options of `rbx explore`.
struct ExploreOptions {
  long count = 20000;            // samples
  unsigned long long seed = 1;   // sample k of seed s depends on (s, k) only
  std::string kind = "contact";  // contact | impact | landing
  std::string backends;          // --backends LIST ("" : every contact backend but exact)
  std::string out;               // output folder ("" : reports/explore)
  std::string baseline;          // --baseline FILE: exit 1 when a backend got worse
  int threads = 0;               // per rank (0: the cores of the node, divided among its ranks)
  int shrink_budget = 400;       // predicate evaluations per group
  bool bench = false;            // --bench: throughput of the sampling only, hulls under 100 points
  bool no_figure = false;        // --no-figure: skip matplotlib (tests)
  std::string shapes;            // --shapes PAIRS: contact kind, shape-class pairs kept ("" : all)
};

/// Options of `rbx ensemble`.
struct EnsembleOptions {
  SceneCommandOptions scene;         // the scene, --json, --set, --force, --backends
  long count = 50;                   // copies
  bool count_given = false;          // --count was given (else the scene's [ensemble] count)
  unsigned long long seed = 1;       // copy k of seed s depends on (s, k) only
  std::vector<std::string> perturb;  // --perturb KEY=SCALE
  bool step_test = false;            // --step-test: also every copy at dt / 10
  std::string out;  // --out DIR: ensemble.json with three nudge sizes, and the figures
  int threads = 0;  // per rank (0: the cores of the node, divided among its ranks)
};

/// `rbx ensemble SCENE`: nudged copies of the scene through every dynamics backend; per backend
/// the spread of the final states, its amplification, the contact sequences and clusters (and
/// with --step-test whether the spread is the physics' or the engine's). A scene with an
/// [ensemble] table runs as the report runs it: its count unless --count is given, its step test
/// (or --step-test), its duration. Exit 1 when a copy's run failed in some backend.
int ensemble_command(const EnsembleOptions& opt);

/// `rbx explore`: random contact pairs against the exact oracle on every core or MPI rank;
/// disagreements grouped by signature, each group shrunk to a scene; writes explore.json,
/// explore.md and scenes/*.toml. Exit 1 when --baseline finds a backend worse.
int explore_command(const ExploreOptions& opt);

}  // namespace rbx

namespace rbx {

/// Options of `rbx view`.
struct ViewOptions {
  std::string scene;     // scene file
  std::string backends;  // --backends LIST ("" : the scene's, or every one that serves it)
  std::string out;       // --out FILE ("" : FAMILY_STEM.html in the current folder)
};

/// `rbx view SCENE`: evaluates the scene (no dt study) and writes its replay page.
int view_command(const ViewOptions& opt);

}  // namespace rbx

namespace rbx {

/// Options of `rbx tosses`.
struct TossesOptions {
  std::string data;      // DATA.csv or .csv.gz
  std::string params;    // --params FILE ("" : params.json beside DATA)
  bool fit = false;      // --fit: fit every selected backend on DATA and write the params file
  std::string backends;  // --backends LIST
  std::string json;      // --json FILE|-
};
/// `rbx tosses`.
int tosses_command(const TossesOptions& opt);

}  // namespace rbx
