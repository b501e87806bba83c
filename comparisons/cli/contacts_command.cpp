// `rbx contacts SCENE`: every backend's contact query at the t = 0 poses (or, with --at
// first-contact, at the first step where a pair touches), side by side, with the angle and depth
// differences against the `exact` oracle, marked as `compare` marks them.
#include <iostream>

#include "comparisons/cli/commands.h"
#include "comparisons/eval/contacts_query.h"
#include "comparisons/output/contacts_table.h"

namespace rbx {

int contacts_command(const SceneCommandOptions& opt) {
  const Scene scene = load_scene_for_command(opt.scenes.at(0), opt);
  const std::vector<std::string> names = select_backends(scene, opt.backends, Capability::Contact);
  std::ostream& out = opt.json == "-" ? std::cerr : std::cout;
  out << "scene: " << scene.name << " (" << scene.file << ")\n";
  const ContactsComparison c = compare_contacts(scene, names, opt.at == "first-contact");
  print_contacts(out, scene, c);
  if (!opt.json.empty()) write_json(opt.json, c.json);
  return 0;
}

}  // namespace rbx
