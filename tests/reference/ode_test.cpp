// ODE 0.16.2 adapter: contact conventions of dCollide on dCreateConvex geoms, the one-point
// convex-convex manifold, and impacts through dWorldStep against hand-derived answers.
#include "reference/ode.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <utility>

#include "tests/common/fixtures.h"

namespace rbx {
namespace {

// The backends under test, by their registry names.
const Backend& ode_hull = ode_adapter().backend("ode-hull");

using test::box_spec;
using test::diagonal_along_x;
using test::pyramid_spec;

// ODE computes in double (dDOUBLE): contact geometry of unit-size boxes is exact to round-off.
constexpr double kRoundOff = 1e-12;

// --- Contact conventions ------------------------------------------------------------------

TEST(OdeContact, OverlapAlongXGivesNormalFromBTowardA) {
  // Unit cubes, B centred at x = 0.9: faces x = 0.5 (A) and x = 0.4 (B) overlap by 0.1.
  const RigidBody a = make_body(box_spec("A", Vec3::Ones(), Vec3::Zero()));
  const RigidBody b = make_body(box_spec("B", Vec3::Ones(), Vec3(0.9, 0, 0)));
  const ContactResult r = ode_hull.contact(a, b);
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_FALSE(r.contacts.empty());
  for (const ContactPoint& c : r.contacts) {
    EXPECT_NEAR(c.normal.x(), -1.0, kRoundOff);
    EXPECT_NEAR(c.normal.y(), 0.0, kRoundOff);
    EXPECT_NEAR(c.normal.z(), 0.0, kRoundOff);
    EXPECT_NEAR(c.depth, 0.1, kRoundOff);
    // On the overlap slab 0.4 <= x <= 0.5, within the 1 x 1 faces.
    EXPECT_GE(c.point.x(), 0.4 - kRoundOff);
    EXPECT_LE(c.point.x(), 0.5 + kRoundOff);
    EXPECT_LE(std::abs(c.point.y()), 0.5 + kRoundOff);
    EXPECT_LE(std::abs(c.point.z()), 0.5 + kRoundOff);
  }
}

TEST(OdeContact, SwappingTheBodiesFlipsTheNormal) {
  const RigidBody a = make_body(box_spec("A", Vec3::Ones(), Vec3::Zero()));
  const RigidBody b = make_body(box_spec("B", Vec3::Ones(), Vec3(0.9, 0, 0)));
  const ContactResult r = ode_hull.contact(b, a);
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_FALSE(r.contacts.empty());
  for (const ContactPoint& c : r.contacts) {
    EXPECT_NEAR(c.normal.x(), 1.0, kRoundOff);
    EXPECT_NEAR(c.depth, 0.1, kRoundOff);
  }
}

TEST(OdeContact, RotatedPairGivesWorldFrameNormal) {
  // Both cubes turned 0.3 rad about z, B at q * (0.9, 0.2, 0.1): the x-overlap of 0.1 in A's
  // frame, so the world normal is q * (-1, 0, 0) = (-cos 0.3, -sin 0.3, 0).
  const Quat q(Eigen::AngleAxisd(0.3, Vec3::UnitZ()));
  const RigidBody a = make_body(box_spec("A", Vec3::Ones(), Vec3::Zero(), 1.0, q));
  const RigidBody b = make_body(box_spec("B", Vec3::Ones(), q * Vec3(0.9, 0.2, 0.1), 1.0, q));
  const ContactResult r = ode_hull.contact(a, b);
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_FALSE(r.contacts.empty());
  for (const ContactPoint& c : r.contacts) {
    EXPECT_NEAR(c.normal.x(), -std::cos(0.3), kRoundOff);
    EXPECT_NEAR(c.normal.y(), -std::sin(0.3), kRoundOff);
    EXPECT_NEAR(c.normal.z(), 0.0, kRoundOff);
    EXPECT_NEAR(c.depth, 0.1, kRoundOff);
  }
}

TEST(OdeContact, TouchingAndSeparatedPairs) {
  const RigidBody a = make_body(box_spec("A", Vec3::Ones(), Vec3::Zero()));
  // Faces exactly touching: no penetration (a zero-depth contact would be allowed).
  const ContactResult touching =
      ode_hull.contact(a, make_body(box_spec("B", Vec3::Ones(), Vec3(1, 0, 0))));
  ASSERT_EQ(touching.status, Status::Ok) << touching.message;
  for (const ContactPoint& c : touching.contacts) EXPECT_LE(c.depth, kRoundOff);
  // 1 mm apart: nothing.
  const ContactResult apart =
      ode_hull.contact(a, make_body(box_spec("B", Vec3::Ones(), Vec3(1.001, 0, 0))));
  ASSERT_EQ(apart.status, Status::Ok) << apart.message;
  EXPECT_TRUE(apart.contacts.empty());
}

TEST(OdeKnownBehaviour, ExactTouchingOffCentreHasNoNormalAndIsTouching) {
  // scenes/contact/touching_zero_depth.toml: A sits exactly on B, shifted (0.3, 0.2) sideways.
  // Debian's ODE runs convex-convex through libccd MPR, which reports this pose as touching at
  // a round-off depth with its direction set to zero (mpr.c: "can be anything" below CCD_EPS).
  // Pinned: the adapter labels that as touching with no normal (status Touching) instead of
  // scoring (0, 0, 0).
  const RigidBody a = make_body(box_spec("A", Vec3::Ones(), Vec3(0.3, 0.2, 1)));
  const RigidBody b = make_body(box_spec("B", Vec3::Ones(), Vec3::Zero()));
  const ContactResult r = ode_hull.contact(a, b);
  EXPECT_EQ(r.status, Status::Touching);
  EXPECT_NE(r.message.find("no normal"), std::string::npos) << r.message;
}

TEST(OdeContact, MergedFacesOfAPyramidOnABox) {
  // Pyramid (vertex mass model: centre of mass 1/5 above the base) turned 30 deg about z, its
  // base at z = 0 sunk 0.02 into the top of a 2 x 2 x 1 box (top at z = 0.02): normal (0,0,1)
  // from the box toward the pyramid, depth 0.02. The base reaches ODE as one quadrilateral.
  BodySpec p = pyramid_spec("P", Vec3::Zero(), Quat(Eigen::AngleAxisd(M_PI / 6, Vec3::UnitZ())));
  p.mass_model = MassModel::Vertices;
  const RigidBody pyramid = make_body(p);
  const RigidBody table = make_body(box_spec("T", Vec3(2, 2, 1), Vec3(0, 0, -0.48)));
  const ContactResult r = ode_hull.contact(pyramid, table);
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_FALSE(r.contacts.empty());
  for (const ContactPoint& c : r.contacts) {
    EXPECT_NEAR(c.normal.z(), 1.0, kRoundOff);
    EXPECT_NEAR(c.depth, 0.02, kRoundOff);
    EXPECT_GE(c.point.z(), -kRoundOff);
    EXPECT_LE(c.point.z(), 0.02 + kRoundOff);
  }
}

TEST(OdeContact, NearlyFlatSliverReachesOdeAsConvexCounterClockwisePolygons) {
  // A hull of 7 points about 3 mm across and 3 um thick, as `rbx explore` draws slivers. Its top
  // has triangles tilted by a few 1e-5 rad from each other, with plane offsets 5e-10 m apart:
  // coplanar by an absolute tolerance of 1e-9 m, not by one relative to the shape. Merged, two of
  // them made a non-convex quadrilateral, and dCreateConvex printed to stdout that a polygon is
  // not counter-clockwise (its check: p0 . (p1 x p2) > 0 for a polygon's first three corners).
  BodySpec spec;
  spec.name = "S";
  spec.shape_kind = ShapeKind::Convex;
  spec.shape = std::make_shared<const ConvexPolyhedron>(ConvexPolyhedron::from_triangles(
      {Vec3(-0.00050624730299864314, -0.0010045729554208052, -1.3909764092413178e-06),
       Vec3(0.0011520936311120705, 0.0010855223275445765, -4.6887027687722172e-07),
       Vec3(-0.0007372764498091973, 0.00064420018367305739, -8.8195048308778018e-09),
       Vec3(-0.00052355330548399699, -0.0012895705862706333, 7.9729038403467692e-07),
       Vec3(0.00039414437936716011, -0.00015765879620640918, -8.9602408192083343e-07),
       Vec3(0.00073055807241739572, 0.00054282559162919521, 1.3861975309348615e-06),
       Vec3(-0.00034368866788662798, -0.00022789830171101119, 6.4160518746510833e-07)},
      {{0, 2, 1},
       {0, 3, 2},
       {4, 0, 1},
       {4, 3, 0},
       {5, 1, 2},
       {5, 4, 1},
       {5, 3, 4},
       {6, 2, 3},
       {6, 5, 2},
       {6, 3, 5}}));
  const RigidBody sliver = make_body(spec);
  const RigidBody box = make_body(box_spec("B", Vec3::Constant(0.002), Vec3(0, 0, -0.0009)));
  testing::internal::CaptureStdout();
  const ContactResult r = ode_hull.contact(sliver, box);
  std::fflush(stdout);
  EXPECT_EQ(testing::internal::GetCapturedStdout(), "");
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_FALSE(r.contacts.empty());
}

TEST(OdeKnownBehaviour, ConvexConvexReturnsOnePoint) {
  // A 0.5 cube pressed 0.05 into the middle of a unit cube's +x face: the true contact patch is
  // the small cube's whole 0.5 x 0.5 face (4 corners), but ODE 0.16.2's convex-convex collider
  // returns a single point (normal and depth right). Face-face impacts therefore get one
  // off-centre impulse (see FaceFaceImpactConservesMomentum). Pinned: if this fails, ODE
  // changed and the reports' notes must too.
  const RigidBody a = make_body(box_spec("A", Vec3::Ones(), Vec3::Zero()));
  const RigidBody b = make_body(box_spec("B", Vec3(0.5, 0.5, 0.5), Vec3(0.7, 0.1, 0.05)));
  const ContactResult r = ode_hull.contact(a, b);
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_EQ(r.contacts.size(), 1u);
  EXPECT_NEAR(r.contacts[0].normal.x(), -1.0, kRoundOff);
  EXPECT_NEAR(r.contacts[0].depth, 0.05, kRoundOff);  // B's face at x = 0.45, A's at 0.5
}

// --- Dynamics -------------------------------------------------------------------------------

// Head-on scene: A (m1 = 1, diagonal along x) at v1 = +1, B (m2 = 3) at v2 = -1; A's leading
// vertex starts 3 mm short of B's face (seen 1 mm deep two steps later at dt = 1 ms).
WorldDefinition head_on(double restitution) {
  WorldDefinition s;
  s.sim.dt = 1e-3;
  s.sim.duration = 0.02;
  s.sim.restitution = restitution;
  s.bodies.push_back(box_spec("A", Vec3::Ones(), Vec3(-std::sqrt(3.0) / 2 - 0.003, 0, 0), 1.0,
                              diagonal_along_x()));
  s.bodies.back().velocity = Vec3(1, 0, 0);
  s.bodies.push_back(box_spec("B", Vec3::Ones(), Vec3(0.5, 0, 0), 3.0));
  s.bodies.back().velocity = Vec3(-1, 0, 0);
  return s;
}

// 1-D closed form with m1 = 1, m2 = 3, v1 = 1, v2 = -1 (momentum -2, reduced mass 3/4):
// v1' = (-2 - 3 e 2) / 4, v2' = (-2 + e 2) / 4, j = (1 + e) * 0.75 * 2.
struct HeadOnAnswer {
  double e, v1, v2, impulse;
};
constexpr HeadOnAnswer kHeadOn[] = {{0.5, -1.25, -0.25, 2.25}, {1.0, -2.0, 0.0, 3.0}};

TEST(OdeDynamics, HeadOnImpactMatchesTheClosedForm) {
  // dWorldStep solves the contact exactly, up to ODE's default CFM = 1e-10, which softens the
  // impulse by a relative CFM / (dt * (1/m1 + 1/m2)) = 1e-10 / (1e-3 * 4/3) = 7.5e-8: 1e-6 m/s.
  for (const HeadOnAnswer& want : kHeadOn) {
    const DynamicsResult r = ode_hull.dynamics(head_on(want.e), {});
    ASSERT_EQ(r.status, Status::Ok) << r.message;
    ASSERT_EQ(r.finals.size(), 2u);
    EXPECT_NEAR(r.finals[0].velocity.x(), want.v1, 1e-6) << "e = " << want.e;
    EXPECT_NEAR(r.finals[1].velocity.x(), want.v2, 1e-6) << "e = " << want.e;
    EXPECT_LT(r.finals[0].angular_velocity.norm(), 1e-9);  // no lever arm
    // One step resolves the impact: one event, B -> A normal along -x, impulse j.
    ASSERT_EQ(r.events.size(), 1u) << "e = " << want.e;
    EXPECT_EQ(r.events[0].body_a, "A");
    EXPECT_EQ(r.events[0].body_b, "B");
    EXPECT_NEAR(r.events[0].contact.normal.x(), -1.0, kRoundOff);
    EXPECT_NEAR(r.events[0].impulse, want.impulse, 1e-6);
  }
}

TEST(OdeDynamics, PositionCorrectionSeparatesAfterAnInelasticImpact) {
  // e = 0, but the contact is first seen 1 mm deep (dt = 1 ms): ODE's contact target speed is
  // max(e * 2 m/s, ERP * depth / dt) = 0.2 * 1e-3 / 1e-3 = 0.2 m/s of separation. Around the
  // centre-of-mass velocity (-2 / 4 = -0.5) that gives v1' = -0.5 - (3/4) 0.2 = -0.65 and
  // v2' = -0.5 + (1/4) 0.2 = -0.45: an effective e of 0.1 instead of 0 (kept visible; see
  // ode.cpp on why the default ERP stays). CFM: 1e-6 as above.
  const DynamicsResult r = ode_hull.dynamics(head_on(0.0), {});
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  EXPECT_NEAR(r.finals[0].velocity.x(), -0.65, 1e-6);
  EXPECT_NEAR(r.finals[1].velocity.x(), -0.45, 1e-6);
}

TEST(OdeDynamics, FaceFaceImpactConservesMomentum) {
  // Axis-aligned cubes meeting face to face (m1 = 1 at +1, m2 = 3 at -1, e = 0.5). With one
  // contact point at a corner of the patch (ConvexConvexReturnsOnePoint) the 1-D answer is not
  // reached and the cubes spin; what must hold whatever the manifold: the contact forces are
  // equal and opposite at a common point, so linear momentum stays (-2, 0, 0) and angular
  // momentum about the origin stays 0 (the initial velocities lie on the x axis through both
  // centres); round-off only.
  WorldDefinition s = head_on(0.5);
  s.bodies[0].orientation = Quat::Identity();
  s.bodies[0].position = Vec3(-0.5 - 0.003, 0, 0);
  const DynamicsResult r = ode_hull.dynamics(s, {});
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  const double m[2] = {1.0, 3.0};
  Vec3 p = Vec3::Zero(), l = Vec3::Zero();
  for (int i = 0; i < 2; ++i) {
    const BodyFinal& f = r.finals[i];
    p += m[i] * f.velocity;
    // Unit cube: I = m/6 * identity about the centre in any orientation.
    l += f.position.cross(m[i] * f.velocity) + m[i] / 6.0 * f.angular_velocity;
  }
  EXPECT_LT((p - Vec3(-2, 0, 0)).norm(), 1e-9);
  EXPECT_LT(l.norm(), 1e-9);
  // The pinned consequence of the one-point manifold: A spins (a centred impulse would not).
  EXPECT_GT(r.finals[0].angular_velocity.norm(), 1e-3);
}

TEST(OdeDynamics, CubeCornerOnStaticSlab) {
  // Unit cube (m = 1, I = 1/6 identity), rotated 45 deg about x then 10 deg about y, falling at
  // 1 m/s onto a static slab; no gravity, e = 0.5. Lowest vertex relative to the centre:
  //   r = (0.5 cos10 - sqrt(2)/2 sin10, 0, -0.5 sin10 - sqrt(2)/2 cos10) = (0.36962, 0, -0.78319)
  // Single impulse along n = (0, 0, 1): r x n = (0, -r_x, 0),
  //   j = 1.5 / (1 + 6 r_x^2),  v' = (0, 0, -1 + j),  w' = (0, -6 r_x j, 0).
  // The slab top sits 2 mm - 1 um below the vertex: at dt = 1 ms the vertex is seen 1 um deep,
  // so ODE's contact point (on the clipped penetrating region) is within a few um of the
  // vertex; that moves r_x by ~1e-6 and j by as much. CFM adds ~6e-8 relative. Tolerance 1e-5.
  const double deg = M_PI / 180.0;
  const double rx = 0.5 * std::cos(10 * deg) - std::sqrt(0.5) * std::sin(10 * deg);
  const double rz = -0.5 * std::sin(10 * deg) - std::sqrt(0.5) * std::cos(10 * deg);
  const double j = 1.5 / (1 + 6 * rx * rx);
  const double slab_z = rz - 0.5 - 0.002 + 1e-6;
  // Both orders of the bodies in the scene: the static slab first must not change anything.
  for (bool slab_first : {false, true}) {
    WorldDefinition s;
    s.sim.dt = 1e-3;
    s.sim.duration = 0.01;
    s.sim.restitution = 0.5;
    s.bodies.push_back(box_spec("cube", Vec3::Ones(), Vec3::Zero(), 1.0,
                                Quat(rotation_from_euler_deg(Vec3(45, 10, 0)))));
    s.bodies.back().velocity = Vec3(0, 0, -1);
    s.bodies.push_back(box_spec("slab", Vec3(4, 4, 1), Vec3(0, 0, slab_z)));
    s.bodies.back().is_static = true;
    if (slab_first) std::swap(s.bodies[0], s.bodies[1]);
    const DynamicsResult r = ode_hull.dynamics(s, {});
    ASSERT_EQ(r.status, Status::Ok) << r.message;
    const BodyFinal& cube = r.finals[slab_first ? 1 : 0];
    const BodyFinal& slab = r.finals[slab_first ? 0 : 1];
    ASSERT_EQ(cube.name, "cube");
    EXPECT_NEAR(cube.velocity.z(), -1 + j, 1e-5);
    EXPECT_NEAR(cube.angular_velocity.y(), -6 * rx * j, 1e-5);
    // Off-plane components: zero for a point in the plane y = 0; ODE's point is clipped from
    // a ~1 um region, so the same 1e-5 bound applies (measured ~2e-9).
    EXPECT_NEAR(cube.velocity.x(), 0.0, 1e-5);
    EXPECT_NEAR(cube.angular_velocity.x(), 0.0, 1e-5);
    EXPECT_EQ(slab.velocity, Vec3::Zero());
    EXPECT_EQ(slab.position.z(), slab_z);
    // One event; its normal points from body_b toward body_a.
    ASSERT_EQ(r.events.size(), 1u);
    const double toward_a = r.events[0].body_a == "cube" ? 1.0 : -1.0;
    EXPECT_NEAR(r.events[0].contact.normal.z(), toward_a, kRoundOff);
    EXPECT_NEAR(r.events[0].impulse, j, 1e-5);
  }
}

TEST(OdeDynamics, AQuickStepRunDoesNotDependOnTheRunsBeforeIt) {
  // The quick step (a studied budget) shuffles its constraints with ODE's random generator, one
  // per process. A cube sliding flat on a slab (four contact points with friction, so the order
  // matters) run three times in one process: the third run must repeat the first bit for bit,
  // though the second advanced the generator.
  WorldDefinition s;
  s.sim.dt = 1e-3;
  s.sim.duration = 0.1;
  s.sim.gravity = Vec3(0, 0, -9.81);
  s.sim.friction = 0.5;
  s.bodies.push_back(box_spec("cube", Vec3::Ones(), Vec3(0, 0, 0.4995)));
  s.bodies.back().velocity = Vec3(1, 0.3, 0);
  s.bodies.push_back(box_spec("slab", Vec3(8, 8, 1), Vec3(0, 0, -0.5)));
  s.bodies.back().is_static = true;
  DynamicsOptions opt;
  opt.budget = 10;
  const Backend& ode = ode_adapter().backend("ode");
  const DynamicsResult first = ode.dynamics(s, opt);
  ASSERT_EQ(first.status, Status::Ok) << first.message;
  ode.dynamics(s, opt);
  const DynamicsResult third = ode.dynamics(s, opt);
  ASSERT_EQ(third.status, Status::Ok) << third.message;
  EXPECT_EQ(first.finals[0].position, third.finals[0].position);
  EXPECT_EQ(first.finals[0].velocity, third.finals[0].velocity);
  EXPECT_EQ(first.finals[0].angular_velocity, third.finals[0].angular_velocity);
}

TEST(OdeDynamics, FrictionIsCoulombMuTimesTheNormalImpulse) {
  // sim.friction is a Coulomb coefficient; ODE's surface.mu is one only with dContactApprox1
  // (without it mu bounds the friction *force* in newtons: see ode.cpp, near_callback).
  // A unit cube (m = 1, I = 1/6 identity) stands on a vertex, its body diagonal vertical, so
  // the lowest vertex is r = (0, 0, -h), h = sqrt(3)/2, straight below the centre. It hits a
  // static slab at v = (2, 0, -1) with e = 0.5, mu = 0.1, no gravity.
  //  - Normal (0, 0, 1): r x n = 0, so j_n = (1 + e) * 1 = 1.5 and v_z' = -1 + 1.5 = 0.5.
  //  - Sticking would need a tangential impulse j = v_x / (1/m + h^2 / I) = 2 / 5.5 = 0.364
  //    (r x x = (0, -h, 0), I^-1 = 6); Coulomb allows mu j_n = 0.15, so the cube slides and
  //    j_t = 0.15 along -x: v_x' = 2 - 0.15 = 1.85, w' = 6 r x (-0.15, 0, 0) = (0, 0.9 h, 0).
  //    (Still sliding afterwards: v_x' + (w' x r)_x = 1.85 - 0.9 h^2 = 1.175 > 0.)
  //  - The normal is along z, so ODE's friction pyramid (dPlaneSpace: -y and x) is aligned
  //    with the sliding direction and equals the cone here.
  // Read as a force limit (no Approx1), mu = 0.1 N would allow only 0.1 N * dt = 1e-4 N s:
  // v_x' = 1.9999. Tolerance 1e-5 as in CubeCornerOnStaticSlab (contact point within ~1 um of
  // the vertex, CFM ~1e-7 relative).
  const double h = std::sqrt(3.0) / 2;
  const double dt = 1e-3;
  WorldDefinition s;
  s.sim.dt = dt;
  s.sim.duration = 0.01;  // impact at step 2; the cube has left the slab well before the end
  s.sim.restitution = 0.5;
  s.sim.friction = 0.1;
  s.bodies.push_back(box_spec("cube", Vec3::Ones(), Vec3::Zero(), 1.0,
                              Quat::FromTwoVectors(Vec3(1, 1, 1).normalized(), -Vec3::UnitZ())));
  s.bodies.back().velocity = Vec3(2, 0, -1);
  // Slab top 2 mm - 1 um below the vertex: seen 1 um deep at the third step (dt = 1 ms).
  s.bodies.push_back(box_spec("slab", Vec3(4, 4, 1), Vec3(0, 0, -h - 0.5 - 0.002 + 1e-6)));
  s.bodies.back().is_static = true;
  const DynamicsResult r = ode_hull.dynamics(s, {});
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  const BodyFinal& cube = r.finals[0];
  EXPECT_NEAR(cube.velocity.x(), 1.85, 1e-5);
  EXPECT_NEAR(cube.velocity.y(), 0.0, 1e-5);
  EXPECT_NEAR(cube.velocity.z(), 0.5, 1e-5);
  EXPECT_NEAR(cube.angular_velocity.x(), 0.0, 1e-5);
  EXPECT_NEAR(cube.angular_velocity.y(), 0.9 * h, 1e-5);
  EXPECT_NEAR(cube.angular_velocity.z(), 0.0, 1e-5);
  ASSERT_EQ(r.events.size(), 1u);
  EXPECT_NEAR(r.events[0].impulse, 1.5, 1e-5);  // normal impulse only
}

TEST(OdeDynamics, FreeRotationStaysInTheWorldFrame) {
  // Isotropic cube: constant world angular velocity, q(t) = exp(w t) q0 (the adapter selects
  // ODE's finite rotation mode, exact for constant w). Round-off over 100 steps.
  const Vec3 w(1, 2, 3);  // rad/s, world
  const Quat q0(Eigen::AngleAxisd(0.7, Vec3(1, -2, 0.5).normalized()));
  WorldDefinition s;
  s.sim.dt = 1e-3;
  s.sim.duration = 0.1;
  s.bodies.push_back(box_spec("A", Vec3::Ones(), Vec3::Zero(), 1.0, q0));
  s.bodies.back().angular_velocity = w;
  const DynamicsResult r = ode_hull.dynamics(s, {});
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  EXPECT_LT((r.finals[0].angular_velocity - w).norm(), 1e-9);
  const Quat expect = Quat(Eigen::AngleAxisd(w.norm() * 0.1, w.normalized())) * q0;
  EXPECT_LT(std::abs(std::abs(expect.dot(r.finals[0].orientation)) - 1.0), 1e-9);
}

TEST(OdeDynamics, FreeFallSamples) {
  // dWorldStep is semi-implicit Euler: v_n = g n dt, x_n = x0 + g dt^2 n (n + 1) / 2.
  const double g = -9.81, dt = 1e-3;
  WorldDefinition s;
  s.sim.dt = dt;
  s.sim.duration = 0.1;
  s.sim.gravity = Vec3(0, 0, g);
  s.bodies.push_back(box_spec("A", Vec3::Ones(), Vec3(0, 0, 5)));
  DynamicsOptions opt;
  opt.sample_every = 10;
  const DynamicsResult r = ode_hull.dynamics(s, opt);
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_EQ(r.samples.size(), 11u);  // t = 0, 0.01, ..., 0.1
  for (size_t k = 0; k < r.samples.size(); ++k) {
    const double n = 10.0 * k;
    EXPECT_NEAR(r.samples[k].time, n * dt, 1e-12);
    EXPECT_NEAR(r.samples[k].bodies[0].velocity.z(), g * n * dt, 1e-12);
    EXPECT_NEAR(r.samples[k].bodies[0].position.z(), 5 + g * dt * dt * n * (n + 1) / 2, 1e-12);
  }
}

TEST(OdeDynamics, OdeErrorsBecomeStatusError) {
  // A negative mass fails dMassCheck inside dBodySetMass, which calls dDebug (abort by
  // default): the handler must turn it into an error result instead.
  WorldDefinition bad_mass;
  bad_mass.sim.duration = 0.01;
  bad_mass.bodies.push_back(box_spec("A", Vec3::Ones(), Vec3::Zero(), -1.0));
  const DynamicsResult r = ode_hull.dynamics(bad_mass, {});
  EXPECT_EQ(r.status, Status::Error);
  EXPECT_NE(r.message.find("ODE"), std::string::npos) << r.message;
  // A NaN velocity propagates silently in ODE: the adapter reports the non-finite state.
  WorldDefinition nan_state;
  nan_state.sim.duration = 0.01;
  nan_state.bodies.push_back(box_spec("A", Vec3::Ones(), Vec3::Zero()));
  nan_state.bodies.back().velocity = Vec3(std::nan(""), 0, 0);
  EXPECT_EQ(ode_hull.dynamics(nan_state, {}).status, Status::Error);
  // And ODE still works afterwards.
  EXPECT_EQ(ode_hull.dynamics(head_on(1.0), {}).status, Status::Ok);
}

}  // namespace
}  // namespace rbx
