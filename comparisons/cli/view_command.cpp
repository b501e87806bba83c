#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "comparisons/cli/commands.h"
#include "comparisons/eval/harness.h"
#include "comparisons/output/view_page.h"

namespace fs = std::filesystem;

namespace rbx {

int view_command(const ViewOptions& opt) {
  SceneCommandOptions so;
  so.scenes = {opt.scene};
  const Scene scene = load_scene_for_command(opt.scene, so);
  HarnessOptions hopt;
  hopt.backends = opt.backends;
  hopt.studies = false;
  const SceneEvaluation ev = evaluate_scene(scene, hopt);
  std::ifstream in(three_js_path(), std::ios::binary);
  std::ostringstream js;
  js << in.rdbuf();
  const std::string out =
      opt.out.empty() ? ev.family + "_" + fs::path(scene.file).stem().string() + ".html" : opt.out;
  const std::string page =
      view_page(view_data(scene, read_replay(ev.json, kViewMaxEvents)), js.str());
  write_text(out, page);
  std::cout << "view: " << out << " (" << page.size() / 1024 << " kB, "
            << ev.json["backends"].size() << " backends)\n";
  return 0;
}

}  // namespace rbx
