// `rbx distance SCENE`: every backend's distance query at the t = 0 poses, side by side, with
// the distance and witness errors against the `exact` oracle.
#include <iostream>

#include "comparisons/cli/commands.h"
#include "comparisons/eval/distance_query.h"
#include "comparisons/output/distance_table.h"

namespace rbx {

int distance_command(const SceneCommandOptions& opt) {
  const Scene scene = load_scene_for_command(opt.scenes.at(0), opt);
  const std::vector<std::string> names = select_backends(scene, opt.backends, Capability::Distance);
  std::ostream& out = opt.json == "-" ? std::cerr : std::cout;
  out << "scene: " << scene.name << " (" << scene.file << ")\n";
  const DistanceComparison c = compare_distances(scene, names);
  print_distances(out, c);
  if (!opt.json.empty()) write_json(opt.json, distance_json(c));
  // A scene fails, as `rbx compare` fails one, when an engine its [expect] binds misses it.
  return c.expect.failing.empty() ? 0 : 1;
}

}  // namespace rbx
