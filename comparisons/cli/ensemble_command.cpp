// `rbx ensemble SCENE`: nudged copies of a scene through every dynamics backend.
#include <cmath>
#include <filesystem>
#include <iostream>

#include "comparisons/cli/commands.h"
#include "comparisons/eval/ensemble.h"
#include "comparisons/eval/json_io.h"
#include "comparisons/output/ensemble_report.h"
#include "comparisons/scene/scene_file.h"

namespace rbx {

namespace {

// The nudges of --perturb KEY=SCALE (keys: position, orientation, velocity, angular_velocity).
Nudge parse_nudges(const std::vector<std::string>& items) {
  Nudge n;
  for (const std::string& item : items) {
    const size_t eq = item.find('=');
    const std::string key = item.substr(0, eq);
    double* field = key == "position"           ? &n.position
                    : key == "orientation"      ? &n.orientation
                    : key == "velocity"         ? &n.velocity
                    : key == "angular_velocity" ? &n.angular_velocity
                                                : nullptr;
    if (eq == std::string::npos || !field)
      throw InputError("rbx ensemble: --perturb '" + item +
                       "': expected KEY=SCALE with KEY one of position, orientation, velocity, "
                       "angular_velocity");
    size_t used = 0;
    double scale = -1.0;
    try {
      scale = std::stod(item.substr(eq + 1), &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() - eq - 1 || !(scale >= 0.0) || !std::isfinite(scale))
      throw InputError("rbx ensemble: --perturb '" + item +
                       "': SCALE must be a finite number >= 0");
    *field = scale;
  }
  return n;
}

}  // namespace

int ensemble_command(const EnsembleOptions& opt) {
  if (opt.count < 2) throw InputError("rbx ensemble: --count must be at least 2");
  Scene scene = load_scene_for_command(opt.scene.scenes.at(0), opt.scene);
  EnsembleSettings settings;
  settings.count = opt.count;
  settings.seed = opt.seed;
  settings.nudge = parse_nudges(opt.perturb);
  settings.step_test = opt.step_test;
  // The scene's [ensemble] table: the run the report makes of it, unless the options say more.
  apply_ensemble_table(scene, settings, opt.count_given);
  const std::vector<std::string> names =
      select_backends(scene, opt.scene.backends, Capability::Dynamics);
  ParallelRun par(opt.threads);
  const EnsembleResult r = run_ensemble(scene, names, settings, par);
  if (!par.root()) return 0;
  std::ostream& out = opt.scene.json == "-" ? std::cerr : std::cout;
  print_ensemble(out, r);
  if (!opt.scene.json.empty()) write_json(opt.scene.json, ensemble_json(r));
  if (!opt.out.empty()) {
    // The spread against the nudge size: a tenth and ten times the nudges, the run between them.
    std::vector<EnsembleResult> sizes = scaled_ensembles(scene, names, settings, {0.1, 10.0}, par);
    sizes.insert(sizes.begin() + 1, r);
    std::filesystem::create_directories(opt.out);
    write_json((std::filesystem::path(opt.out) / "ensemble.json").string(),
               ensemble_json(r, sizes));
    const bool drawn = draw_ensemble_figures(opt.out);
    out << "wrote " << opt.out << "/ensemble.json"
        << (drawn ? ", ensemble_scatter.png and ensemble_spread.png"
                  : " (figures not drawn: see figures.log)")
        << "\n";
  }
  long failed = 0;
  for (const BackendEnsemble& b : r.backends) failed += b.failed;
  return failed > 0 ? 1 : 0;
}

}  // namespace rbx
