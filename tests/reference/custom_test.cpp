// The `custom` backend behind the interface: its contact query answers with the manifold its
// world steps with (one pipeline, engine/manifold.h), its one point first.
#include "reference/custom.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <vector>

#include "engine/world.h"
#include "tests/common/fixtures.h"

namespace rbx {
namespace {

using test::random_rotation;

RigidBody body_of(const char* name, const ConvexPolyhedron& shape, const Vec3& position,
                  const Quat& orientation, bool is_static) {
  BodySpec spec;
  spec.name = name;
  spec.shape = std::make_shared<const ConvexPolyhedron>(shape);
  spec.position = position;
  spec.orientation = orientation;
  spec.is_static = is_static;
  return make_body(spec);
}

TEST(CustomBackend, TheQueryAnswersWithTheManifoldTheStepSolves) {
  // 300 random pairs (boxes of several proportions, a prism, an icosphere; centres 0 to 1.2
  // apart, so most touch, some deeply), A free and B static, both at rest with no gravity: one
  // step of a world solves the manifold at the start poses, and records every point it solved
  // (World::step_contacts). The query's points after its first are those, bit for bit and in
  // the same order, with the same normal.
  const std::vector<ConvexPolyhedron> shapes = {
      make_box(Vec3(1.0, 0.6, 0.3)), make_box(Vec3::Ones()), make_prism(0.4, 1.2, 7),
      make_icosphere(0.5, 2), make_box(Vec3(2.0, 2.0, 0.5))};
  const Backend& custom = custom_adapter().backend("custom");
  std::mt19937 rng(5151);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(shapes.size()) - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  SimSettings sim;
  sim.gravity = Vec3::Zero();
  sim.dt = 1e-3;
  int compared = 0, several = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const RigidBody a =
        body_of("A", shapes[pick(rng)], random_rotation(rng) * Vec3::UnitX() * unit(rng) * 1.2,
                random_rotation(rng), false);
    const RigidBody b = body_of("B", shapes[pick(rng)], Vec3::Zero(), random_rotation(rng), true);
    const ContactResult answer = custom.contact(a, b);
    World world(sim, {a, b}, ContactModel::Extended);
    ASSERT_TRUE(world.step());
    const std::vector<SolvedContact>& solved = world.step_contacts();
    if (answer.contacts.empty()) {
      EXPECT_TRUE(solved.empty()) << "trial " << trial;
      continue;
    }
    ++compared;
    ASSERT_EQ(answer.contacts.size(), solved.size() + 1) << "trial " << trial;
    several += solved.size() > 1 ? 1 : 0;
    for (size_t i = 0; i < solved.size(); ++i) {
      EXPECT_EQ(answer.contacts[i + 1].point, solved[i].point) << "trial " << trial;
      EXPECT_EQ(answer.contacts[i + 1].depth, solved[i].depth) << "trial " << trial;
      EXPECT_EQ(answer.contacts[i + 1].normal, solved[i].normal) << "trial " << trial;
    }
  }
  EXPECT_GT(compared, 150);
  EXPECT_GT(several, 20);
}

}  // namespace
}  // namespace rbx
