// The `rbx` command: parses arguments, dispatches to a subcommand, maps failures to exit codes
// (0 success, 1 a check failed, 2 bad input or usage, with one line on stderr).
#include <CLI/CLI.hpp>
#include <exception>
#include <filesystem>
#include <iostream>

#include "comparisons/cli/commands.h"
#include "comparisons/cli/view.h"
#include "comparisons/eval/tosses.h"
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

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rbx: rigid-body collision detection and response testbed"};
  app.require_subcommand(1);
  rbx::SceneCommandOptions run_opt, contacts_opt, compare_opt;
  rbx::ReportOptions report_opt, check_opt;
  scene_options(app.add_subcommand("run", "custom engine only: collision events and final state"),
                run_opt, false, true);
  CLI::App* contacts =
      app.add_subcommand("contacts", "contact query at the t=0 poses, every backend");
  scene_options(contacts, contacts_opt, false, true);
  contacts
      ->add_option("--at", contacts_opt.at,
                   "first-contact: query at the first step where a pair touches (the custom "
                   "engine's motion, the exact oracle's test)")
      ->check(CLI::IsMember({"first-contact"}));
  scene_options(app.add_subcommand("compare", "the scenes' checks, side by side"), compare_opt,
                true, true);
  CLI::App* report =
      app.add_subcommand("report", "accuracy report (default: scenes/ -> reports/latest)");
  report->add_option("inputs", report_opt.inputs, "scene files or folders");
  report->add_option("--out", report_opt.out, "output folder");
  report->add_option("--backends", report_opt.backends, "comma-separated backend names");
  report->add_option("--threads", report_opt.threads, "threads per rank (default: every core)");
  std::vector<std::string> scenes_inputs;
  app.add_subcommand("scenes", "the scene library as a markdown table (scenes/README.md)")
      ->add_option("inputs", scenes_inputs, "scene files or folders (default: scenes/)");
  CLI::App* check = app.add_subcommand("check", "regression check against reports/baseline.json");
  check->add_option("inputs", check_opt.inputs, "scene files or folders (default: scenes/)");
  check->add_option("--baseline", check_opt.baseline, "baseline file");
  check->add_option("--backends", check_opt.backends,
                    "comma-separated backend names: only their metrics are compared (and updated)");
  CLI::Option* update = check->add_flag("--update", check_opt.update,
                                        "merge this run into the baseline (scenes and backends not "
                                        "run stay); refused while anything is worse");
  check
      ->add_flag("--accept-worse", check_opt.accept_worse,
                 "with --update: record worse metrics too")
      ->needs(update);
  check->add_flag("--explore", check_opt.explore,
                  "also run explore's fixed random samples (contact and impact kinds, seed 1): "
                  "the default when no scene is named");
  check->add_flag("--no-cache", check_opt.no_cache,
                  "rerun every reference library (no build/cache)");
  rbx::BenchOptions bench_opt;
  CLI::App* bench = app.add_subcommand(
      "bench", "performance comparison (default: reports/latest, and reports/perf.md)");
  bench->add_option("--out", bench_opt.out, "output folder");
  bench->add_flag("--quick", bench_opt.quick, "fewer sizes and shorter runs (under a minute)");
  rbx::TossesOptions tosses_opt;
  CLI::App* tosses =
      app.add_subcommand("tosses", "every dynamics backend against measured cube tosses");
  tosses->add_option("data", tosses_opt.data, "tosses CSV (.csv or .csv.gz)")->required();
  tosses->add_option("--params", tosses_opt.params,
                     "parameter file (default: params.json beside DATA)");
  tosses->add_flag("--fit", tosses_opt.fit,
                   "fit restitution and friction per backend on DATA, write the parameter file");
  tosses->add_option("--backends", tosses_opt.backends, "comma-separated backend names");
  tosses->add_option("--json", tosses_opt.json,
                     "write JSON results to FILE, or - for standard output");
  rbx::ViewOptions view_opt;
  CLI::App* view = app.add_subcommand("view", "one offline HTML page: 3-D replay of every backend");
  view->add_option("scene", view_opt.scene, "scene file (TOML)")->required();
  view->add_option("--backends", view_opt.backends, "comma-separated backend names");
  view->add_option("--out", view_opt.out, "output HTML file (default: FAMILY_STEM.html)");

  rbx::ExploreOptions explore_opt;
  CLI::App* explore = app.add_subcommand(
      "explore", "random contact pairs against the exact oracle; disagreements shrunk to scenes");
  explore->add_option("--count", explore_opt.count, "number of samples (default 20000)");
  explore->add_option("--seed", explore_opt.seed, "seed (default 1)");
  explore->add_option("--kind", explore_opt.kind, "contact | impact | landing");
  explore->add_option("--backends", explore_opt.backends, "comma-separated backend names");
  explore->add_option("--out", explore_opt.out, "output folder (default reports/explore)");
  explore->add_option("--baseline", explore_opt.baseline,
                      "stored explore.json: exit 1 when a backend got worse");
  explore->add_option("--threads", explore_opt.threads, "threads per rank (default: every core)");
  explore->add_option("--shrink-budget", explore_opt.shrink_budget,
                      "evaluations per group while shrinking");
  explore->add_flag("--bench", explore_opt.bench,
                    "time the sampling only (hulls under 100 points)");
  explore->add_flag("--no-figure", explore_opt.no_figure, "skip the matplotlib figure");

  // An unknown command is named as such (CLI11 would say only that a subcommand is required).
  if (argc > 1 && argv[1][0] != '-') {
    std::string names;
    bool known = false;
    for (const CLI::App* sub : app.get_subcommands({})) {
      names += (names.empty() ? "" : ", ") + sub->get_name();
      known = known || sub->get_name() == argv[1];
    }
    if (!known) {
      std::cerr << "rbx: unknown command '" << argv[1] << "'; commands: " << names
                << " (see rbx --help)\n";
      return 2;
    }
  }

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

  // Usage that would quietly mean something else is refused before any work: an empty
  // --backends (it would run the defaults) and a --json file in a folder that does not exist
  // (it would fail only after the whole run).
  for (const CLI::App* sub : app.get_subcommands()) {
    for (const CLI::Option* o : sub->get_options()) {
      if (o->count() == 0) continue;
      const std::string value = o->as<std::string>();
      if (o->get_name() == "--backends" && value.find_first_not_of(", ") == std::string::npos) {
        std::cerr << "rbx " << sub->get_name()
                  << ": --backends: the list is empty; name backends (e.g. custom,fcl) or all\n";
        return 2;
      }
      if (o->get_name() == "--json" && value != "-") {
        const std::filesystem::path folder = std::filesystem::path(value).parent_path();
        if (!folder.empty() && !std::filesystem::is_directory(folder)) {
          std::cerr << "rbx " << sub->get_name() << ": --json: folder '" << folder.string()
                    << "' does not exist\n";
          return 2;
        }
      }
    }
  }

  try {
    if (app.got_subcommand("run")) return rbx::run_command(run_opt);
    if (app.got_subcommand("contacts")) return rbx::contacts_command(contacts_opt);
    if (app.got_subcommand("compare")) return rbx::compare_command(compare_opt);
    if (app.got_subcommand("report")) return rbx::report_command(report_opt);
    if (app.got_subcommand("check")) return rbx::check_command(check_opt);
    if (app.got_subcommand("scenes")) return rbx::scenes_command(scenes_inputs);
    if (app.got_subcommand("bench")) return rbx::bench_command(bench_opt);
    if (app.got_subcommand("tosses")) return rbx::tosses_command(tosses_opt);
    if (app.got_subcommand("view")) return rbx::view_command(view_opt);
    if (app.got_subcommand("explore")) return rbx::explore_command(explore_opt);
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
