// A backend is one adapter file and one registry entry (docs/backends.md, "Adding a backend"):
// this file is a whole toy backend, and the test shows that its entry alone brings it into the
// harness, the pages' colours, the figure scripts' styles and `rbx bench`'s cases. (A built-in
// adapter's table is listed in reference/registry.cpp's adapters(); this one is registered at
// run time, as a researcher's own backend is from Python. The conformance suite,
// tests/reference/conformance_test.cpp, runs over the built-in registry.)
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "comparisons/eval/bench_cases.h"
#include "comparisons/eval/harness.h"
#include "comparisons/output/backend_style.h"
#include "comparisons/scene/scene_file.h"
#include "reference/backend.h"

namespace rbx {
namespace {

// The toy's contact query: each body as the sphere about its origin through its farthest
// vertex. Conventions as the contract states them: normal from B toward A, depth >= 0, the
// point midway between the spheres' surfaces along the normal, world frame.
ContactResult toy_contact(const RigidBody& a, const RigidBody& b) {
  auto radius = [](const RigidBody& body) {
    double r = 0.0;
    for (const Vec3& v : body.shape->vertices()) r = std::max(r, v.norm());
    return r;
  };
  const Vec3 d = a.position - b.position;
  const double ra = radius(a), rb = radius(b), depth = ra + rb - d.norm();
  if (depth < 0.0 || d.norm() == 0.0) return {};
  const Vec3 n = d.normalized();
  ContactPoint c;
  c.normal = n;
  c.depth = depth;
  c.point = b.position + n * (rb - 0.5 * depth);
  return {Status::Ok, "", {c}};
}

// The toy's whole registry entry: name, description, query, style, the hulls `rbx bench` times.
Backend toy_backend() {
  return Backend{"toy-spheres", "bounding spheres about each body's origin (a toy)",
                 toy_contact,   nullptr,
                 nullptr,       false}
      .drawn("#123456", "p")
      .timed(128, 32);
}

TEST(ToyBackend, ItsEntryAloneBringsItIntoTheHarnessThePagesAndTheBench) {
  register_backend(toy_backend());
  // The harness runs it beside the oracle on a scene of the library and scores it.
  HarnessOptions opt;
  opt.backends = "exact,toy-spheres";
  opt.studies = false;
  opt.timing_budget_s = 0.0;
  const SceneEvaluation ev =
      evaluate_scene(load_scene(std::string(RBX_SOURCE_DIR) + "/scenes/contact/axis_x.toml"), opt);
  ASSERT_TRUE(ev.json["backends"].contains("toy-spheres")) << ev.json.dump(1);
  EXPECT_EQ(ev.json["backends"]["toy-spheres"]["status"], "ok") << ev.json.dump(1);
  bool scored = false;
  for (const Metric& m : ev.metrics) scored = scored || (m.backend == "toy-spheres");
  EXPECT_TRUE(scored) << "no metric of the toy against the truth";
  // The pages and the figure scripts draw it in its colour.
  EXPECT_EQ(backend_colour("toy-spheres"), "#123456");
  EXPECT_NE(backend_style_json().find("\"toy-spheres\":[\"#123456\",\"p\"]"), std::string::npos)
      << backend_style_json();
  // `rbx bench` times it up to the sizes of its entry.
  bool timed = false;
  for (const NarrowBackend& n : narrow_backends())
    if (n.backend == "toy-spheres") {
      timed = true;
      EXPECT_EQ(n.variant, "default");
      EXPECT_EQ(n.max_vertices_full, 128);
      EXPECT_EQ(n.max_vertices_quick, 32);
    }
  EXPECT_TRUE(timed);
  unregister_backend("toy-spheres");
  EXPECT_EQ(find_backend("toy-spheres"), nullptr);
}

}  // namespace
}  // namespace rbx
