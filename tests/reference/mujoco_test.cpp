// MuJoCo 2.2.2 adapter: contact conventions, the mesh recentring, the box-box half-depth defect,
// and impacts against hand-derived single-impulse answers.
#include "reference/mujoco.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <set>
#include <utility>

#include "reference/contact_laws.h"
#include "tests/common/fixtures.h"

// LeakSanitizer in the sanitizer build (RBX_SANITIZE, CMakeLists.txt).
#ifdef RBX_SANITIZE
#include <sanitizer/lsan_interface.h>
#endif

namespace rbx {
namespace {

// The backends under test, by their registry names.
const Backend& mujoco = mujoco_adapter().backend("mujoco");
const Backend& mujoco_hull = mujoco_adapter().backend("mujoco-hull");

constexpr double kPi = 3.14159265358979323846;

using test::box_spec;
using test::diagonal_along_x;
using test::pyramid_spec;

// MuJoCo stores mesh vertices as float: coordinates of size 0.5..1 carry ~6e-8 round-off, and
// the compiler's recentring adds a few more float operations; 1e-6 m covers them.
constexpr double kFloatGeometry = 1e-6;

// --- Contact conventions ------------------------------------------------------------------

TEST(MujocoContact, OverlapAlongXGivesNormalFromBTowardA) {
  // Unit cubes, B centred at x = 0.9: the faces x = 0.5 (A) and x = 0.4 (B) overlap by 0.1;
  // pushing A out of B is along -x.
  const RigidBody a = make_body(box_spec("A", Vec3::Ones(), Vec3::Zero()));
  const RigidBody b = make_body(box_spec("B", Vec3::Ones(), Vec3(0.9, 0, 0)));
  const ContactResult r = mujoco_hull.contact(a, b);
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_EQ(r.contacts.size(), 1u);  // mesh-mesh in 2.2.2: MPR, one point
  const ContactPoint& c = r.contacts[0];
  EXPECT_NEAR(c.normal.x(), -1.0, kFloatGeometry);
  EXPECT_NEAR(c.normal.y(), 0.0, kFloatGeometry);
  EXPECT_NEAR(c.normal.z(), 0.0, kFloatGeometry);
  EXPECT_NEAR(c.depth, 0.1, kFloatGeometry);
  // MuJoCo's point is the midpoint between the surfaces: x = (0.4 + 0.5) / 2, somewhere on the
  // 1 x 1 overlap patch (in 2.2.2 a corner of it, not the centre).
  EXPECT_NEAR(c.point.x(), 0.45, kFloatGeometry);
  EXPECT_LE(std::abs(c.point.y()), 0.5 + kFloatGeometry);
  EXPECT_LE(std::abs(c.point.z()), 0.5 + kFloatGeometry);
}

TEST(MujocoContact, SwappingTheBodiesFlipsTheNormal) {
  // Same pair as above with B first: now B is pushed out of A along +x; same depth.
  const RigidBody a = make_body(box_spec("A", Vec3::Ones(), Vec3::Zero()));
  const RigidBody b = make_body(box_spec("B", Vec3::Ones(), Vec3(0.9, 0, 0)));
  const ContactResult r = mujoco_hull.contact(b, a);
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_EQ(r.contacts.size(), 1u);
  EXPECT_NEAR(r.contacts[0].normal.x(), 1.0, kFloatGeometry);
  EXPECT_NEAR(r.contacts[0].normal.y(), 0.0, kFloatGeometry);
  EXPECT_NEAR(r.contacts[0].depth, 0.1, kFloatGeometry);
  EXPECT_NEAR(r.contacts[0].point.x(), 0.45, kFloatGeometry);
}

TEST(MujocoContact, RotatedPairGivesWorldFrameNormal) {
  // Both cubes turned by 0.3 rad about z, B at q * (0.9, 0.2, 0.1): in A's frame this is the
  // overlap above (0.1 along A's x, the y and z offsets leave the faces overlapping), so the
  // world normal is q * (-1, 0, 0) = (-cos 0.3, -sin 0.3, 0) and the depth 0.1.
  const Quat q(Eigen::AngleAxisd(0.3, Vec3::UnitZ()));
  const RigidBody a = make_body(box_spec("A", Vec3::Ones(), Vec3::Zero(), 1.0, q));
  const RigidBody b = make_body(box_spec("B", Vec3::Ones(), q * Vec3(0.9, 0.2, 0.1), 1.0, q));
  const ContactResult r = mujoco_hull.contact(a, b);
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_EQ(r.contacts.size(), 1u);
  EXPECT_NEAR(r.contacts[0].normal.x(), -std::cos(0.3), kFloatGeometry);
  EXPECT_NEAR(r.contacts[0].normal.y(), -std::sin(0.3), kFloatGeometry);
  EXPECT_NEAR(r.contacts[0].normal.z(), 0.0, kFloatGeometry);
  EXPECT_NEAR(r.contacts[0].depth, 0.1, kFloatGeometry);
}

TEST(MujocoContact, TouchingAndSeparatedPairs) {
  const RigidBody a = make_body(box_spec("A", Vec3::Ones(), Vec3::Zero()));
  // Faces exactly touching (B at x = 1): no penetration; a zero-depth contact would be allowed.
  const ContactResult touching =
      mujoco_hull.contact(a, make_body(box_spec("B", Vec3::Ones(), Vec3(1, 0, 0))));
  ASSERT_EQ(touching.status, Status::Ok) << touching.message;
  for (const ContactPoint& c : touching.contacts) EXPECT_LE(c.depth, kFloatGeometry);
  // 1 mm apart: nothing.
  const ContactResult apart =
      mujoco_hull.contact(a, make_body(box_spec("B", Vec3::Ones(), Vec3(1.001, 0, 0))));
  ASSERT_EQ(apart.status, Status::Ok) << apart.message;
  EXPECT_TRUE(apart.contacts.empty());
}

TEST(MujocoContact, RecentredMeshStaysOnOurPose) {
  // A square pyramid under the seed's vertex mass model has its centre of mass at the vertex
  // average, z = 1/5 above the base, while MuJoCo recentres the mesh on its volume centroid,
  // z = 1/4. Turned 30 deg about z with its base at z = 0, on a 2 x 2 x 1 box whose top is at
  // z = 0.02: the base sinks 0.02 into the box top (the base's corners reach sqrt(2)/2 < 1 from
  // the axis, inside the top face), so the contact is (0, 0, 1) from the box toward the
  // pyramid with depth 0.02. An uncompensated 0.05 shift would change the depth.
  BodySpec p = pyramid_spec("P", Vec3::Zero(), Quat(Eigen::AngleAxisd(M_PI / 6, Vec3::UnitZ())));
  p.mass_model = MassModel::Vertices;
  const RigidBody pyramid = make_body(p);
  ASSERT_NEAR(pyramid.position.z(), 0.2, 1e-12);  // our centre of mass
  const RigidBody table = make_body(box_spec("T", Vec3(2, 2, 1), Vec3(0, 0, -0.48)));
  const ContactResult r = mujoco_hull.contact(pyramid, table);
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_EQ(r.contacts.size(), 1u);
  EXPECT_NEAR(r.contacts[0].normal.z(), 1.0, kFloatGeometry);
  EXPECT_NEAR(r.contacts[0].depth, 0.02, kFloatGeometry);
  // Between the two surfaces z = 0 and z = 0.02, over the pyramid's base. (MuJoCo documents
  // the point as the midpoint; its MPR point is an average of portal support points, which
  // here lands at z = 0.02/3, not 0.01.)
  EXPECT_GE(r.contacts[0].point.z(), -kFloatGeometry);
  EXPECT_LE(r.contacts[0].point.z(), 0.02 + kFloatGeometry);
  EXPECT_LE(r.contacts[0].point.head<2>().norm(), std::sqrt(0.5) + kFloatGeometry);
}

// --- Known wrong answer: MPR on a small cube at a big cube's corner (FCL issue 545) ----------

// docs/references.md and scenes/contact/small_on_diagonal.toml: a 0.1 cube B centred at (0.4, 0.4,
// 0.4) inside the unit cube A at the origin. B spans [0.35, 0.45]^3; the least translation that
// frees it is 0.15 along an axis (0.5 - 0.35; a three-way tie), so the truth is depth 0.15 with
// an axis normal. MuJoCo 2.2.2 runs libccd's MPR on mesh geoms with the geom centres as the
// interior point: the ray from c_A - c_B = -(0.4, 0.4, 0.4) through the origin leaves the
// Minkowski difference (the cube of half-extent 0.55 about -(0.4, 0.4, 0.4)) exactly at its
// corner (0.15, 0.15, 0.15): the diagonal, at distance 0.15 sqrt(3) ~ 0.2598.
RigidBody diagonal_big() { return make_body(box_spec("A", Vec3::Ones(), Vec3::Zero())); }
RigidBody diagonal_small(const Vec3& centre) {
  return make_body(box_spec("B", Vec3::Constant(0.1), centre));
}

TEST(MujocoKnownWrongAnswer, SmallCubeOnTheDiagonalPinned) {
  // Pinned as the adapter returns it. Ours: normal from B toward A = -(1, 1, 1)/sqrt(3) (MuJoCo's
  // frame, geom1 -> geom2, is the diagonal toward the small cube), depth 0.15 sqrt(3). MuJoCo
  // stores the vertices as float (0.05 -> 0.0500000007), hence kFloatGeometry.
  const ContactResult r = mujoco_hull.contact(diagonal_big(), diagonal_small(Vec3::Constant(0.4)));
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_EQ(r.contacts.size(), 1u);
  const ContactPoint& c = r.contacts[0];
  EXPECT_NEAR((c.normal + Vec3::Ones().normalized()).norm(), 0.0, kFloatGeometry)
      << c.normal.transpose();
  EXPECT_NEAR(c.depth, 0.15 * std::sqrt(3.0), kFloatGeometry);
  // Against the truth (an axis, 0.15): 54.7 deg off and sqrt(3) too deep.
  EXPECT_GT(c.depth - 0.15, 0.1);
  // Swapped (the scene's order, small cube first): the same wrong answer, flipped.
  const ContactResult swapped =
      mujoco_hull.contact(diagonal_small(Vec3::Constant(0.4)), diagonal_big());
  ASSERT_EQ(swapped.status, Status::Ok) << swapped.message;
  ASSERT_EQ(swapped.contacts.size(), 1u);
  EXPECT_NEAR((swapped.contacts[0].normal - Vec3::Ones().normalized()).norm(), 0.0, kFloatGeometry)
      << swapped.contacts[0].normal.transpose();
  EXPECT_NEAR(swapped.contacts[0].depth, 0.15 * std::sqrt(3.0), kFloatGeometry);
}

TEST(MujocoKnownWrongAnswer, SmallCubeNearTheDiagonalPinned) {
  // scenes/contact/small_near_diagonal.toml: the small cube at (0.4, 0.39, 0.39), first. Truth:
  // it spans x in [0.35, 0.45], y and z in [0.34, 0.44]; out along +x costs 0.15, along +y or
  // +z 0.16: unique answer n = (1, 0, 0) (from the big cube toward the small one), depth 0.15.
  // Measured, not derived (MPR's final portal is not a face of the Minkowski difference here):
  // MuJoCo answers n = (2.5, 1, 1)/sqrt(8.25) = (0.87039, 0.34816, 0.34816), 29.5 deg off the
  // axis, and depth 0.172337, which is not even the overlap along its own normal (0.242: the
  // small cube's lowest point along n is 0.541 and the big cube's highest 0.783): the depth is
  // the distance to the last portal's plane. Float vertices: kFloatGeometry.
  const double n_long = 2.5 / std::sqrt(8.25), n_short = 1.0 / std::sqrt(8.25);
  const double measured_depth = 0.17233688105783818;
  for (bool swapped : {false, true}) {
    const RigidBody small = diagonal_small(Vec3(0.4, 0.39, 0.39));
    const ContactResult r = swapped ? mujoco_hull.contact(diagonal_big(), small)
                                    : mujoco_hull.contact(small, diagonal_big());
    ASSERT_EQ(r.status, Status::Ok) << r.message;
    ASSERT_EQ(r.contacts.size(), 1u);
    const ContactPoint& c = r.contacts[0];
    const double sign = swapped ? -1.0 : 1.0;  // ours points toward the first body
    EXPECT_NEAR((c.normal - sign * Vec3(n_long, n_short, n_short)).norm(), 0.0, kFloatGeometry)
        << c.normal.transpose();
    EXPECT_NEAR(c.depth, measured_depth, kFloatGeometry);
    // Clearly not the truth (+-x, 0.15).
    EXPECT_GT(std::abs(c.depth - 0.15), 0.02);
    EXPECT_LT(std::abs(c.normal.x()), 0.9);
  }
}

// --- Known defect: box-box half depth -------------------------------------------------------

// Loads MJCF text through MuJoCo's virtual file system.
mjModel* load_mjcf(const char* xml) {
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const int n = static_cast<int>(std::strlen(xml));
  if (mj_makeEmptyFileVFS(vfs.get(), "pin.xml", n) != 0) return nullptr;
  std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), "pin.xml")], xml, n);
  char error[512] = "";
  mjModel* m = mj_loadXML("pin.xml", vfs.get(), error, sizeof(error));
  mj_deleteVFS(vfs.get());
  return m;
}

