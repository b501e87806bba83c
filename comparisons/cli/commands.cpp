// What the scene commands share.
#include "comparisons/cli/commands.h"

#include "comparisons/scene/scene_file.h"

namespace rbx {

Scene load_scene_for_command(const std::string& path, const SceneCommandOptions& opt) {
  std::vector<std::string> sets = opt.sets;
  if (opt.force) sets.push_back("force=true");
  return load_scene(path, sets);
}

}  // namespace rbx
