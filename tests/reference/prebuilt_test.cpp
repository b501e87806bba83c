// The "prebuilt" query variants (reference/prebuilt_cache.h): the same query with the library's
// shapes built once and kept. The report times them beside the per-call backends, so their
// answers must be the per-call answers bit for bit, at every pose, also when a kept shape is met
// again at a new pose (a stale placement would show here). The same holds for custom's
// "faithful" variant: the seed's loops must find what the accelerated detector finds.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "engine/format.h"
#include "reference/backend.h"
#include "tests/common/fixtures.h"

namespace rbx {
namespace {

using test::box_at;
using test::generic_rotation;
using test::pyramid_spec;
using test::unit_cube;

/// Pairs over three shapes (a unit cube, a flat box, a pyramid), each shape met at several poses:
/// face overlap, a rotated overlap, a corner in a face, separated.
std::vector<std::pair<RigidBody, RigidBody>> pairs() {
  const RigidBody cube = unit_cube("A", Vec3::Zero());
  const RigidBody slab = box_at("B", Vec3(2.0, 0.5, 1.5), Vec3(1.2, 0.1, -0.05));
  RigidBody pyramid = make_body(pyramid_spec("P", Vec3(0.1, 0.2, 0.3), generic_rotation()));
  std::vector<std::pair<RigidBody, RigidBody>> out;
  auto at = [](RigidBody b, const Vec3& p, const Quat& q) {
    b.position = p;
    b.orientation = q;
    return b;
  };
  out.push_back({cube, slab});
  out.push_back({cube, at(slab, Vec3(1.0, 0.3, 0.2), generic_rotation())});
  out.push_back({at(cube, Vec3(0.2, -0.1, 0.0), generic_rotation().conjugate()), slab});
  out.push_back({cube, pyramid});
  out.push_back({pyramid, at(slab, Vec3(0.4, 0.8, 0.4), Quat::Identity())});
  out.push_back({cube, at(slab, Vec3(5.0, 0.0, 0.0), Quat::Identity())});  // separated
  out.push_back({cube, slab});                                             // back to the first
  return out;
}

TEST(Prebuilt, EveryVariantAnswersAsItsBackendAtEveryPose) {
  int variants = 0;
  for (const QueryVariant& v : query_variants()) {
    if (v.variant != "prebuilt" && v.variant != "faithful") continue;
    ++variants;
    const Backend* be = find_backend(v.backend);
    ASSERT_NE(be, nullptr) << v.backend;
    ASSERT_TRUE(be->contact) << v.backend;
    int touching = 0;
    for (const auto& [a, b] : pairs()) {
      const ContactResult plain = be->contact(a, b);
      const ContactResult kept = v.contact(a, b);
      const std::string what = v.backend + " on " + a.name + "-" + b.name + " at " +
                               fmt_vec(a.position) + " / " + fmt_vec(b.position);
      ASSERT_EQ(kept.status, plain.status) << what << ": " << kept.message;
      ASSERT_EQ(kept.contacts.size(), plain.contacts.size()) << what;
      touching += plain.contacts.empty() ? 0 : 1;
      for (size_t k = 0; k < plain.contacts.size(); ++k) {
        EXPECT_EQ(kept.contacts[k].normal, plain.contacts[k].normal) << what;
        EXPECT_EQ(kept.contacts[k].point, plain.contacts[k].point) << what;
        EXPECT_EQ(kept.contacts[k].depth, plain.contacts[k].depth) << what;
        EXPECT_EQ(kept.contacts[k].feature, plain.contacts[k].feature) << what;
      }
    }
    // The pairs are not all trivial for this backend: most of them touch.
    EXPECT_GE(touching, 4) << v.backend;
  }
  // fcl, fcl-hull, bullet, bullet-hull, bullet-sat, ode, ode-hull, mujoco, mujoco-hull, dart,
  // dart-hull; and custom's faithful variant.
  EXPECT_EQ(variants, 12);
}

}  // namespace
}  // namespace rbx