TEST(MujocoKnownDefect, BoxBoxReportsHalfTheDepth) {
  // Two unit box geoms (primitive type "box", not meshes) overlapping 0.1 along x, as in
  // OverlapAlongX. The true depth is 0.1; MuJoCo 2.2.2's box-box collider reports
  // dist = -0.05 (fixed upstream much later). This test pins the defect: if it fails, the
  // library changed and docs/references.md must be updated. The adapter uses mesh geoms, which get
  // 0.1 (OverlapAlongXGivesNormalFromBTowardA).
  mjModel* m = load_mjcf(R"(<mujoco><worldbody>
      <body pos="0 0 0"><freejoint/><geom type="box" size="0.5 0.5 0.5"/></body>
      <body pos="0.9 0 0"><freejoint/><geom type="box" size="0.5 0.5 0.5"/></body>
      </worldbody></mujoco>)");
  ASSERT_NE(m, nullptr);
  mjData* d = mj_makeData(m);
  mj_forward(m, d);
  ASSERT_GE(d->ncon, 1);
  for (int i = 0; i < d->ncon; ++i) {
    // Box geoms are stored in double: only round-off separates the answer from 0.05.
    EXPECT_NEAR(-d->contact[i].dist, 0.05, 1e-12) << "contact " << i;
    EXPECT_NEAR(std::abs(d->contact[i].frame[0]), 1.0, 1e-12);
  }
  mj_deleteData(d);
  mj_deleteModel(m);
}

