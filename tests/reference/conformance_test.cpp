// What every registered backend must do, whatever its library: one suite run over the registry
// (backends()), so a new adapter is held to the conventions by its registry entry alone.
//
// Contact: a separated pair has no contact; on an overlapping pair every point is finite, every
// normal unit, every depth non-negative, and a normal near the true axis points from B toward A;
// the other body order turns it round; the same query twice gives the same answer, bit for bit.
// Dynamics: a lone body in free fall follows the closed form within the integrator's own error,
// the same run twice ends in the same state, bit for bit, and a non-finite start is an error.
// These are the interface's conventions, not accuracy: a normal far from the truth (DART's
// triangle normals on hulls) is the report's business, measured and labelled there, so the
// direction is checked only where a normal lies within 60 degrees of the axis. A backend that
// passes a library's defect on unpatched says so in its result's message ("known defects":
// fcl-indep's negative depth and unrotated normal); such a result is held to the rest.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "reference/backend.h"
#include "reference/exact.h"
#include "reference/isolate.h"
#include "tests/common/fixtures.h"

namespace rbx {
namespace {

std::vector<std::string> names_with(bool contact) {
  std::vector<std::string> names;
  for (const Backend& b : backends())
    if (contact ? static_cast<bool>(b.contact) : static_cast<bool>(b.dynamics))
      names.push_back(b.name);
  return names;
}

// A test name may hold letters, digits and '_' only.
std::string test_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string s = info.param;
  for (char& c : s)
    if (c == '-') c = '_';
  return s;
}

class ContactConformance : public ::testing::TestWithParam<std::string> {
 protected:
  const Backend& backend() const { return *find_backend(GetParam()); }
};

// Two unit cubes, B at the origin, A above it at `gap` (negative: overlapping) along z, offset
// across so that no two faces are flush (a generic face contact), A turned about z.
std::pair<RigidBody, RigidBody> stacked(double gap) {
  const Quat turn(Eigen::AngleAxisd(0.3, Vec3::UnitZ()));
  return {test::unit_cube("A", Vec3(0.2, 0.1, 1.0 + gap), turn),
          test::unit_cube("B", Vec3::Zero())};
}

TEST_P(ContactConformance, SeparatedBodiesHaveNoContact) {
  for (const double gap : {0.5, 0.01, 0.001}) {
    const auto [a, b] = stacked(gap);
    const ContactResult r = backend().contact(a, b);
    ASSERT_EQ(r.status, Status::Ok) << r.message;
    EXPECT_TRUE(r.contacts.empty()) << "gap " << gap << ": " << r.contacts.size() << " contacts";
  }
}

// A result that passes a library's defect on unpatched, as its message says.
bool labelled_defect(const ContactResult& r) {
  return r.message.find("known defects") != std::string::npos;
}

// Within 60 degrees of the true axis (z): near enough that its sign is the convention's.
bool near_axis(const Vec3& n) { return std::abs(n.z()) >= 0.5; }

TEST_P(ContactConformance, AnOverlappingPairFollowsTheContactConventions) {
  const auto [a, b] = stacked(-0.1);
  const ContactResult r = backend().contact(a, b);
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_FALSE(r.contacts.empty());
  const bool labelled = labelled_defect(r);
  int checked = 0;
  for (const ContactPoint& c : r.contacts) {
    EXPECT_TRUE(c.point.allFinite());
    if (!labelled) {
      EXPECT_GE(c.depth, 0.0);
    }
    // At most the smaller body's size: 0.1 m deep, anything past 1 m is not this pair.
    EXPECT_LE(std::abs(c.depth), 1.0);
    if (c.depth <= kTouchingDepth && !c.normal.allFinite()) continue;  // touching, no normal
    // Unit to round-off of a normalised double vector.
    EXPECT_NEAR(c.normal.norm(), 1.0, 1e-9);
    // From B toward A: A lies above.
    if (!labelled && near_axis(c.normal)) {
      EXPECT_GT(c.normal.z(), 0.0) << c.normal.transpose();
      ++checked;
    }
  }
  std::printf("%s: %zu points, %d normals near the axis%s\n", GetParam().c_str(), r.contacts.size(),
              checked, labelled ? " (labelled defect)" : "");
}

TEST_P(ContactConformance, TheOtherBodyOrderTurnsTheNormalRound) {
  const auto [a, b] = stacked(-0.1);
  const ContactResult ab = backend().contact(a, b), ba = backend().contact(b, a);
  ASSERT_EQ(ab.status, Status::Ok) << ab.message;
  ASSERT_EQ(ba.status, Status::Ok) << ba.message;
  ASSERT_FALSE(ab.contacts.empty());
  ASSERT_FALSE(ba.contacts.empty());
  // The first contact of each order: A above B, so A's normal points up and B's down.
  const Vec3 &n_ab = ab.contacts.front().normal, &n_ba = ba.contacts.front().normal;
  if (labelled_defect(ab) || labelled_defect(ba) || !near_axis(n_ab) || !near_axis(n_ba))
    GTEST_SKIP() << "a labelled defect or a normal far from the axis: the report's business";
  EXPECT_GT(n_ab.z(), 0.0);
  EXPECT_LT(n_ba.z(), 0.0);
}

TEST_P(ContactConformance, TheSameQueryTwiceGivesTheSameAnswer) {
  const auto [a, b] = stacked(-0.1);
  const ContactResult first = backend().contact(a, b), second = backend().contact(a, b);
  ASSERT_EQ(first.status, Status::Ok) << first.message;
  ASSERT_EQ(first.status, second.status);
  ASSERT_FALSE(first.contacts.empty());
  ASSERT_EQ(first.contacts.size(), second.contacts.size());
  for (size_t k = 0; k < first.contacts.size(); ++k) {
    const ContactPoint &x = first.contacts[k], &y = second.contacts[k];
    EXPECT_EQ(x.depth, y.depth) << k;
    EXPECT_TRUE(x.point == y.point) << k;
    EXPECT_TRUE(x.normal == y.normal || (!x.normal.allFinite() && !y.normal.allFinite())) << k;
  }
}

INSTANTIATE_TEST_SUITE_P(EveryContactBackend, ContactConformance,
                         ::testing::ValuesIn(names_with(true)), test_name);

class DynamicsConformance : public ::testing::TestWithParam<std::string> {};

TEST_P(DynamicsConformance, ALoneBodyFallsAsTheClosedFormSays) {
  // A unit cube dropped from rest for 0.1 s at dt = 1 ms, far from anything: z = z0 - g t^2 / 2
  // and v = -g t. Any first-order integrator is off by at most g dt t (semi-implicit Euler by
  // g dt t / 2 in position); that bounds every backend's error.
  WorldDefinition world;
  world.sim.dt = 1e-3;
  world.sim.duration = 0.1;
  world.sim.gravity = Vec3(0.0, 0.0, -9.81);  // a scene's default is none
  world.bodies = {test::box_spec("cube", Vec3::Ones(), Vec3(0.0, 0.0, 10.0))};
  const DynamicsResult r = find_backend(GetParam())->dynamics(world, {});
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_EQ(r.finals.size(), 1u);
  const double g = -world.sim.gravity.z(), t = world.sim.duration;
  const double bound = g * world.sim.dt * t;
  EXPECT_NEAR(r.finals[0].position.z(), 10.0 - 0.5 * g * t * t, bound);
  EXPECT_NEAR(r.finals[0].velocity.z(), -g * t, bound);
  EXPECT_NEAR(r.finals[0].position.x(), 0.0, 1e-12);
  EXPECT_TRUE(r.events.empty()) << r.events.size() << " collision events in free fall";
}

TEST_P(DynamicsConformance, TheSameRunTwiceEndsInTheSameState) {
  // Two cubes meeting head-on, one turned, on a floor: collisions, friction and resting contact.
  // A run is a function of its input: the second run's final state equals the first's, bit for
  // bit (no state kept between runs, no clock or thread order in the result).
  WorldDefinition world;
  world.sim.dt = 1e-3;
  world.sim.duration = 0.3;
  world.sim.gravity = Vec3(0.0, 0.0, -9.81);  // the cubes land on the floor and slide
  world.sim.restitution = 0.5;
  world.sim.friction = 0.4;
  BodySpec floor = test::box_spec("floor", Vec3(10.0, 10.0, 1.0), Vec3(0.0, 0.0, -0.5));
  floor.is_static = true;
  BodySpec a = test::box_spec("A", Vec3::Ones(), Vec3(-1.0, 0.0, 0.55), 1.0,
                              Quat(Eigen::AngleAxisd(0.4, Vec3::UnitZ())));
  BodySpec b = test::box_spec("B", Vec3::Ones(), Vec3(1.0, 0.0, 0.55), 2.0);
  a.velocity = Vec3(3.0, 0.0, 0.0);
  b.velocity = Vec3(-2.0, 0.0, 0.0);
  world.bodies = {floor, a, b};
  const Backend& backend = *find_backend(GetParam());
  const DynamicsResult first = backend.dynamics(world, {}), second = backend.dynamics(world, {});
  ASSERT_EQ(first.status, Status::Ok) << first.message;
  ASSERT_EQ(second.status, Status::Ok) << second.message;
  ASSERT_EQ(first.finals.size(), second.finals.size());
  for (size_t k = 0; k < first.finals.size(); ++k) {
    const BodyFinal &x = first.finals[k], &y = second.finals[k];
    EXPECT_TRUE(x.position == y.position) << x.name;
    EXPECT_TRUE(x.velocity == y.velocity) << x.name;
    EXPECT_TRUE(x.angular_velocity == y.angular_velocity) << x.name;
    EXPECT_TRUE(x.orientation.coeffs() == y.orientation.coeffs()) << x.name;
  }
  EXPECT_EQ(first.events.size(), second.events.size());
  // The premise: the cubes met. Friction alone (mu g = 3.9 m/s^2 for at most 0.3 s) leaves A
  // above 1.8 m/s; only the collision takes it below 1 m/s.
  EXPECT_LT(first.finals[1].velocity.x(), 1.0) << "the cubes never met";
}

TEST_P(DynamicsConformance, ANonFiniteStartIsTheBackendsErrorNeverOkNorACrash) {
  // A NaN velocity (an API caller's, past the scene loader that refuses it): the run is the
  // backend's `error` with a message, in an isolated child as every library run is (DART's own
  // assertion aborts it), never `ok` with NaN states and never this process's crash.
  WorldDefinition world;
  world.sim.dt = 1e-3;
  world.sim.duration = 0.01;
  BodySpec cube = test::box_spec("cube", Vec3::Ones(), Vec3(0.0, 0.0, 1.0));
  cube.velocity = Vec3(std::nan(""), 0.0, 0.0);
  world.bodies = {cube};
  const Backend* backend = find_backend(GetParam());
  const TimedDynamics r = isolated_dynamics(GetParam(), 30.0, [&] {
    return TimedDynamics{backend->dynamics(world, {}), 0.0};
  });
  EXPECT_EQ(r.result.status, Status::Error) << r.result.message;
  EXPECT_FALSE(r.result.message.empty());
}

INSTANTIATE_TEST_SUITE_P(EveryDynamicsBackend, DynamicsConformance,
                         ::testing::ValuesIn(names_with(false)), test_name);

// Distance: two bodies apart across parallel faces are at the gap, with A's point on A's face
// and B's on B's, straight across; the other body order swaps the points; the same query twice
// gives the same answer, bit for bit; an overlapping pair is never given a positive distance.
// Conventions, not accuracy: the tolerance is 1e-6 m, FCL's default distance_tolerance and the
// loosest any registered library states for its distance; a library's rounding of a shape
// (Bullet's box margin, pinned in fair_settings_test) is the report's business, so only poses
// where it cannot show are used here.
std::vector<std::string> names_with_distance() {
  std::vector<std::string> names;
  for (const Backend& b : backends())
    if (b.distance) names.push_back(b.name);
  return names;
}

class DistanceConformance : public ::testing::TestWithParam<std::string> {
 protected:
  const Backend& backend() const { return *find_backend(GetParam()); }
};

constexpr double kDistanceConventionTol = 1e-6;

TEST_P(DistanceConformance, APairApartAcrossParallelFacesIsAtTheGap) {
  for (const double gap : {0.5, 0.01}) {
    const auto [a, b] = stacked(gap);
    const DistanceResult r = backend().distance(a, b);
    ASSERT_EQ(r.status, Status::Ok) << r.message;
    ASSERT_FALSE(r.overlapping) << "gap " << gap;
    EXPECT_NEAR(r.distance, gap, kDistanceConventionTol);
    // A's point on A's bottom face, B's on B's top face, straight across.
    EXPECT_NEAR(r.point_a.z(), 0.5 + gap, kDistanceConventionTol);
    EXPECT_NEAR(r.point_b.z(), 0.5, kDistanceConventionTol);
    EXPECT_LE(exact_point_distance(*a.shape, a.pose(), r.point_a), kDistanceConventionTol);
    EXPECT_LE(exact_point_distance(*b.shape, b.pose(), r.point_b), kDistanceConventionTol);
    EXPECT_NEAR((r.point_a - r.point_b).head<2>().norm(), 0.0, kDistanceConventionTol);
  }
}

// A above B turned by `turn`, its lowest point `gap` above B's top face at (0.2, 0.1): a pose
// whose closest pair is unique when a corner points down.
std::pair<RigidBody, RigidBody> hanging(const Quat& turn, double gap) {
  RigidBody a = test::unit_cube("A", Vec3::Zero(), turn);
  double lowest = 0.0;
  for (const Vec3& v : a.shape->vertices()) lowest = std::min(lowest, (turn * v).z());
  a = test::unit_cube("A", Vec3(0.2, 0.1, 0.5 + gap - lowest), turn);
  return {a, test::unit_cube("B", Vec3::Zero())};
}

TEST_P(DistanceConformance, TheOtherBodyOrderSwapsTheWitnessPoints) {
  // A corner of A straight down (its body diagonal turned onto z, then 20 degrees about z):
  // one closest pair, the corner and the point of B's face below it. The points of both orders
  // agree; each is its own body's.
  const Quat turn = Quat(Eigen::AngleAxisd(0.35, Vec3::UnitZ())) *
                    Quat::FromTwoVectors(Vec3(1, 1, 1).normalized(), Vec3::UnitZ());
  const auto [a, b] = hanging(turn, 0.1);
  const DistanceResult ab = backend().distance(a, b), ba = backend().distance(b, a);
  ASSERT_EQ(ab.status, Status::Ok) << ab.message;
  ASSERT_EQ(ba.status, Status::Ok) << ba.message;
  ASSERT_FALSE(ab.overlapping);
  ASSERT_FALSE(ba.overlapping);
  EXPECT_NEAR(ab.distance, ba.distance, kDistanceConventionTol);
  EXPECT_LE((ab.point_a - ba.point_b).norm(), kDistanceConventionTol);
  EXPECT_LE((ab.point_b - ba.point_a).norm(), kDistanceConventionTol);
  // Which body a point belongs to: A's point is nearer A than B's point is, and B's nearer B
  // (where each point lies exactly is accuracy: MuJoCo's margin contacts give a midpoint and a
  // distance, the report's business).
  EXPECT_LT(exact_point_distance(*a.shape, a.pose(), ab.point_a),
            exact_point_distance(*a.shape, a.pose(), ab.point_b));
  EXPECT_LT(exact_point_distance(*b.shape, b.pose(), ab.point_b),
            exact_point_distance(*b.shape, b.pose(), ab.point_a));
}

TEST_P(DistanceConformance, TheSameQueryTwiceGivesTheSameAnswer) {
  const auto [a, b] = stacked(0.01);
  const DistanceResult first = backend().distance(a, b), second = backend().distance(a, b);
  ASSERT_EQ(first.status, Status::Ok) << first.message;
  EXPECT_EQ(first.status, second.status);
  EXPECT_EQ(first.overlapping, second.overlapping);
  EXPECT_EQ(first.distance, second.distance);
  EXPECT_TRUE(first.point_a == second.point_a);
  EXPECT_TRUE(first.point_b == second.point_b);
}

TEST_P(DistanceConformance, AnOverlappingPairIsNeverGivenAPositiveDistance) {
  const auto [a, b] = stacked(-0.1);
  const DistanceResult r = backend().distance(a, b);
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  // Either the library says it overlaps, or (DART, which clamps at its lower bound of 0) it gives
  // zero; never a gap.
  EXPECT_TRUE(r.overlapping || r.distance <= 0.0) << r.distance;
}

INSTANTIATE_TEST_SUITE_P(EveryDistanceBackend, DistanceConformance,
                         ::testing::ValuesIn(names_with_distance()), test_name);

TEST(Registry, EveryBackendIsNamedInTheContractAndInTheBackendsTable) {
  // docs/contract.md names every backend and docs/backends.md gives each a row: a backend added
  // to the registry without its documentation fails here.
  auto read = [](const std::string& path) {
    std::ifstream in(std::string(RBX_SOURCE_DIR) + "/" + path);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  };
  const std::string contract = read("docs/contract.md"), table = read("docs/backends.md");
  ASSERT_FALSE(contract.empty());
  ASSERT_FALSE(table.empty());
  for (const Backend& b : backends()) {
    EXPECT_NE(contract.find("`" + b.name + "`"), std::string::npos) << b.name;
    EXPECT_NE(table.find("| `" + b.name + "` |"), std::string::npos) << b.name;
  }
}

}  // namespace
}  // namespace rbx
