// `rbx toi SCENE`: every backend's time of impact over an interval, side by side, with the time
// error against the `exact` oracle.
#include <cmath>
#include <iostream>

#include "comparisons/cli/commands.h"
#include "comparisons/eval/toi_query.h"
#include "comparisons/output/toi_table.h"

namespace rbx {

int toi_command(const SceneCommandOptions& opt) {
  const Scene scene = load_scene_for_command(opt.scenes.at(0), opt);
  const double interval = opt.interval > 0 ? opt.interval : scene.sim.dt;
  const std::vector<std::string> names = select_backends(scene, opt.backends, Capability::Toi);
  std::ostream& out = opt.json == "-" ? std::cerr : std::cout;
  out << "scene: " << scene.name << " (" << scene.file << ")\n";
  const ToiComparison c = compare_tois(scene, names, interval);
  print_tois(out, c);
  if (!opt.json.empty()) write_json(opt.json, toi_json(c));
  // A scene fails, as `rbx compare` fails one, when an engine its [expect] binds misses it.
  return c.expect.failing.empty() ? 0 : 1;
}

}  // namespace rbx