TEST(MujocoKnownDefect, BoxBoxAddsAPointAtTheBigBoxsCorner) {
  // A 0.97 x 0.87 x 1.01 box 1 mm deep on a 4 x 4 x 1 box, both free bodies, the small one
  // first (as rbx's contact queries build them), as box geoms. Beside the small box's four
  // corners (at half the depth, BoxBoxReportsHalfTheDepth), MuJoCo 2.2.2's box-box collider
  // returns a fifth point at the big box's corner (-2, -2), 2 m outside the small box, at the
  // same depth and normal (with the big box first, or a world geom, the four corners only). Pinned:
  // if it fails, the library changed and docs/references.md with it.
  mjModel* m = load_mjcf(R"(<mujoco><worldbody>
      <body pos="0 0 0.504"><freejoint/><geom type="box" size="0.485 0.435 0.505"/></body>
      <body pos="0 0 -0.5"><freejoint/><geom type="box" size="2 2 0.5"/></body>
      </worldbody></mujoco>)");
  ASSERT_NE(m, nullptr);
  mjData* d = mj_makeData(m);
  mj_forward(m, d);
  int inside = 0, at_corner = 0;
  for (int i = 0; i < d->ncon; ++i) {
    const mjtNum* p = d->contact[i].pos;
    // Box geoms are stored in double: round-off only.
    if (std::abs(p[0]) <= 0.485 + 1e-12 && std::abs(p[1]) <= 0.435 + 1e-12) ++inside;
    if (std::abs(p[0] + 2) < 1e-12 && std::abs(p[1] + 2) < 1e-12) ++at_corner;
    EXPECT_NEAR(-d->contact[i].dist, 0.0005, 1e-12) << "contact " << i;
  }
  EXPECT_EQ(inside, 4);
  EXPECT_EQ(at_corner, 1);
  EXPECT_EQ(d->ncon, 5);
  mj_deleteData(d);
  mj_deleteModel(m);
}

