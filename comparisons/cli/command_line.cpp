// The `rbx` command line: parses arguments, dispatches to a subcommand, maps failures to exit
// codes (0 success, 1 a check failed, 2 bad input or usage, with one line on stderr). The `rbx`
// executable (main.cpp) and the Python module (python/rbx_module.cpp) both run it.
#include <CLI/CLI.hpp>
#include <cmath>
#include <exception>
#include <filesystem>
#include <iostream>

#include "comparisons/cli/commands.h"
#include "comparisons/scene/scene_file.h"
#include "engine/polyhedron.h"

namespace {

// Adds the options every scene command shares.
void scene_options(CLI::App* cmd, rbx::SceneCommandOptions& o, bool many, bool backends) {
  if (many)
    cmd->add_option("scene", o.scenes, "scene files (TOML)")->required();
  else
    cmd->add_option("scene", o.scenes, "scene file (TOML)")->required()->expected(1);
  cmd->add_option("--json", o.json, "write JSON results to FILE, or - for standard output");
  cmd->add_option("--set", o.sets, "override a scene key, TOML-typed: KEY=VALUE (repeatable)");
  cmd->add_flag("--force", o.force, "accept runs of more than 1e8 steps (at most 2^53)");
  if (backends) cmd->add_option("--backends", o.backends, "comma-separated backend names");
}

// Every command's options, filled by the parser.
struct Options {
  rbx::SceneCommandOptions run, contacts, distance, toi, compare;
  rbx::ReportOptions report, check;
  std::vector<std::string> scenes_inputs;
  rbx::BenchOptions bench;
  rbx::TossesOptions tosses;
  rbx::ViewOptions view;
  rbx::ExploreOptions explore;
  rbx::EnsembleOptions ensemble;
};

// A count of at least 1, said in a few words (CLI11's PositiveNumber writes out its range up to
// the largest double in full).
const CLI::Validator kAtLeastOne(
    [](std::string& text) -> std::string {
      size_t used = 0;
      long value = 0;
      try {
        value = std::stol(text, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used == text.size() && value >= 1) return "";
      return "must be a whole number >= 1, got '" + text + "'";
    },
    "N >= 1");

// A finite number of seconds, above zero (or at least zero where zero has a meaning).
CLI::Validator seconds_at_least(bool zero_allowed) {
  return CLI::Validator(
      [zero_allowed](std::string& text) -> std::string {
        size_t used = 0;
        double value = 0;
        try {
          value = std::stod(text, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used == text.size() && std::isfinite(value) &&
            (value > 0 || (zero_allowed && value == 0)))
          return "";
        return std::string(zero_allowed ? "must be a number of seconds >= 0"
                                        : "must be a positive number of seconds") +
               ", got '" + text + "'";
      },
      zero_allowed ? "S >= 0" : "S > 0");
}
const CLI::Validator kPositiveSeconds = seconds_at_least(false);

// run, contacts, distance, toi, compare: the commands on scene files.
void add_scene_commands(CLI::App& app, Options& o) {
  CLI::App* run = app.add_subcommand("run", "custom engine only: collision events and final state");
  scene_options(run, o.run, false, true);
  run->add_option("--sample-every", o.run.sample_every,
                  "with --json: each backend's trajectory, every N steps")
      ->check(kAtLeastOne);
  CLI::App* contacts =
      app.add_subcommand("contacts", "contact query at the t=0 poses, every backend");
  scene_options(contacts, o.contacts, false, true);
  contacts
      ->add_option("--at", o.contacts.at,
                   "first-contact: query at the first step where a pair touches (the custom "
                   "engine's motion, the exact oracle's test)")
      ->check(CLI::IsMember({"first-contact"}));
  scene_options(app.add_subcommand("distance", "distance query at the t=0 poses, every backend"),
                o.distance, false, true);
  CLI::App* toi = app.add_subcommand(
      "toi", "time of impact: each body at its velocities from its t=0 pose, every backend");
  scene_options(toi, o.toi, false, true);
  toi->add_option("--interval", o.toi.interval, "the interval in seconds (default: the scene's dt)")
      ->check(kPositiveSeconds);
  scene_options(app.add_subcommand("compare", "the scenes' checks, side by side"), o.compare, true,
                true);
}

// report, scenes, check, bench: the commands over a scene library.
void add_library_commands(CLI::App& app, Options& o) {
  CLI::App* report =
      app.add_subcommand("report", "accuracy report (default: scenes/ -> reports/latest)");
  report->add_option("inputs", o.report.inputs, "scene files or folders");
  report->add_option("--out", o.report.out, "output folder");
  report->add_option("--backends", o.report.backends, "comma-separated backend names");
  report->add_option("--threads", o.report.threads, "threads per rank (default: every core)");
  report->add_flag("--check", o.report.check,
                   "also compare this report's runs with reports/baseline.json as rbx check "
                   "does (every backend); exit 1 when a metric is worse");
  report->add_option("--baseline", o.report.baseline, "with --check: the baseline file");
  report
      ->add_option("--timing-budget", o.report.timing_budget_s,
                   "seconds each contact query and main dynamics run is timed for, at least "
                   "(default 0.01); 0: one call each, the answers only")
      ->check(seconds_at_least(true));
  report->add_flag("--explore", o.report.explore,
                   "also summarise explore's fixed random samples (contact and impact kinds, seed "
                   "1): the default when no scene is named");
  app.add_subcommand("scenes", "the scene library as a markdown table (scenes/README.md)")
      ->add_option("inputs", o.scenes_inputs, "scene files or folders (default: scenes/)");
  CLI::App* check = app.add_subcommand("check", "regression check against reports/baseline.json");
  check->add_option("inputs", o.check.inputs, "scene files or folders (default: scenes/)");
  check->add_option("--baseline", o.check.baseline, "baseline file");
  check->add_option("--backends", o.check.backends,
                    "comma-separated backend names: only their metrics are compared (and updated)");
  CLI::Option* update = check->add_flag("--update", o.check.update,
                                        "merge this run into the baseline (scenes and backends not "
                                        "run stay); refused while anything is worse");
  check->add_flag("--accept-worse", o.check.accept_worse, "with --update: record worse metrics too")
      ->needs(update);
  check->add_flag("--explore", o.check.explore,
                  "also run explore's fixed random samples (contact and impact kinds, seed 1): "
                  "the default when no scene is named");
  check->add_flag("--no-cache", o.check.no_cache, "rerun every reference library (no build/cache)");
  check->add_option("--threads", o.check.threads,
                    "threads the scenes spread over (default: every core)");
  CLI::App* bench = app.add_subcommand(
      "bench", "performance comparison (default: reports/latest, and reports/perf.md)");
  bench->add_option("--out", o.bench.out, "output folder");
  bench->add_flag("--quick", o.bench.quick, "fewer sizes and shorter runs (under a minute)");
}

// tosses, view, explore, ensemble.
void add_study_commands(CLI::App& app, Options& o) {
  CLI::App* tosses =
      app.add_subcommand("tosses", "every dynamics backend against measured cube tosses");
  tosses->add_option("data", o.tosses.data, "tosses CSV (.csv or .csv.gz)")->required();
  tosses->add_option("--params", o.tosses.params,
                     "parameter file (default: params.json beside DATA)");
  tosses->add_flag("--fit", o.tosses.fit,
                   "fit restitution and friction per backend on DATA, write the parameter file");
  tosses->add_option("--backends", o.tosses.backends, "comma-separated backend names");
  tosses->add_option("--json", o.tosses.json,
                     "write JSON results to FILE, or - for standard output");
  CLI::App* view = app.add_subcommand("view", "one offline HTML page: 3-D replay of every backend");
  view->add_option("scene", o.view.scene, "scene file (TOML)")->required();
  view->add_option("--backends", o.view.backends, "comma-separated backend names");
  view->add_option("--out", o.view.out, "output HTML file (default: FAMILY_STEM.html)");
  CLI::App* explore = app.add_subcommand(
      "explore", "random contact pairs against the exact oracle; disagreements shrunk to scenes");
  explore->add_option("--count", o.explore.count, "number of samples (default 20000)");
  explore->add_option("--seed", o.explore.seed, "seed (default 1)");
  explore->add_option("--kind", o.explore.kind,
                      "contact | distance | impact | landing | slide | tunnel | toi");
  explore->add_option("--backends", o.explore.backends, "comma-separated backend names");
  explore->add_option("--shapes", o.explore.shapes,
                      "contact kind: only these shape-class pairs, e.g. box-box,box-hull (classes "
                      "box, hull, sliver; other samples are left out, not redrawn)");
  explore->add_option("--out", o.explore.out, "output folder (default reports/explore)");
  explore->add_option("--baseline", o.explore.baseline,
                      "stored explore.json: exit 1 when a backend got worse");
  explore->add_option("--threads", o.explore.threads, "threads per rank (default: every core)");
  explore->add_option("--shrink-budget", o.explore.shrink_budget,
                      "evaluations per group while shrinking");
  explore->add_flag("--bench", o.explore.bench, "time the sampling only (hulls under 100 points)");
  explore->add_flag("--no-figure", o.explore.no_figure, "skip the matplotlib figure");
  CLI::App* ensemble = app.add_subcommand(
      "ensemble",
      "nudged copies of a scene through every dynamics backend: how far outcomes spread");
  scene_options(ensemble, o.ensemble.scene, false, true);
  ensemble->add_option("--count", o.ensemble.count,
                       "number of copies (default: the scene's [ensemble] count, else 50)");
  ensemble->add_option("--seed", o.ensemble.seed, "seed (default 1)");
  ensemble->add_option("--perturb", o.ensemble.perturb,
                       "nudge scale KEY=SCALE, KEY: position (m), orientation (rad), velocity "
                       "(m/s), angular_velocity (rad/s); default 1e-6 each (repeatable)");
  ensemble->add_flag("--step-test", o.ensemble.step_test,
                     "also run every copy at dt/10: a spread that stays is the physics', one "
                     "that shrinks the engine's (also when the scene's [ensemble] asks for it)");
  ensemble->add_option("--out", o.ensemble.out,
                       "folder: ensemble.json with the spread at a tenth and ten times the "
                       "nudges too, and the figures");
  ensemble->add_option("--threads", o.ensemble.threads, "threads per rank (default: every core)");
}

// An unknown command is named as such (CLI11 would say only that a subcommand is required).
bool unknown_command(CLI::App& app, int argc, char** argv) {
  if (argc <= 1 || argv[1][0] == '-') return false;
  std::string names;
  bool known = false;
  for (const CLI::App* sub : app.get_subcommands({})) {
    names += (names.empty() ? "" : ", ") + sub->get_name();
    known = known || sub->get_name() == argv[1];
  }
  if (known) return false;
  std::cerr << "rbx: unknown command '" << argv[1] << "'; commands: " << names
            << " (see rbx --help)\n";
  return true;
}

// Usage that would quietly mean something else is refused before any work: an empty
// --backends (it would run the defaults) and a --json file in a folder that does not exist
// (it would fail only after the whole run).
bool refused_usage(CLI::App& app) {
  for (const CLI::App* sub : app.get_subcommands()) {
    for (const CLI::Option* o : sub->get_options()) {
      if (o->count() == 0) continue;
      const std::string value = o->as<std::string>();
      if (o->get_name() == "--backends" && value.find_first_not_of(", ") == std::string::npos) {
        std::cerr << "rbx " << sub->get_name()
                  << ": --backends: the list is empty; name backends (e.g. custom,fcl) or all\n";
        return true;
      }
      if (o->get_name() == "--json" && value != "-") {
        const std::filesystem::path folder = std::filesystem::path(value).parent_path();
        if (!folder.empty() && !std::filesystem::is_directory(folder)) {
          std::cerr << "rbx " << sub->get_name() << ": --json: folder '" << folder.string()
                    << "' does not exist\n";
          return true;
        }
      }
    }
  }

  return false;
}

// The chosen command; its failures as exit code 2 with one line on stderr.
int dispatch(CLI::App& app, const Options& o) {
  try {
    if (app.got_subcommand("run")) return rbx::run_command(o.run);
    if (app.got_subcommand("contacts")) return rbx::contacts_command(o.contacts);
    if (app.got_subcommand("distance")) return rbx::distance_command(o.distance);
    if (app.got_subcommand("toi")) return rbx::toi_command(o.toi);
    if (app.got_subcommand("compare")) return rbx::compare_command(o.compare);
    if (app.got_subcommand("report")) return rbx::report_command(o.report);
    if (app.got_subcommand("check")) return rbx::check_command(o.check);
    if (app.got_subcommand("scenes")) return rbx::scenes_command(o.scenes_inputs);
    if (app.got_subcommand("bench")) return rbx::bench_command(o.bench);
    if (app.got_subcommand("tosses")) return rbx::tosses_command(o.tosses);
    if (app.got_subcommand("view")) return rbx::view_command(o.view);
    if (app.got_subcommand("explore")) return rbx::explore_command(o.explore);
    if (app.got_subcommand("ensemble")) {
      rbx::EnsembleOptions e = o.ensemble;
      e.count_given = app.get_subcommand("ensemble")->count("--count") > 0;
      return rbx::ensemble_command(e);
    }
  } catch (const rbx::InputError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  } catch (const rbx::GeometryError& e) {
    std::cerr << "rbx: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "rbx: error: " << e.what() << "\n";
    return 2;
  }
  return 2;
}

}  // namespace

int rbx::command_line(int argc, char** argv) {
  // Named, so that usage lines say `rbx`, not the path the binary was started from.
  CLI::App app{"rbx: rigid-body collision detection and response testbed", "rbx"};
  app.require_subcommand(1);
  Options o;
  add_scene_commands(app, o);
  add_library_commands(app, o);
  add_study_commands(app, o);
  if (unknown_command(app, argc, argv)) return 2;
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "rbx: " << e.what() << " (see rbx --help)\n";
    return 2;
  }
  if (refused_usage(app)) return 2;
  return dispatch(app, o);
}
