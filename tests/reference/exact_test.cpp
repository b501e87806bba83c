// Tests of the exact SAT oracle (reference/exact): closed-form cases derived by hand, FCL's
// public box-box cases re-derived, and a randomised check of its invariants against an
// independent brute-force separating-axis test over every triangle normal and every edge pair.
//
// Manifold convention under test (reference/exact.cpp): clipped incident points are reported
// midway between the incident surface and the reference plane; an edge-edge point is the
// midpoint of the closest points of the two edges.
#include "reference/exact.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "tests/common/fixtures.h"

namespace rbx {
namespace {

using test::random_rotation;

using test::cube_symmetries;

// Round-off bound for closed-form cases at unit scale: rotations from quaternions and
// projections carry a few 1e-16; 1e-12 leaves a margin of ~1000 and still catches any
// geometric mistake (the smallest features in these cases are 1e-2).
constexpr double kRoundOff = 1e-12;

// Largest deviations from the closed forms seen by this file (printed at the end).
struct Precision {
  double depth = 0.0, normal = 0.0, point = 0.0, swap_depth = 0.0, swap_normal = 0.0;
  double swap_points = 0.0;
  double random_depth_vs_brute = 0.0;
  int swap_depth_bitwise_equal = 0, swap_depth_compared = 0;
};
Precision& precision() {
  static Precision p;
  return p;
}
class PrecisionReport : public ::testing::Environment {
 public:
  void TearDown() override {
    const Precision& p = precision();
    std::printf(
        "[exact precision] closed forms: depth %.2e, normal %.2e, points %.2e m; order swap: "
        "depth %.2e, normal %.2e, points %.2e m (%d/%d depths bit-identical); random depth vs "
        "brute force %.2e m\n",
        p.depth, p.normal, p.point, p.swap_depth, p.swap_normal, p.swap_points,
        p.swap_depth_bitwise_equal, p.swap_depth_compared, p.random_depth_vs_brute);
  }
};
[[maybe_unused]] ::testing::Environment* const kReport =
    ::testing::AddGlobalTestEnvironment(new PrecisionReport);

Pose pose(const Vec3& position, const Quat& orientation = Quat::Identity()) {
  return {position, orientation};
}
Quat about(double angle_rad, const Vec3& axis) {
  return Quat(Eigen::AngleAxisd(angle_rad, axis.normalized()));
}

/// Each expected point matched by a distinct result point within tol (sizes equal); the worst
/// distance is folded into *worst.
void expect_same_points(const std::vector<Vec3>& got, const std::vector<Vec3>& want, double tol,
                        const std::string& what, double* worst) {
  ASSERT_EQ(got.size(), want.size()) << what;
  for (const Vec3& w : want) {
    double best = std::numeric_limits<double>::infinity();
    for (const Vec3& g : got) best = std::min(best, (g - w).norm());
    *worst = std::max(*worst, best);
    EXPECT_LE(best, tol) << what << ": no manifold point near " << w.transpose();
  }
}

/// Expected answer for the order (A, B).
struct Expected {
  Vec3 normal;                 // from B toward A
  double depth;                // m
  std::string kind;            // axis_kind for (A, B)
  std::vector<Vec3> manifold;  // world
};

/// Checks (A, B) against `e`, then (B, A): flipped normal, same depth, same manifold, mirrored
/// axis kind.
void check_both_orders(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                       const Pose& pb, const Expected& e, double tol, const std::string& what) {
  const SatResult ab = sat_query(a, pa, b, pb);
  const SatResult ba = sat_query(b, pb, a, pa);
  EXPECT_TRUE(ab.touching) << what;
  EXPECT_NEAR(ab.depth, e.depth, tol) << what;
  EXPECT_LE((ab.normal - e.normal).norm(), tol) << what << ": normal " << ab.normal.transpose();
  EXPECT_EQ(ab.axis_kind, e.kind) << what;
  expect_same_points(ab.manifold, e.manifold, tol, what + " (A, B)", &precision().point);
  precision().depth = std::max(precision().depth, std::abs(ab.depth - e.depth));
  precision().normal = std::max(precision().normal, (ab.normal - e.normal).norm());

  const std::string mirrored =
      e.kind == "face_a" ? "face_b" : (e.kind == "face_b" ? "face_a" : e.kind);
  EXPECT_TRUE(ba.touching) << what;
  EXPECT_NEAR(ba.depth, e.depth, tol) << what << " (B, A)";
  EXPECT_LE((ba.normal + e.normal).norm(), tol) << what << " (B, A): " << ba.normal.transpose();
  EXPECT_EQ(ba.axis_kind, mirrored) << what;
  expect_same_points(ba.manifold, e.manifold, tol, what + " (B, A)", &precision().point);
  precision().swap_depth = std::max(precision().swap_depth, std::abs(ab.depth - ba.depth));
  precision().swap_normal = std::max(precision().swap_normal, (ab.normal + ba.normal).norm());
  precision().swap_depth_compared += 1;
  precision().swap_depth_bitwise_equal += ab.depth == ba.depth ? 1 : 0;
}

/// The four corners of the face of box (centre c, rotation q, half extents h) at local
/// coordinate `axis` = sign * h[axis], moved along the world vector `shift`.
std::vector<Vec3> face_corners(const Vec3& c, const Quat& q, const Vec3& h, int axis, double sign,
                               const Vec3& shift = Vec3::Zero()) {
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  std::vector<Vec3> out;
  for (double su : {-1.0, 1.0})
    for (double sv : {-1.0, 1.0}) {
      Vec3 local = Vec3::Zero();
      local[axis] = sign * h[axis];
      local[u] = su * h[u];
      local[v] = sv * h[v];
      out.push_back(c + q * local + shift);
    }
  return out;
}

TEST(ExactSat, AxisAlignedBoxesEveryAxisAndSide) {
  // A: unit cube at s * 1.4 e_k + 0.2 e_(k+1); B: cube of side 2 at the origin.
  // Overlap along e_k: (0.5 + 1) - 1.4 = 0.1; along e_(k+1): 1.5 - 0.2 = 1.3; along the third
  // axis 1.5. Edge pairs of aligned boxes give the same three axes. So depth 0.1 along s e_k,
  // from B toward A. Reference: B's face (area 4 > 1). Incident: A's face at s * 0.9 e_k, its 4
  // corners lie inside B's face (|0.2 +- 0.5| < 1), 0.1 below B's plane s * 1.0 e_k: reported
  // midway, at s * 0.95 along e_k.
  const ConvexPolyhedron a = make_box(Vec3::Ones());
  const ConvexPolyhedron b = make_box(Vec3(2, 2, 2));
  for (int k = 0; k < 3; ++k)
    for (double s : {1.0, -1.0}) {
      const Vec3 ek = Vec3::Unit(k), ek1 = Vec3::Unit((k + 1) % 3);
      const Vec3 ca = s * 1.4 * ek + 0.2 * ek1;
      Expected e{s * ek, 0.1, "face_b",
                 face_corners(ca, Quat::Identity(), Vec3::Constant(0.5), k, -s, s * 0.05 * ek)};
      check_both_orders(a, pose(ca), b, pose(Vec3::Zero()), e, kRoundOff,
                        "axis " + std::to_string(k) + " sign " + std::to_string(s));
    }
}

TEST(ExactSat, FclCase1RotatedCubePressedIntoBigCube) {
  // A: unit cube rotated 45 deg about y at the origin. B: cube of side 3 at (0, 0, -1.5), top
  // face on z = 0. Ry(45) maps a corner (x, y, z) to z' = (z - x) sqrt(2)/2, so A's lowest
  // points, the local edge x = 0.5, z = -0.5, sit at z = -sqrt(2)/2, x = 0: depth sqrt(2)/2
  // along +z (B toward A). Sideways A spans |x| <= sqrt(2)/2 inside B's |x| <= 1.5, so every
  // other axis needs more than 1.5. A's two faces at that edge are equally anti-parallel to +z
  // (cosines -sqrt(2)/2 each): the incident feature is the edge, y in [-0.5, 0.5], reported
  // midway: (0, +-0.5, -sqrt(2)/4).
  const ConvexPolyhedron a = make_box(Vec3::Ones());
  const ConvexPolyhedron b = make_box(Vec3::Constant(3));
  const double r = std::sqrt(2.0) / 2;
  const Expected e{Vec3::UnitZ(), r, "face_b", {Vec3(0, 0.5, -r / 2), Vec3(0, -0.5, -r / 2)}};
  int n = 0;
  for (const Quat& sym : cube_symmetries())
    check_both_orders(a, pose(Vec3::Zero(), about(M_PI / 4, Vec3::UnitY())), b,
                      pose(Vec3(0, 0, -1.5), sym), e, kRoundOff,
                      "FCL case 1, symmetry " + std::to_string(n++));
}

TEST(ExactSat, FclCase2TiltedCubeOnDiamondEightPointManifold) {
  // A: unit cube rotated theta = 22.5 deg about x at the origin. B: unit cube rotated 45 deg
  // about z at (0, 0, -0.75): its top face is the diamond |x| + |y| <= r = sqrt(2)/2 at
  // z = -0.25. With s = sin(theta), c = cos(theta), A's local face z = -0.5 has the world normal
  // (0, s, -c) and the corners (x, c y + s/2, s y - c/2), x, y = +-1/2: it spans world
  // y in [y0, y1] = [(s - c)/2, (s + c)/2], and on it z(y) = (s y - 1/2) / c. Its lowest edge is
  // at z = -(s + c)/2, so the depth along +z is (s + c)/2 - 0.25 = sqrt(2)/2 cos(pi/4 - theta)
  // - 0.25 (FCL's closed form, ~0.4033). The other axes need more (B's side faces 1.32, A's
  // faces >= 0.54). The incident face (cosine -c against -s for the other face at that edge) is
  // clipped by the diamond: on y = y0 the segment |x| <= r + y0; on x = +-1/2 the segment
  // |y| <= r - 1/2; on y = y1 the segment |x| <= r - y1. Eight points, all below z = -0.25
  // (the highest is z(y1) = (s - c)/2 ~ -0.27), each reported midway: (z(y) - 0.25) / 2.
  const double theta = M_PI / 8, s = std::sin(theta), c = std::cos(theta);
  const double r = std::sqrt(2.0) / 2, y0 = (s - c) / 2, y1 = (s + c) / 2;
  auto at = [&](double x, double y) { return Vec3(x, y, ((s * y - 0.5) / c - 0.25) / 2); };
  const Expected e{Vec3::UnitZ(),
                   r * std::cos(M_PI / 4 - theta) - 0.25,
                   "face_b",
                   {at(r + y0, y0), at(-(r + y0), y0), at(0.5, r - 0.5), at(0.5, 0.5 - r),
                    at(-0.5, r - 0.5), at(-0.5, 0.5 - r), at(r - y1, y1), at(-(r - y1), y1)}};
  const ConvexPolyhedron cube = make_box(Vec3::Ones());
  int n = 0;
  for (const Quat& sym : cube_symmetries())
    check_both_orders(cube, pose(Vec3::Zero(), about(theta, Vec3::UnitX())), cube,
                      pose(Vec3(0, 0, -0.75), about(M_PI / 4, Vec3::UnitZ()) * sym), e, kRoundOff,
                      "FCL case 2, symmetry " + std::to_string(n++));
}

TEST(ExactSat, FclCase3EdgeEdge) {
  // A: unit cube, R = Ry(-45 deg) Rz(45 deg), centre at (sqrt(2) - 0.1) dir with
  // dir = (1, 0, 1)/sqrt(2). B: unit cube at the origin. B's support along dir is its edge
  // x = z = 0.5 (parallel to y) at dir . p = sqrt(2)/2. R^T (-dir) = (-1, 1, 0)/sqrt(2), so A's
  // support along -dir is its local edge x = -1/2, y = 1/2 (parallel to local z), at
  // sqrt(2)/2 from A's centre; world: the line through (sqrt(2)/2 - 0.1) dir along
  // R e_z = (-1, 0, 1)/sqrt(2). Overlap along dir: sqrt(2)/2 - (sqrt(2) - 0.1 - sqrt(2)/2)
  // = 0.1; the face axes need 0.425. The edges' cross product (-1,0,1)/sqrt(2) x e_y is
  // parallel to dir: normal +dir (B toward A). Both closest points lie on the line along dir
  // (at y = 0, mid-edge): (sqrt(2)/2 - 0.1) dir and (sqrt(2)/2) dir, midpoint
  // (sqrt(2)/2 - 0.05) dir.
  const Vec3 dir = Vec3(1, 0, 1).normalized();
  const Quat ra = about(-M_PI / 4, Vec3::UnitY()) * about(M_PI / 4, Vec3::UnitZ());
  const Vec3 ca = (std::sqrt(2.0) - 0.1) * dir;
  const Expected e{dir, 0.1, "edge_edge", {(std::sqrt(2.0) / 2 - 0.05) * dir}};
  const ConvexPolyhedron cube = make_box(Vec3::Ones());
  int n = 0;
  for (const Quat& sym : cube_symmetries())
    check_both_orders(cube, pose(ca, ra), cube, pose(Vec3::Zero(), sym), e, kRoundOff,
                      "FCL case 3, symmetry " + std::to_string(n++));
}

TEST(ExactSat, TetrahedronVertexIntoBoxFace) {
  // Tetrahedron with its apex at the local origin and its base the triangle of circumradius 1
  // at local z = 1; placed with the apex at (0.1, 0.2, 0.45), 0.05 below the top z = 0.5 of a
  // unit cube at the origin. Depth 0.05 along +z. The side faces' outward normals make 63 deg
  // with -z and lean sideways, so along them the cube reaches ~0.8 past the apex; the base
  // edges are horizontal and the apex edges at 45 deg, so the edge pairs other than the
  // horizontal ones (whose cross products are +-z) need > 0.25. The three side
  // faces around the apex are equally anti-parallel: the incident feature is the apex, one
  // point, midway: (0.1, 0.2, 0.475).
  const double h = std::sqrt(3.0) / 2;
  const ConvexPolyhedron tet = ConvexPolyhedron::from_triangles(
      {Vec3(0, 0, 0), Vec3(1, 0, 1), Vec3(-0.5, h, 1), Vec3(-0.5, -h, 1)},
      {{1, 2, 3}, {0, 2, 1}, {0, 3, 2}, {0, 1, 3}});
  const Expected e{Vec3::UnitZ(), 0.05, "face_b", {Vec3(0.1, 0.2, 0.475)}};
  check_both_orders(tet, pose(Vec3(0.1, 0.2, 0.45)), make_box(Vec3::Ones()), pose(Vec3::Zero()), e,
                    kRoundOff, "tetrahedron apex");
}

TEST(ExactSat, CrossedBarsEdgeEdge) {
  // A: bar 2 x 0.2 x 0.2 rotated 45 deg about x (a diamond cross-section): its lowest feature is
  // the edge along x at z = z_A - 0.1 sqrt(2), y = 0.3. B: bar 0.2 x 2 x 0.2 rotated 45 deg about
  // y: its highest feature is the edge along y at z = 0.1 sqrt(2), x = -0.4. With
  // z_A = 0.2 sqrt(2) - 0.03 the edges overlap by 0.03 along e_x x e_y = +z (B toward A); the
  // slanted faces of each bar tilt the other bar's length (half length 1) onto their normal by
  // 45 deg, so every face axis needs > 0.4, and the other edge pairs > 0.07. Closest points:
  // (-0.4, 0.3, 0.1 sqrt(2) - 0.03) and (-0.4, 0.3, 0.1 sqrt(2)); midpoint at
  // z = 0.1 sqrt(2) - 0.015.
  const ConvexPolyhedron a = make_box(Vec3(2, 0.2, 0.2));
  const ConvexPolyhedron b = make_box(Vec3(0.2, 2, 0.2));
  const double top = 0.1 * std::sqrt(2.0);
  const Expected e{Vec3::UnitZ(), 0.03, "edge_edge", {Vec3(-0.4, 0.3, top - 0.015)}};
  check_both_orders(a, pose(Vec3(0, 0.3, 2 * top - 0.03), about(M_PI / 4, Vec3::UnitX())), b,
                    pose(Vec3(-0.4, 0, 0), about(M_PI / 4, Vec3::UnitY())), e, kRoundOff,
                    "crossed bars");
}

TEST(ExactSat, SmallCubeOnTheDiagonalOfBigCube) {
  // FCL issue 545: unit cube B at the origin (corner (0.5, 0.5, 0.5)), cube A of side 0.1 at
  // (0.4, 0.4, 0.4). Overlap along each of x, y, z: 0.5 - (0.4 - 0.05) = 0.15; along the
  // diagonal (MPR's answer) 0.15 sqrt(3) ~ 0.26. The true minimum translation is 0.15 along
  // an axis; the three are tied and the oracle's slot-free tie-break (larger face, then larger
  // outward normal) picks the big cube's +x face. Incident: the small cube's -x face at
  // x = 0.35, reported midway at x = 0.425. Here the big cube is A, so the normal (from the small
  // cube toward the big one) is -x and the reference face is A's.
  const ConvexPolyhedron big = make_box(Vec3::Ones());
  const ConvexPolyhedron small = make_box(Vec3::Constant(0.1));
  const Vec3 ca = Vec3::Constant(0.4);
  const Expected diagonal{
      -Vec3::UnitX(), 0.15, "face_a",
      face_corners(ca, Quat::Identity(), Vec3::Constant(0.05), 0, -1, Vec3(0.075, 0, 0))};
  check_both_orders(big, pose(Vec3::Zero()), small, pose(ca), diagonal, kRoundOff, "diagonal");
  // Off the diagonal at (0.4, 0.39, 0.38): overlaps x 0.15, y 0.16, z 0.17: the unique answer
  // is x; with the small cube as A the normal is +x.
  const Vec3 cb(0.4, 0.39, 0.38);
  const Expected near{
      Vec3::UnitX(), 0.15, "face_b",
      face_corners(cb, Quat::Identity(), Vec3::Constant(0.05), 0, -1, Vec3(0.075, 0, 0))};
  check_both_orders(small, pose(cb), big, pose(Vec3::Zero()), near, kRoundOff, "near diagonal");
}

TEST(ExactSat, FaceFaceManifoldSmallBoxRestingOnBigBox) {
  // A: cube of side 0.5 rotated 30 deg about z, centre (0.2, -0.3, 1.24): bottom at z = 0.99.
  // B: cube of side 2 at the origin, top at z = 1. Depth 0.01 along +z; the sides need more
  // than 1. Reference: B's top (area 4 > 0.25); incident: A's bottom, whose corners have
  // |x| <= 0.2 + 0.25 sqrt(2) and |y| <= 0.3 + 0.25 sqrt(2), both < 1, so all four survive the
  // clip, reported midway at z = 0.995.
  const Vec3 ca(0.2, -0.3, 1.24);
  const Quat qa = about(M_PI / 6, Vec3::UnitZ());
  const Expected e{Vec3::UnitZ(), 0.01, "face_b",
                   face_corners(ca, qa, Vec3::Constant(0.25), 2, -1, Vec3(0, 0, 0.005))};
  check_both_orders(make_box(Vec3::Constant(0.5)), pose(ca, qa), make_box(Vec3::Constant(2)),
                    pose(Vec3::Zero()), e, kRoundOff, "resting box");
}

TEST(ExactSat, TouchingExactlyAndSeparated) {
  const ConvexPolyhedron cube = make_box(Vec3::Ones());
  // Faces flush at x = 0.5 (all coordinates exact in binary): depth 0, touching, normal +x; the
  // shared square x = 0.5, |y|, |z| <= 0.5 is the manifold (distance 0: midway = on it).
  const Expected flush{Vec3::UnitX(), 0.0, "face_b",
                       face_corners(Vec3::UnitX(), Quat::Identity(), Vec3::Constant(0.5), 0, -1)};
  // Equal faces tie; the slot-free tie-break picks the larger outward normal: B's +x face.
  check_both_orders(cube, pose(Vec3::UnitX()), cube, pose(Vec3::Zero()), flush, 0.0, "flush");

  // A rotated 45 deg about z at x = 0.5 + sqrt(2)/2: its vertical edge (local x = y = -0.5)
  // rests on B's face x = 0.5 up to round-off (~1e-16). Touching (within the round-off
  // allowance), depth 0; the two faces at that edge tie, so the manifold is the edge:
  // (0.5, 0.1, +-0.5).
  const Vec3 ca(0.5 + std::sqrt(2.0) / 2, 0.1, 0);
  const Expected edge{Vec3::UnitX(), 0.0, "face_b", {Vec3(0.5, 0.1, 0.5), Vec3(0.5, 0.1, -0.5)}};
  check_both_orders(cube, pose(ca, about(M_PI / 4, Vec3::UnitZ())), cube, pose(Vec3::Zero()), edge,
                    kRoundOff, "edge on face");

  // A rotated by theta about z, its centre at x = 0.5 + (cos theta + sin theta) / 2 (its half
  // width along x): its vertical edge at local (-0.5, 0.5) lies on x = 0.5, at
  // y = (cos theta - sin theta) / 2 inside B's face, for every theta in (0, 90 deg). The
  // computed overlap is 0 up to a few 1e-16 of either sign: always touching, depth clamped to
  // [0, round-off].
  for (int deg = 3; deg < 90; deg += 4) {
    const double t = deg * M_PI / 180;
    const Vec3 c(0.5 + 0.5 * (std::cos(t) + std::sin(t)), 0, 0.1);
    const SatResult r = sat_query(cube, pose(c, about(t, Vec3::UnitZ())), cube, pose(Vec3::Zero()));
    EXPECT_TRUE(r.touching) << deg << " deg";
    EXPECT_GE(r.depth, 0.0) << deg << " deg";
    EXPECT_LE(r.depth, kRoundOff) << deg << " deg";
  }

  // Separated by a gap of 0.2 along x: not touching, depth = -0.2, normal +x, no manifold.
  for (const bool swap : {false, true}) {
    const SatResult r = swap ? sat_query(cube, pose(Vec3::Zero()), cube, pose(Vec3(1.2, 0, 0)))
                             : sat_query(cube, pose(Vec3(1.2, 0, 0)), cube, pose(Vec3::Zero()));
    EXPECT_FALSE(r.touching);
    EXPECT_NEAR(r.depth, -0.2, kRoundOff);
    EXPECT_LE((r.normal - (swap ? -1.0 : 1.0) * Vec3::UnitX()).norm(), kRoundOff);
    EXPECT_TRUE(r.manifold.empty());
  }
}

TEST(ExactSat, FarFromTheWorldOriginKeepsPrecision) {
  // FCL case 2 moved by (1000, 2000, -3000): the depth is the same closed form. The inputs
  // themselves carry eps * 3000 ~ 7e-13 m of round-off; 1e-11 allows for a dozen such terms.
  const double theta = M_PI / 8;
  const Vec3 far(1000, 2000, -3000);
  const ConvexPolyhedron cube = make_box(Vec3::Ones());
  const SatResult r = sat_query(cube, pose(far, about(theta, Vec3::UnitX())), cube,
                                pose(far + Vec3(0, 0, -0.75), about(M_PI / 4, Vec3::UnitZ())));
  EXPECT_NEAR(r.depth, std::sqrt(2.0) / 2 * std::cos(M_PI / 4 - theta) - 0.25, 1e-11);
  EXPECT_LE((r.normal - Vec3::UnitZ()).norm(), 1e-11);
  EXPECT_EQ(r.manifold.size(), 8u);
}

TEST(ExactContact, CentroidFirstThenManifoldPoints) {
  // The resting box above through the backend interface: Ok, 1 + 4 contacts, all with normal +z
  // and depth 0.01, feature "face"; the first is the centre of the square, the centre of A's
  // bottom moved midway: (0.2, -0.3, 0.995).
  RigidBody a, b;
  a.shape = std::make_shared<const ConvexPolyhedron>(make_box(Vec3::Constant(0.5)));
  a.position = Vec3(0.2, -0.3, 1.24);
  a.orientation = about(M_PI / 6, Vec3::UnitZ());
  b.shape = std::make_shared<const ConvexPolyhedron>(make_box(Vec3::Constant(2)));
  const ContactResult r = exact_contact(a, b);
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_EQ(r.contacts.size(), 5u);
  EXPECT_LE((r.contacts[0].point - Vec3(0.2, -0.3, 0.995)).norm(), kRoundOff);
  for (const ContactPoint& p : r.contacts) {
    EXPECT_LE((p.normal - Vec3::UnitZ()).norm(), kRoundOff);
    EXPECT_NEAR(p.depth, 0.01, kRoundOff);
    EXPECT_EQ(p.feature, "face");
  }
  // Crossed bars: 1 + 1 contacts, feature "edge", both at the closest-point midpoint.
  a.shape = std::make_shared<const ConvexPolyhedron>(make_box(Vec3(2, 0.2, 0.2)));
  b.shape = std::make_shared<const ConvexPolyhedron>(make_box(Vec3(0.2, 2, 0.2)));
  const double top = 0.1 * std::sqrt(2.0);
  a.position = Vec3(0, 0.3, 2 * top - 0.03);
  a.orientation = about(M_PI / 4, Vec3::UnitX());
  b.position = Vec3(-0.4, 0, 0);
  b.orientation = about(M_PI / 4, Vec3::UnitY());
  const ContactResult e = exact_contact(a, b);
  ASSERT_EQ(e.status, Status::Ok) << e.message;
  ASSERT_EQ(e.contacts.size(), 2u);
  for (const ContactPoint& p : e.contacts) {
    EXPECT_LE((p.point - Vec3(-0.4, 0.3, top - 0.015)).norm(), kRoundOff);
    EXPECT_EQ(p.feature, "edge");
  }
  // Apart: Ok and no contacts. A body without a shape: an error, not a crash.
  a.position = Vec3(0, 0, 5);
  const ContactResult apart = exact_contact(a, b);
  EXPECT_EQ(apart.status, Status::Ok);
  EXPECT_TRUE(apart.contacts.empty());
  a.shape.reset();
  EXPECT_EQ(exact_contact(a, b).status, Status::Error);
}

// ---- Randomised invariants -------------------------------------------------------------

/// Independent brute force: the minimum over every triangle normal of both shapes and every
/// cross product of an edge direction of A with an edge direction of B (triangulation diagonals
/// included; extra axes are harmless) of the overlap along that axis, the shorter way. > 0:
/// overlapping by at least that much; < 0: separated by at least that much.
double brute_min_overlap(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                         const Pose& pb) {
  std::vector<Vec3> xa, xb;
  for (const Vec3& v : a.vertices()) xa.push_back(pa.apply(v));
  for (const Vec3& v : b.vertices()) xb.push_back(pb.apply(v));
  std::vector<Vec3> axes;
  for (const Plane& p : a.planes()) axes.push_back(pa.orientation * p.normal);
  for (const Plane& p : b.planes()) axes.push_back(pb.orientation * p.normal);
  // Edge directions, parallel ones once (they give the same axes).
  auto directions = [](const ConvexPolyhedron& p, const std::vector<Vec3>& x) {
    std::vector<Vec3> out;
    for (const Edge& e : p.edges()) {
      const Vec3 d = (x[e.b] - x[e.a]).normalized();
      bool seen = false;
      for (const Vec3& o : out) seen = seen || d.cross(o).norm() < 1e-12;
      if (!seen) out.push_back(d);
    }
    return out;
  };
  for (const Vec3& da : directions(a, xa))
    for (const Vec3& db : directions(b, xb)) {
      const Vec3 n = da.cross(db);
      if (n.norm() > 1e-12) axes.push_back(n.normalized());
    }
  double best = std::numeric_limits<double>::infinity();
  for (const Vec3& n : axes) {
    double lo_a = 1e300, hi_a = -1e300, lo_b = 1e300, hi_b = -1e300;
    for (const Vec3& x : xa) lo_a = std::min(lo_a, x.dot(n)), hi_a = std::max(hi_a, x.dot(n));
    for (const Vec3& x : xb) lo_b = std::min(lo_b, x.dot(n)), hi_b = std::max(hi_b, x.dot(n));
    best = std::min(best, std::min(hi_b - lo_a, hi_a - lo_b));
  }
  return best;
}

/// A random convex polyhedron: a box, prism or icosphere through a random shear and scale
/// (a linear map with positive determinant keeps it convex and outward), rebuilt with
/// ConvexPolyhedron::from_triangles.
ConvexPolyhedron random_shape(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int kind = static_cast<int>(u(rng) * 3);
  const ConvexPolyhedron base =
      kind == 0   ? make_box(Vec3(0.3 + u(rng), 0.3 + u(rng), 0.3 + u(rng)))
      : kind == 1 ? make_prism(0.3 + 0.5 * u(rng), 0.3 + u(rng), 3 + static_cast<int>(u(rng) * 6))
                  : make_icosphere(0.3 + 0.5 * u(rng), static_cast<int>(u(rng) * 3));
  Mat3 m = Mat3::Identity();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) += (i == j ? 0.5 : 0.3) * (2 * u(rng) - 1);
  if (m.determinant() < 0.1) m = Mat3::Identity();
  std::vector<Vec3> v;
  for (const Vec3& p : base.vertices()) v.push_back(m * p);
  return ConvexPolyhedron::from_triangles(v, base.triangles());
}

TEST(ExactSatRandom, InvariantsAgainstBruteForce) {
  std::mt19937 rng(20240611);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int samples = 300;
  int touching = 0, edge_minima = 0;
  for (int i = 0; i < samples; ++i) {
    const ConvexPolyhedron a = random_shape(rng), b = random_shape(rng);
    // Size: the larger bounding-box extent; A placed at 0.2 to 1.1 of the sum of the radii.
    const double size = std::max((a.bounds().max - a.bounds().min).maxCoeff(),
                                 (b.bounds().max - b.bounds().min).maxCoeff());
    const double reach =
        0.5 * ((a.bounds().max - a.bounds().min).norm() + (b.bounds().max - b.bounds().min).norm());
    const Pose pb = pose(Vec3(u(rng), u(rng), u(rng)) - Vec3::Constant(0.5), random_rotation(rng));
    const Vec3 dir = Vec3(2 * u(rng) - 1, 2 * u(rng) - 1, 2 * u(rng) - 1).normalized();
    const Pose pa = pose(pb.position + (0.2 + 0.9 * u(rng)) * reach * dir, random_rotation(rng));
    const std::string what = "sample " + std::to_string(i);

    const SatResult r = sat_query(a, pa, b, pb);
    const SatResult s = sat_query(b, pb, a, pa);
    // Unit normal (round-off of a normalised vector: a few eps).
    EXPECT_NEAR(r.normal.norm(), 1.0, 1e-12) << what;
    // Order swap: same verdict and depth, flipped normal, same manifold (round-off only).
    EXPECT_EQ(r.touching, s.touching) << what;
    EXPECT_NEAR(r.depth, s.depth, 1e-12 * size) << what;
    EXPECT_LE((r.normal + s.normal).norm(), 1e-12) << what;
    precision().swap_depth = std::max(precision().swap_depth, std::abs(r.depth - s.depth));
    precision().swap_normal = std::max(precision().swap_normal, (r.normal + s.normal).norm());
    precision().swap_depth_compared += 1;
    precision().swap_depth_bitwise_equal += r.depth == s.depth ? 1 : 0;
    if (r.touching)
      expect_same_points(s.manifold, r.manifold, 1e-9 * size, what + " swap",
                         &precision().swap_points);

    // Against the brute force: when touching, the SAT minimum over all axes IS the penetration
    // depth, so both must agree to round-off (the oracle's axis pruning and merging tolerances
    // are ~1e-9 of the size at worst); when apart both must say so.
    const double brute = brute_min_overlap(a, pa, b, pb);
    EXPECT_EQ(r.touching, brute >= -1e-12 * size) << what << " brute " << brute;
    if (!r.touching) continue;
    ++touching;
    edge_minima += r.axis_kind == "edge_edge" ? 1 : 0;
    EXPECT_GE(r.depth, 0.0) << what;
    EXPECT_NEAR(r.depth, brute, 1e-9 * size) << what;
    precision().random_depth_vs_brute =
        std::max(precision().random_depth_vs_brute, std::abs(r.depth - brute));
    EXPECT_FALSE(r.manifold.empty()) << what;

    // Moving A by depth + 1e-9 size along the normal separates (gap 1e-9 size >> round-off).
    const Pose out = pose(pa.position + (r.depth + 1e-9 * size) * r.normal, pa.orientation);
    const SatResult after = sat_query(a, out, b, pb);
    EXPECT_TRUE(!after.touching || after.depth < 1e-12 * size) << what;
    EXPECT_LT(brute_min_overlap(a, out, b, pb), 0.0) << what;
    // Moving by depth - 1e-6 size leaves them overlapping by at least 1e-6 size if the depth is
    // the minimum (a ball of radius depth fits in the Minkowski difference): the brute force must
    // find no axis with less than half of that.
    if (r.depth > 1e-6 * size) {
      const Pose in = pose(pa.position + (r.depth - 1e-6 * size) * r.normal, pa.orientation);
      EXPECT_TRUE(sat_query(a, in, b, pb).touching) << what;
      EXPECT_GT(brute_min_overlap(a, in, b, pb), 0.5e-6 * size) << what;
    }
  }
  // Representative samples (Jolt's habit): neither almost all apart nor almost all touching,
  // and both face and edge-edge minima among the contacts.
  EXPECT_GT(touching, samples / 5);
  EXPECT_LT(touching, samples * 9 / 10);
  EXPECT_GT(edge_minima, touching / 10);
  EXPECT_LT(edge_minima, touching * 9 / 10);
}

}  // namespace
}  // namespace rbx