TEST(MujocoKnownDefect, BoxBoxReturnsMetresDeepPointsUnderABoxAt45Degrees) {
  // rbx explore --kind landing --seed 2718, sample 222 shrunk: a 0.97 x 0.87 x 1.01 box turned
  // 45 deg about z lands flat at 1 m/s on a static 4 x 4 x 1 floor, e = 0, mu = 0.5, and rests
  // 0.26 mm deep (half-depth points). At step 101 MuJoCo 2.2.2's box-box collider returns,
  // beside the four corners, three points 2.3 to 2.8 m deep (no such overlap exists: the box is
  // 1.01 m tall), and the box leaves at some 76 m/s. Pinned through the adapter's contact-law
  // record (the penetration law's worst is the deepest point MuJoCo reported); the same box
  // unturned stays at rest.
  WorldDefinition s;
  s.sim.duration = 0.103;
  s.sim.gravity = Vec3(0, 0, -9.81);
  s.sim.restitution = 0;
  s.sim.friction = 0.5;
  const auto landing = [&](double yaw_deg) {
    BodySpec floor = box_spec("floor", Vec3(4, 4, 1), Vec3(0, 0, -0.5));
    floor.is_static = true;
    BodySpec box = box_spec("box", Vec3(0.97, 0.87, 1.01), Vec3(0, 0, 0.50753065625), 1.0,
                            Quat(Eigen::AngleAxisd(yaw_deg * kPi / 180, Vec3::UnitZ())));
    box.velocity = Vec3(0, 0, -1);
    s.bodies = {box, floor};
    return mujoco.dynamics(s, {});
  };
  const DynamicsResult turned = landing(45);
  ASSERT_EQ(turned.status, Status::Ok) << turned.message;
  ASSERT_TRUE(turned.laws.measured);
  EXPECT_GT(turned.laws.residuals[static_cast<int>(Law::Penetration)].worst, 2.0);
  EXPECT_GT(turned.finals[0].velocity.norm(), 10.0);
  const DynamicsResult straight = landing(0);
  ASSERT_EQ(straight.status, Status::Ok) << straight.message;
  EXPECT_LT(straight.laws.residuals[static_cast<int>(Law::Penetration)].worst, 1e-3);
  EXPECT_LT(straight.finals[0].velocity.norm(), 0.01);
}

