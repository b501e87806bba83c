// Bodies from scene specifications: re-centring on the centre of mass, poses, static bodies.
#include "engine/body.h"

#include <gtest/gtest.h>

#include <memory>

namespace rbx {
namespace {

// Square pyramid: base 2 x 2 in z = 0, apex at height 3. Solid centre of mass at h/4 = 0.75;
// the seed's vertex average at h/5 = 0.6, so the two mass models place the body differently.
std::shared_ptr<const ConvexPolyhedron> pyramid() {
  std::vector<Vec3> v = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, {0, 0, 3}};
  std::vector<std::array<int, 3>> t = {{0, 2, 1}, {0, 3, 2}, {0, 1, 4},
                                       {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
  return std::make_shared<const ConvexPolyhedron>(
      ConvexPolyhedron::from_triangles(std::move(v), std::move(t)));
}

BodySpec pyramid_spec(MassModel model, bool is_static) {
  BodySpec s;
  s.name = "P";
  s.shape_kind = ShapeKind::Convex;
  s.shape = pyramid();
  s.mass = 2.0;
  s.mass_model = model;
  s.is_static = is_static;
  s.position = Vec3(1, 2, 3);
  s.orientation = Quat(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()));  // local z -> world -y
  s.velocity = Vec3(0.5, 0, 0);
  s.angular_velocity = Vec3(0, 0, 2);
  return s;
}

// Round-off on O(1) coordinates after a rotation and a few sums.
constexpr double kRotationRoundOff = 1e-14;

TEST(Body, PoseIsTheCentreOfMassOfEitherMassModel) {
  for (const auto& [model, com_height] :
       {std::pair{MassModel::Solid, 0.75}, std::pair{MassModel::Vertices, 0.6}}) {
    const RigidBody b = make_body(pyramid_spec(model, false));
    // position = spec.position + R * com, with R taking local z to world -y.
    EXPECT_LT((b.position - Vec3(1, 2 - com_height, 3)).norm(), kRotationRoundOff);
    EXPECT_LT((b.shape_origin_offset - Vec3(0, 0, -com_height)).norm(), kRotationRoundOff);
    // The stored shape is re-centred: its own centre of mass (same model) is the origin.
    const MassProperties own = mass_properties(*b.shape, b.mass, model);
    EXPECT_LT(own.center_of_mass.norm(), kRotationRoundOff);
    // The apex is where the scene put it, whatever the model: spec.position + R (0, 0, 3).
    EXPECT_LT((b.world_vertex(4) - Vec3(1, -1, 3)).norm(), kRotationRoundOff);
  }
}

TEST(Body, MovingBodyKeepsItsStateAndInvertsItsInertia) {
  const RigidBody b = make_body(pyramid_spec(MassModel::Solid, false));
  EXPECT_DOUBLE_EQ(b.inverse_mass, 0.5);
  EXPECT_LT((b.inverse_inertia_body * b.inertia_body - Mat3::Identity()).norm(), 1e-13);
  EXPECT_EQ(b.velocity, Vec3(0.5, 0, 0));
  EXPECT_EQ(b.angular_velocity, Vec3(0, 0, 2));
  // World inverse inertia is R I^-1 R^T (seed correction 5 (world-frame inverse inertia, static
  // bodies zero)).
  const Mat3 r = b.orientation.toRotationMatrix();
  EXPECT_LT((b.inverse_inertia_world() - r * b.inverse_inertia_body * r.transpose()).norm(), 1e-15);
}

TEST(Body, AMeasuredInertiaReplacesTheShapes) {
  // A measured inertia (the tossed cube's) is taken as given; the centre of mass and the pose
  // still come from the shape.
  BodySpec spec = pyramid_spec(MassModel::Solid, false);
  const Mat3 measured = Vec3(0.4, 0.5, 0.6).asDiagonal();
  spec.inertia = measured;
  const RigidBody b = make_body(spec);
  const RigidBody from_shape = make_body(pyramid_spec(MassModel::Solid, false));
  EXPECT_EQ(b.inertia_body, measured);
  EXPECT_LT((b.inverse_inertia_body * measured - Mat3::Identity()).norm(), 1e-15);
  EXPECT_GT((from_shape.inertia_body - measured).norm(), 0.1);
  EXPECT_EQ(b.position, from_shape.position);
  EXPECT_DOUBLE_EQ(b.mass, 2.0);
}

TEST(Body, StaticBodyHasZeroInversesAndNoMotion) {
  // seed correction 5 (world-frame inverse inertia, static bodies zero): static bodies have inverse
  // mass and inverse inertia zero; the velocities a scene gives them are dropped (an immovable body
  // has none).
  const RigidBody b = make_body(pyramid_spec(MassModel::Solid, true));
  EXPECT_TRUE(b.is_static);
  EXPECT_EQ(b.inverse_mass, 0.0);
  EXPECT_EQ(b.inverse_inertia_body, Mat3::Zero());
  EXPECT_EQ(b.inverse_inertia_world(), Mat3::Zero());
  EXPECT_EQ(b.velocity, Vec3::Zero());
  EXPECT_EQ(b.angular_velocity, Vec3::Zero());
  EXPECT_EQ(b.kinetic_energy(), 0.0);
  EXPECT_DOUBLE_EQ(b.mass, 2.0);  // the nominal mass is kept for reports
}

}  // namespace
}  // namespace rbx
