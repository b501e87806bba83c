// Uses the installed rbx from another project: a box resting 0.1 m deep in a slab, queried through
// two backends of the registry, and a scene file evaluated by the harness.
#include <cstdio>

#include "comparisons/eval/harness.h"
#include "comparisons/scene/scene_file.h"
#include "reference/backend.h"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: app SCENE.toml\n");
    return 2;
  }
  const rbx::Scene scene = rbx::load_scene(argv[1]);
  const std::vector<rbx::RigidBody> bodies = rbx::make_bodies(scene);
  for (const char* name : {"exact", "fcl"}) {
    const rbx::ContactResult r = rbx::find_backend(name)->contact(bodies[0], bodies[1]);
    if (r.contacts.empty()) return 1;
    const rbx::ContactPoint& c = r.contacts.front();
    std::printf("%s: normal (%g, %g, %g) depth %g\n", name, c.normal.x(), c.normal.y(),
                c.normal.z(), c.depth);
  }
  rbx::HarnessOptions opt;
  opt.backends = "exact,fcl";
  opt.studies = false;
  const rbx::SceneEvaluation ev = rbx::evaluate_scene(scene, opt);
  std::printf("harness: %zu metrics\n", ev.metrics.size());
  return ev.metrics.empty() ? 1 : 0;
}