TEST(MujocoKnownDefect, ASlidingBoxLeavesItsSurfaceAtMuTimesItsSlip) {
  // rbx explore --kind slide --seed 8086, sample 18 shrunk: a 0.4 x 0.8 x 0.3 box resting on a
  // 30 deg incline, mu = 0.9, launched up the fall line at 1 m/s. Coulomb's law slows it along
  // the surface; MuJoCo's convex contact model (the cone relaxation Anitescu's model shares)
  // lets the contact leave at a normal speed of mu times the slip: after its first contact step
  // the box moves off the surface at 0.485 m/s while it slips at 0.539 m/s, and it flies
  // centimetres before it lands. Each of the two steps adds g dt = 0.0098 m/s of gravity, the
  // tolerance here.
  constexpr double theta = 30 * kPi / 180, mu = 0.9, dt = 1e-3;
  const Quat tilt(Eigen::AngleAxisd(theta, Vec3::UnitY()));
  const Vec3 n = tilt * Vec3::UnitZ(), up = -(tilt * Vec3::UnitX());
  WorldDefinition s;
  s.sim.dt = dt;
  s.sim.duration = 2 * dt;
  s.sim.gravity = Vec3(0, 0, -9.81);
  s.sim.restitution = 0;
  s.sim.friction = mu;
  BodySpec incline = box_spec("incline", Vec3(4, 4, 1), -0.5 * n, 1.0, tilt);
  incline.is_static = true;
  BodySpec box = box_spec("box", Vec3(0.4, 0.8, 0.3), 0.15 * n, 1.0, tilt);
  box.velocity = up;
  s.bodies = {box, incline};
  const DynamicsResult r = mujoco.dynamics(s, {});
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  const Vec3 v = r.finals[0].velocity;
  const double normal = v.dot(n), slip = (v - normal * n).norm();
  EXPECT_GT(normal, 0.4);  // away from the surface
  EXPECT_NEAR(normal, mu * slip, 9.81 * dt);
}

// --- Errors: mju_error becomes Status::Error -------------------------------------------------

// An allocator for MuJoCo (mju_user_malloc / mju_user_free) that counts its calls and fails
// the `fail_at`-th (1-based; 0: never): every MuJoCo allocation goes through mju_malloc, which
// calls mju_error("Could not allocate memory") when it gets nullptr. Blocks are 64-byte
// aligned as MuJoCo's own (2.2.2 checks its buffer layout against that alignment; plain
// malloc gave "mjModel buffer size mismatch") and come from aligned_alloc, so MuJoCo's default
// free can release them after the hooks are gone.
//
// Leaks: the longjmp out of a failed mj_makeData abandons its partial mjData, which the
// destructor frees (the sanitizer build checks for leaks). It must not free what MuJoCo itself
// keeps from one mj_loadXML to the next (freed by the next load: freeing it here was a double
// free): those are the blocks a clean query leaves live, identified by their call number.
struct FailingAllocator {
  static long calls, fail_at;
  static std::map<void*, long>* live;  // block -> number of the call that allocated it
  static void* allocate(size_t n) {
    if (++calls == fail_at) return nullptr;
    void* p = std::aligned_alloc(64, (n + 63) / 64 * 64);
    if (p) (*live)[p] = calls;
    return p;
  }
  static void release(void* p) {
    live->erase(p);
    std::free(p);
  }
  // Installs the hooks until destruction; `kept` are the call numbers whose blocks MuJoCo keeps
  // after a clean query.
  FailingAllocator(long fail, std::set<long> kept) : kept_by_mujoco(std::move(kept)) {
    calls = 0;
    fail_at = fail;
    live = &blocks;
    mju_user_malloc = allocate;
    mju_user_free = release;
  }
  ~FailingAllocator() {
    mju_user_malloc = nullptr;
    mju_user_free = nullptr;
    for (const auto& [p, call] : blocks)
      if (!kept_by_mujoco.count(call)) std::free(p);
  }
  std::map<void*, long> blocks;
  std::set<long> kept_by_mujoco;
};
long FailingAllocator::calls = 0;
long FailingAllocator::fail_at = 0;
std::map<void*, long>* FailingAllocator::live = nullptr;

// A clean contact query under the counting allocator: how many allocations it makes (model
// compile, mjData) and which of them MuJoCo keeps afterwards.
struct AllocationProfile {
  long calls = 0;
  std::set<long> kept;
};
AllocationProfile profile_contact_query(const RigidBody& a, const RigidBody& b) {
  AllocationProfile out;
  std::set<long> all;  // keep everything: nothing is freed after a clean query
  for (long k = 1; k <= 1000; ++k) all.insert(k);
  FailingAllocator count(0, all);
  EXPECT_EQ(mujoco_hull.contact(a, b).status, Status::Ok);
  out.calls = FailingAllocator::calls;
  for (const auto& [p, call] : count.blocks) out.kept.insert(call);
  return out;
}

TEST(MujocoErrors, MjuErrorInMakeDataIsAStatusErrorWithItsMessage) {
  // A real mju_error on the adapter's own guarded path: the last allocation of a contact query
  // is mj_makeData's (after mj_loadXML, whose compiler catches its own errors), and it fails.
  // MuJoCo calls mju_error("Could not allocate memory"), which by default exits the process;
  // the adapter's mju_user_error handler must jump back and return status Error with the
  // message, and the next query must work.
  const RigidBody a = make_body(box_spec("A", Vec3::Ones(), Vec3::Zero()));
  const RigidBody b = make_body(box_spec("B", Vec3::Ones(), Vec3(0.9, 0, 0)));
  const AllocationProfile clean = profile_contact_query(a, b);
  const long n = clean.calls;
  ASSERT_GT(n, 2);
  ASSERT_LT(n, 1000);
  {
    FailingAllocator fail_last(n, clean.kept);
    const ContactResult r = mujoco_hull.contact(a, b);
    EXPECT_EQ(FailingAllocator::calls, n);  // it did reach the failing allocation
    EXPECT_EQ(r.status, Status::Error);
    EXPECT_EQ(r.message, "MuJoCo mj_makeData: Could not allocate memory");
    EXPECT_TRUE(r.contacts.empty());
  }
  // Still alive, and MuJoCo still answers (the face pair above: one contact, depth 0.1).
  const ContactResult again = mujoco_hull.contact(a, b);
  ASSERT_EQ(again.status, Status::Ok) << again.message;
  ASSERT_EQ(again.contacts.size(), 1u);
  EXPECT_NEAR(again.contacts[0].depth, 0.1, kFloatGeometry);
}

TEST(MujocoErrors, EveryFailedAllocationIsAStatusError) {
  // Each of the query's allocations failed in turn: every one must come back as status Error
  // naming the failure, whether it happens in the VFS, inside the compiler (reported through
  // mj_loadXML's error buffer) or in mj_makeData (through the adapter's handler). Before the
  // VFS call was guarded, failing the first allocation ended the process ("MuJoCo error outside
  // a guarded call").
  const RigidBody a = make_body(box_spec("A", Vec3::Ones(), Vec3::Zero()));
  const RigidBody b = make_body(box_spec("B", Vec3::Ones(), Vec3(0.9, 0, 0)));
  const AllocationProfile clean = profile_contact_query(a, b);
  const long n = clean.calls;
  ASSERT_LT(n, 1000);
  int through_compiler = 0, through_handler = 0;
#ifdef RBX_SANITIZE
  // When a failed allocation makes MuJoCo's compiler give up inside its convex-hull step, the
  // Qhull state it had set up (qh_memsetup, plain malloc, outside mju_user_malloc) is abandoned:
  // MuJoCo's leak on an error path this test provokes on purpose, about 130 KB per failure. Not
  // ours to free (we never see those blocks), so LeakSanitizer ignores what this loop allocates.
  __lsan::ScopedDisabler lsan_off;
#endif
  for (long k = 1; k <= n; ++k) {
    FailingAllocator fail(k, clean.kept);
    const ContactResult r = mujoco_hull.contact(a, b);
    EXPECT_EQ(r.status, Status::Error) << "allocation " << k;
    EXPECT_NE(r.message.find("Could not allocate memory"), std::string::npos)
        << "allocation " << k << ": " << r.message;
    if (r.message.rfind("MuJoCo mj_loadXML", 0) == 0) ++through_compiler;
    if (r.message.rfind("MuJoCo mj_makeData", 0) == 0 ||
        r.message.rfind("MuJoCo mj_makeEmptyFileVFS", 0) == 0)
      ++through_handler;
  }
  EXPECT_EQ(through_compiler + through_handler, n);
  EXPECT_GT(through_compiler, 0);
  EXPECT_GT(through_handler, 1);  // the VFS file and at least one of mj_makeData's
}

// --- Dynamics -------------------------------------------------------------------------------

// Head-on scene: A (m1 = 1, diagonal along x) at v1 = +1, B (m2 = 3, axis-aligned) at v2 = -1.
// A's leading vertex starts `gap` short of B's face at x = 0.
WorldDefinition head_on(double restitution, double gap, double dt) {
  WorldDefinition s;
  s.sim.dt = dt;
  s.sim.duration = 0.1;  // the soft contact lasts ~25 steps = 25 ms
  s.sim.restitution = restitution;
  s.bodies.push_back(
      box_spec("A", Vec3::Ones(), Vec3(-std::sqrt(3.0) / 2 - gap, 0, 0), 1.0, diagonal_along_x()));
  s.bodies.back().velocity = Vec3(1, 0, 0);
  s.bodies.push_back(box_spec("B", Vec3::Ones(), Vec3(0.5, 0, 0), 3.0));
  s.bodies.back().velocity = Vec3(-1, 0, 0);
  return s;
}

// 1-D closed form: v1' = (m1 v1 + m2 v2 + m2 e (v2 - v1)) / (m1 + m2),
// v2' = (m1 v1 + m2 v2 + m1 e (v1 - v2)) / (m1 + m2); with m1 = 1, m2 = 3, v1 = 1, v2 = -1:
// e = 0.5: v1' = (-2 - 3) / 4 = -1.25, v2' = (-2 + 1) / 4 = -0.25;
// e = 1:   v1' = (-2 - 6) / 4 = -2,    v2' = (-2 + 2) / 4 = 0.
// The impulse is j = (1 + e) m1 m2 / (m1 + m2) |v1 - v2| = (1 + e) * 0.75 * 2.
struct HeadOnAnswer {
  double e, v1, v2, impulse;
};
constexpr HeadOnAnswer kHeadOn[] = {{0.5, -1.25, -0.25, 2.25}, {1.0, -2.0, 0.0, 3.0}};

TEST(MujocoDynamics, HeadOnImpactAtTheCalibratedEntryPhase) {
  // Closing speed 2 m/s, dt = 1 ms: a gap of 3 mm leaves the vertex 1 mm = half a step's travel
  // inside B at the first step that sees the contact: entry phase 1/2, the phase the damping is
  // calibrated at. The remaining model error is the impedance d = 0.9999 (the solver reaches
  // aref to 1e-4 relative), so velocities and impulse agree to 1e-4.
  for (const HeadOnAnswer& want : kHeadOn) {
    const DynamicsResult r = mujoco_hull.dynamics(head_on(want.e, 0.003, 1e-3), {});
    ASSERT_EQ(r.status, Status::Ok) << r.message;
    ASSERT_EQ(r.finals.size(), 2u);
    EXPECT_NEAR(r.finals[0].velocity.x(), want.v1, 1e-4) << "e = " << want.e;
    EXPECT_NEAR(r.finals[1].velocity.x(), want.v2, 1e-4) << "e = " << want.e;
    // Momentum 1*1 + 3*(-1) = -2 is conserved to round-off (equal and opposite forces).
    EXPECT_NEAR(r.finals[0].velocity.x() + 3.0 * r.finals[1].velocity.x(), -2.0, 1e-9);
    // No lever arm: no spin (round-off only).
    EXPECT_LT(r.finals[0].angular_velocity.norm(), 1e-9);
    // One collision event (one contact episode), B -> A normal along -x.
    ASSERT_EQ(r.events.size(), 1u);
    EXPECT_EQ(r.events[0].body_a, "A");
    EXPECT_EQ(r.events[0].body_b, "B");
    EXPECT_NEAR(r.events[0].contact.normal.x(), -1.0, kFloatGeometry);
    EXPECT_NEAR(r.events[0].impulse, want.impulse, 1e-4);  // = momentum change of A
  }
}

TEST(MujocoDynamics, HeadOnImpactAtAnotherEntryPhase) {
  // Gap 4 mm - 1 um: the vertex is only 1 um inside when the contact is first seen (phase
  // ~0). The adapter's recursion (mujoco.cpp, soft_contact_restitution) puts e between 0.485
  // and 0.517 over entry phases 0..1 for a target of 0.5, so |e - 0.5| <= 0.018 and the
  // velocities move by at most m2/(m1+m2) |de| |v1 - v2| = 0.75 * 0.018 * 2 = 0.027 (A) and
  // m1/(m1+m2) |de| 2 = 0.009 (B). This is the price of detecting contact at step starts.
  const DynamicsResult r = mujoco_hull.dynamics(head_on(0.5, 0.004 - 1e-6, 1e-3), {});
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  EXPECT_NEAR(r.finals[0].velocity.x(), -1.25, 0.027);
  EXPECT_NEAR(r.finals[1].velocity.x(), -0.25, 0.009);
  EXPECT_NEAR(r.finals[0].velocity.x() + 3.0 * r.finals[1].velocity.x(), -2.0, 1e-9);
}

TEST(MujocoDynamics, CubeCornerOnStaticSlab) {
  // Unit cube (m = 1, solid: I = m/6 * 1, the same in every orientation), rotated 45 deg about
  // x then 10 deg about y, falling at 1 m/s onto a static slab; no gravity, e = 0.5.
  // Lowest vertex: local (0.5, -0.5, -0.5) -> Rx(45): (0.5, 0, -sqrt(2)/2) -> Ry(10):
  //   r = (0.5 cos10 - sqrt(2)/2 sin10, 0, -0.5 sin10 - sqrt(2)/2 cos10) = (0.36962, 0, -0.78319)
  // (its neighbour (-0.5, -0.5, -0.5) ends 0.17 m higher, so one vertex strikes).
  // Single impulse along n = (0, 0, 1) at r: r x n = (0, -r_x, 0),
  //   j = -(1 + e) v_n / (1/m + (r x n) . 6/m (r x n)) = 1.5 / (1 + 6 r_x^2),
  //   v' = (0, 0, -1 + j),  w' = 6 j (r x n) = (0, -6 r_x j, 0).
  const double deg = M_PI / 180.0;
  const double rx = 0.5 * std::cos(10 * deg) - std::sqrt(0.5) * std::sin(10 * deg);
  const double rz = -0.5 * std::sin(10 * deg) - std::sqrt(0.5) * std::cos(10 * deg);
  const double e = 0.5;
  const double j = (1 + e) / (1 + 6 * rx * rx);
  // dt = 0.1 ms; the slab top 0.15 mm below the vertex: entry phase 1/2 (see above).
  const double dt = 1e-4;
  WorldDefinition s;
  s.sim.dt = dt;
  s.sim.duration = 0.006;  // contact ~2.5 ms; the next vertex is still 0.17 m up
  s.sim.restitution = e;
  s.bodies.push_back(box_spec("cube", Vec3::Ones(), Vec3::Zero(), 1.0,
                              Quat(rotation_from_euler_deg(Vec3(45, 10, 0)))));
  s.bodies.back().velocity = Vec3(0, 0, -1);
  s.bodies.push_back(box_spec("slab", Vec3(4, 4, 1), Vec3(0, 0, rz - 0.5 - 1.5 * dt)));
  s.bodies.back().is_static = true;
  const DynamicsResult r = mujoco_hull.dynamics(s, {});
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  // Tolerance: a soft contact is not an instantaneous impulse. Over its ~25 steps (2.5 ms) the
  // cube turns by about |w'| T / 2 = 1.8 * 2.5e-3 / 2 = 2.3e-3 rad, moving the lever r_x by
  // |r_z| * 2.3e-3 = 1.8e-3 (0.5%); that shifts j by ~0.45% (3.7e-3 N s), v_z by as much and
  // w_y by 6 (r_x dj + j dr_x) ~ 1.7e-2. We allow 5e-3 m/s and 2e-2 rad/s.
  EXPECT_NEAR(r.finals[0].velocity.z(), -1 + j, 5e-3);
  EXPECT_NEAR(r.finals[0].angular_velocity.y(), -6 * rx * j, 2e-2);
  EXPECT_NEAR(r.finals[0].velocity.x(), 0.0, 1e-9);
  EXPECT_NEAR(r.finals[0].angular_velocity.x(), 0.0, 1e-6);
  // The static slab is a world geom: its pose is unchanged and it never moves.
  EXPECT_EQ(r.finals[1].velocity, Vec3::Zero());
  EXPECT_NEAR(r.finals[1].position.z(), rz - 0.5 - 1.5 * dt, 1e-15);
}

TEST(MujocoDynamics, FreeRotationStaysInTheWorldFrame) {
  // A cube has isotropic inertia, so Euler's equations give a constant world angular velocity
  // and the orientation q(t) = exp(w t) q0. MuJoCo's free joint keeps w in the body frame: a
  // missing conversion would show here, since the cube starts turned.
  const Vec3 w(1, 2, 3);  // rad/s, world
  const Quat q0(Eigen::AngleAxisd(0.7, Vec3(1, -2, 0.5).normalized()));
  WorldDefinition s;
  s.sim.dt = 1e-3;
  s.sim.duration = 0.1;
  s.bodies.push_back(box_spec("A", Vec3::Ones(), Vec3::Zero(), 1.0, q0));
  s.bodies.back().angular_velocity = w;
  const DynamicsResult r = mujoco_hull.dynamics(s, {});
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  // Round-off over 100 steps of an exact quaternion update.
  EXPECT_LT((r.finals[0].angular_velocity - w).norm(), 1e-9);
  const Quat expect = Quat(Eigen::AngleAxisd(w.norm() * 0.1, w.normalized())) * q0;
  EXPECT_LT(std::abs(std::abs(expect.dot(r.finals[0].orientation)) - 1.0), 1e-9);
}

TEST(MujocoDynamics, FreeFallSamples) {
  // Semi-implicit Euler from rest: v_n = g n dt, x_n = x0 + g dt^2 n (n + 1) / 2 exactly (up to
  // round-off). Samples every 10 steps over 100 steps: t = 0, 0.01, ..., 0.1 (11 samples).
  const double g = -9.81, dt = 1e-3;
  WorldDefinition s;
  s.sim.dt = dt;
  s.sim.duration = 0.1;
  s.sim.gravity = Vec3(0, 0, g);
  s.bodies.push_back(box_spec("A", Vec3::Ones(), Vec3(0, 0, 5)));
  DynamicsOptions opt;
  opt.sample_every = 10;
  const DynamicsResult r = mujoco_hull.dynamics(s, opt);
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_EQ(r.samples.size(), 11u);
  for (size_t k = 0; k < r.samples.size(); ++k) {
    const double n = 10.0 * k;
    EXPECT_NEAR(r.samples[k].time, n * dt, 1e-12);
    EXPECT_NEAR(r.samples[k].bodies[0].velocity.z(), g * n * dt, 1e-12);
    EXPECT_NEAR(r.samples[k].bodies[0].position.z(), 5 + g * dt * dt * n * (n + 1) / 2, 1e-12);
  }
  EXPECT_NEAR(r.finals[0].velocity.z(), g * 0.1, 1e-12);
}

TEST(MujocoDynamics, NonFiniteStateIsAnError) {
  // MuJoCo warns about a NaN velocity and silently resets the state; the adapter must say so.
  WorldDefinition s;
  s.sim.duration = 0.01;
  s.bodies.push_back(box_spec("A", Vec3::Ones(), Vec3::Zero()));
  s.bodies.back().velocity = Vec3(std::nan(""), 0, 0);
  const DynamicsResult r = mujoco_hull.dynamics(s, {});
  EXPECT_EQ(r.status, Status::Error);
  EXPECT_NE(r.message.find("MuJoCo"), std::string::npos) << r.message;
}

}  // namespace
}  // namespace rbx
