// Moore & Wilhelms detector: face, vertex and edge tests on hand-built poses, the argument-order
// symmetry, separated and touching bodies, rotated poses, one test per docs/seed_corrections.md
// correction (1, 2, 8, 9, 10) that fails on the literal seed text, and a fixed-seed cross-check
// against an independent separating-axis reference.
#include "engine/detect.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

namespace rbx {
namespace {

// Every configuration below has coordinates of order 1 and goes through a handful of flops
// (a rotation, a centroid, a projection), so round-off is ~1e-15; 1e-12 leaves a wide margin
// and is still far below every geometric distance the tests distinguish (>= 1e-2).
constexpr double kDetectRoundOff = 1e-12;

Pose pose_at(const Vec3& position, const Quat& orientation = Quat::Identity()) {
  Pose p;
  p.position = position;
  p.orientation = orientation;
  return p;
}

void expect_vec_near(const Vec3& actual, const Vec3& expected, double tol) {
  EXPECT_LE((actual - expected).norm(), tol)
      << "actual (" << actual.transpose() << "), expected (" << expected.transpose() << ")";
}

// Rotation taking a unit cube's corner direction (-1,-1,-1)/sqrt(3) to -z: the corner at
// local (-1/2,-1/2,-1/2) becomes the lowest point, sqrt(3)/2 below the centre.
Quat corner_down() { return Quat::FromTwoVectors(Vec3(-1, -1, -1).normalized(), Vec3(0, 0, -1)); }

// A fixed, generic rotation (0.7 rad about (1, 2, 3)) for the rotated-pose tests.
Quat generic_rotation() { return Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized())); }

// The same configuration seen in a rotated world: R applied to both poses.
Pose rotate_pose(const Quat& r, const Pose& p) {
  return pose_at(r * p.position, r * p.orientation);
}

// Pose moved by an offset (m, world).
Pose shifted(const Pose& p, const Vec3& offset) {
  return pose_at(p.position + offset, p.orientation);
}

// ---- Configurations shared by several tests -----------------------------------------------

// Face-face: A a unit cube at the origin; B a (1, 0.8, 0.8) box on A's +x side, centre at
// x = 0.9 + gap, so B spans x in [0.4 + gap, 1.4 + gap] and overlaps A by 0.1 - gap along x.
struct FaceFace {
  explicit FaceFace(double gap = 0.0) : pb(pose_at(Vec3(0.9 + gap, 0, 0))) {}
  ConvexPolyhedron a = make_box(Vec3(1, 1, 1));
  ConvexPolyhedron b = make_box(Vec3(1, 0.8, 0.8));
  Pose pa = pose_at(Vec3(0, 0, 0));
  Pose pb;
};

// Vertex: a unit cube A standing on a corner, the corner 0.1 - lift deep in the top face
// (z = 0.5) of a flat (4, 4, 1) box B at the origin.
struct CornerIntoFace {
  explicit CornerIntoFace(double lift = 0.0)
      : pa(pose_at(Vec3(0, 0, 0.5 + std::sqrt(3.0) / 2 - 0.1 + lift), corner_down())) {}
  ConvexPolyhedron a = make_box(Vec3(1, 1, 1));
  ConvexPolyhedron b = make_box(Vec3(4, 4, 1));
  Pose pa;
  Pose pb = pose_at(Vec3(0, 0, 0));
};

// Edge: crossed bars. B is a (1, 4, 1) bar along y at the origin (top face z = 0.5); A is a
// (4, 1, 1) bar along x centred at z = 0.9 + lift, so its bottom edges (along x) sit at
// z = 0.4 + lift. No vertex of either bar is inside the other and no face centroid is either
// (A's bottom-face centroids are at |x| = 2/3 > 0.5, B's top-face ones at |y| = 2/3 > 0.5), so
// only the edge test can see the contact.
struct CrossedBars {
  explicit CrossedBars(double lift = 0.0) : pa(pose_at(Vec3(0, 0, 0.9 + lift))) {}
  ConvexPolyhedron a = make_box(Vec3(4, 1, 1));
  ConvexPolyhedron b = make_box(Vec3(1, 4, 1));
  Pose pa;
  Pose pb = pose_at(Vec3(0, 0, 0));
};

// Small box B (0.5 cube) pressed 0.1 into the top face of a flat (4, 4, 1) box A. B's centre is
// at z = 0.65, so its bottom face is at 0.4 and its side-face centroids at z = 0.65 -+ 1/12 >
// 0.5; A's top-face centroids (|x| = |y| = 2/3) miss B. Only the (B, A) face test hits.
struct SmallOnBig {
  ConvexPolyhedron a = make_box(Vec3(4, 4, 1));
  ConvexPolyhedron b = make_box(Vec3(0.5, 0.5, 0.5));
  Pose pa = pose_at(Vec3(0, 0, 0));
  Pose pb = pose_at(Vec3(0.3, 0.2, 0.5 + 0.25 - 0.1));
};

// Tilted bar: B the (1, 4, 1) bar along y; A a (4, 1, 1) bar rotated by alpha = 30 deg about y,
// so A's long axis is e_a = (cos a, 0, -sin a) and its bottom face has outward normal -n with
// n = (sin a, 0, cos a). A is placed so that B's top-right edge (x = 0.5, z = 0.5, along y) lies
// 0.1 deep behind A's bottom face: centre = (0.5, 0, 0.5) + (0.5 - 0.1) n. A's bottom edges run
// down through B's top face and out of its +x face; no vertex or face centroid of either body
// is inside the other (checked below through the face and vertex tests).
struct TiltedBar {
  static constexpr double kAlpha = M_PI / 6;
  Vec3 n = Vec3(std::sin(kAlpha), 0, std::cos(kAlpha));
  Vec3 e_a = Vec3(std::cos(kAlpha), 0, -std::sin(kAlpha));
  ConvexPolyhedron a = make_box(Vec3(4, 1, 1));
  ConvexPolyhedron b = make_box(Vec3(1, 4, 1));
  Pose pa = pose_at(Vec3(0.5, 0, 0.5) + 0.4 * n, Quat(Eigen::AngleAxisd(kAlpha, Vec3::UnitY())));
  Pose pb = pose_at(Vec3(0, 0, 0));
};

// ---- Face, vertex, edge --------------------------------------------------------------------

TEST(Detect, FaceFaceBoxesAlongX) {
  const FaceFace s;
  // A's +x face (x = 0.5) is split into triangles {1,3,7} and {1,7,5} with centroids
  // (0.5, 1/6, -1/6) and (0.5, -1/6, 1/6), both inside B (|y|, |z| <= 0.4); every other centroid
  // of A has x <= 1/6 < 0.4. Their average is (0.5, 0, 0). A's triangle normal +x points toward
  // B, so the normal from B toward A is -x (seed correction 9 (face normal negated)). Depth:
  // max_b(-x) - min_a(-x) = -0.4 - (-0.5) = 0.1.
  for (const auto& hit : {face_test(s.a, s.pa, s.b, s.pb), detect(s.a, s.pa, s.b, s.pb)}) {
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->feature, "face");
    expect_vec_near(hit->point, Vec3(0.5, 0, 0), kDetectRoundOff);
    expect_vec_near(hit->normal, Vec3(-1, 0, 0), kDetectRoundOff);
    EXPECT_NEAR(hit->depth, 0.1, kDetectRoundOff);
  }
}

TEST(Detect, CubeCornerIntoFaceIsAVertexHit) {
  const CornerIntoFace s;
  // No face centroid is inside the other shape (the corner's neighbouring centroids are at
  // least 2/(3 sqrt 3) = 0.385 above the tip, which is only 0.1 deep), so detect() reaches the
  // vertex test. The lowest corner, local (-1/2,-1/2,-1/2), is at (0, 0, 0.4); B's nearest face
  // is its top (0.1 away; the others are >= 0.9), whose outward normal +z points from B toward
  // A. Depth = max_b z - min_a z = 0.5 - 0.4.
  EXPECT_FALSE(face_test(s.a, s.pa, s.b, s.pb).has_value());
  EXPECT_FALSE(face_test(s.b, s.pb, s.a, s.pa).has_value());
  for (const auto& hit : {vertex_test(s.a, s.pa, s.b, s.pb), detect(s.a, s.pa, s.b, s.pb)}) {
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->feature, "vertex");
    expect_vec_near(hit->point, Vec3(0, 0, 0.4), kDetectRoundOff);
    expect_vec_near(hit->normal, Vec3(0, 0, 1), kDetectRoundOff);
    EXPECT_NEAR(hit->depth, 0.1, kDetectRoundOff);
  }
}

TEST(Detect, EdgeLandingFlatAveragesItsVerticesOnTheSameFace) {
  // Departure from the seed's "first vertex": a unit cube turned 45 deg about x has a bottom
  // edge along x at depth 0.02 in a wide slab's top face. Both ends, (+-1/2, 0, -0.02) relative
  // to the slab top, are inside B with the same closest face (the top): the point is their
  // midpoint (0, 0, top - 0.02), so the impulse acts on the symmetry plane (no spurious spin).
  const ConvexPolyhedron a = make_box(Vec3::Ones()), b = make_box(Vec3(4, 4, 1));
  const double h = std::sqrt(2.0) / 2;
  const Pose pa =
      pose_at(Vec3(0, 0, 0.5 + h - 0.02), Quat(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitX())));
  const Pose pb = pose_at(Vec3::Zero());
  const auto hit = vertex_test(a, pa, b, pb);
  ASSERT_TRUE(hit.has_value());
  expect_vec_near(hit->point, Vec3(0, 0, 0.48), kDetectRoundOff);
  expect_vec_near(hit->normal, Vec3(0, 0, 1), kDetectRoundOff);
  EXPECT_NEAR(hit->depth, 0.02, kDetectRoundOff);
}

TEST(Detect, EdgePiercingAFaceTakesTheFaceNormal) {
  // A unit cube 0.05 deep in a wall whose face is the plane x = 0 (the wall B spans x < 0).
  // A's four edges along x pierce the wall's face; e_a x e_b lies in the wall plane (for any
  // e_b of the face, the face diagonal included) and would push A sideways by ~1 m. The wall's
  // outward normal +x separates with 0.05: it is the contact normal, depth 0.05.
  const ConvexPolyhedron a = make_box(Vec3::Ones()), b = make_box(Vec3(2, 8, 8));
  const Pose pa = pose_at(Vec3(0.45, 0.3, -0.2)), pb = pose_at(Vec3(-1, 0, 0));
  const auto hit = edge_test(a, pa, b, pb);
  ASSERT_TRUE(hit.has_value());
  expect_vec_near(hit->normal, Vec3(1, 0, 0), kDetectRoundOff);
  EXPECT_NEAR(hit->depth, 0.05, kDetectRoundOff);
}

TEST(Detect, CrossedBarsAreAnEdgeHit) {
  const CrossedBars s;
  EXPECT_FALSE(detect_feature(Feature::Face, s.a, s.pa, s.b, s.pb).has_value());
  EXPECT_FALSE(detect_feature(Feature::Vertex, s.a, s.pa, s.b, s.pb).has_value());
  // A's first edge (0,1) runs from (-2, -0.5, 0.4) to (2, -0.5, 0.4). It crosses B's planes
  // x = -0.5 and x = 0.5 at t = 1.5/4 and 2.5/4; the midpoint of that interval, (0, -0.5, 0.4),
  // is inside B. e_a = x and e_b = y (B's top edge of the crossed x = -0.5 face, 0.51 from the
  // point, against 0.71 for the diagonal), so the normal is +-z; from B (below) toward A it is
  // +z. Depth = max_b z - min_a z = 0.5 - 0.4.
  for (const auto& hit : {edge_test(s.a, s.pa, s.b, s.pb), detect(s.a, s.pa, s.b, s.pb)}) {
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->feature, "edge");
    expect_vec_near(hit->point, Vec3(0, -0.5, 0.4), kDetectRoundOff);
    expect_vec_near(hit->normal, Vec3(0, 0, 1), kDetectRoundOff);
    EXPECT_NEAR(hit->depth, 0.1, kDetectRoundOff);
  }
}

TEST(Detect, TiltedEdgeNormalIsEaCrossEb) {
  const TiltedBar s;
  EXPECT_FALSE(detect_feature(Feature::Face, s.a, s.pa, s.b, s.pb).has_value());
  EXPECT_FALSE(detect_feature(Feature::Vertex, s.a, s.pa, s.b, s.pb).has_value());
  // A's edge (0,1) is the line (0.5, -0.5, 0.5) - 0.1 n + tau e_a. It enters B's top face
  // (z = 0.5) at tau = -0.1 cos(a) / sin(a) and leaves the +x face (x = 0.5) at
  // tau = 0.1 sin(a) / cos(a); no other plane of B is crossed in between, so the point is at
  // the midpoint of that interval. B's nearest crossed triangle is the top one, whose nearest
  // edge is the top-right edge along y: the normal is e_a x y = n (up to sign; n points from B
  // toward A). B's extreme point along n is that edge and A's is its bottom face: depth 0.1.
  const double tau_in = -0.1 * std::cos(TiltedBar::kAlpha) / std::sin(TiltedBar::kAlpha);
  const double tau_out = 0.1 * std::sin(TiltedBar::kAlpha) / std::cos(TiltedBar::kAlpha);
  const Vec3 expected_point = Vec3(0.5, -0.5, 0.5) - 0.1 * s.n + 0.5 * (tau_in + tau_out) * s.e_a;
  const auto hit = detect(s.a, s.pa, s.b, s.pb);
  ASSERT_TRUE(hit.has_value());
  EXPECT_EQ(hit->feature, "edge");
  expect_vec_near(hit->point, expected_point, kDetectRoundOff);
  expect_vec_near(hit->normal, s.n, kDetectRoundOff);
  EXPECT_NEAR(hit->depth, 0.1, kDetectRoundOff);
}

// ---- Argument order, separation, touching, rotation ----------------------------------------

TEST(Detect, SwappingArgumentsFlipsTheNormalOnly) {
  // Configurations where only one order of the tests hits, so both argument orders find the
  // same feature: the point and depth are equal and the normal flips.
  {
    const CornerIntoFace s;
    const auto ab = detect(s.a, s.pa, s.b, s.pb), ba = detect(s.b, s.pb, s.a, s.pa);
    ASSERT_TRUE(ab.has_value() && ba.has_value());
    EXPECT_EQ(ba->feature, "vertex");
    expect_vec_near(ba->point, ab->point, kDetectRoundOff);
    expect_vec_near(ba->normal, -ab->normal, kDetectRoundOff);
    EXPECT_NEAR(ba->depth, ab->depth, kDetectRoundOff);
  }
  {
    // B's bottom-face centroids (0.3 -+ 1/12, 0.2 -+ 1/12, 0.4) average to (0.3, 0.2, 0.4).
    // B's bottom normal is -z; the face normal of (B, A) is +z (from A toward B), flipped to -z
    // for detect(A, B). Depth 0.5 - 0.4 = 0.1 either way.
    const SmallOnBig s;
    const auto ab = detect(s.a, s.pa, s.b, s.pb), ba = detect(s.b, s.pb, s.a, s.pa);
    ASSERT_TRUE(ab.has_value() && ba.has_value());
    EXPECT_EQ(ab->feature, "face");
    EXPECT_EQ(ba->feature, "face");
    expect_vec_near(ab->point, Vec3(0.3, 0.2, 0.4), kDetectRoundOff);
    expect_vec_near(ba->point, Vec3(0.3, 0.2, 0.4), kDetectRoundOff);
    expect_vec_near(ab->normal, Vec3(0, 0, -1), kDetectRoundOff);
    expect_vec_near(ba->normal, Vec3(0, 0, 1), kDetectRoundOff);
    EXPECT_NEAR(ab->depth, 0.1, kDetectRoundOff);
    EXPECT_NEAR(ba->depth, 0.1, kDetectRoundOff);
  }
  {
    // Crossed bars: each bar's edges pierce the other, so each order finds its own first edge
    // (A's bottom edge at (0, -0.5, 0.4), B's top edge at (-0.5, 0, 0.5)): only the normal and
    // depth are comparable. Both points lie in the overlap of the bars.
    const CrossedBars s;
    const auto ab = detect(s.a, s.pa, s.b, s.pb), ba = detect(s.b, s.pb, s.a, s.pa);
    ASSERT_TRUE(ab.has_value() && ba.has_value());
    expect_vec_near(ba->normal, -ab->normal, kDetectRoundOff);
    EXPECT_NEAR(ba->depth, ab->depth, kDetectRoundOff);
    expect_vec_near(ba->point, Vec3(-0.5, 0, 0.5), kDetectRoundOff);
  }
}

TEST(Detect, SeparatedBodiesGiveNothing) {
  // Each configuration moved 0.2 apart along its contact normal: the 0.1 overlap becomes a
  // 0.1 gap, 10^8 times the point-in-mesh tolerance (1e-9 of a ~1..6 m shape).
  {
    const FaceFace s(0.2);
    EXPECT_FALSE(detect(s.a, s.pa, s.b, s.pb).has_value());
    EXPECT_FALSE(detect(s.b, s.pb, s.a, s.pa).has_value());
  }
  {
    const CornerIntoFace s(0.2);
    EXPECT_FALSE(detect(s.a, s.pa, s.b, s.pb).has_value());
  }
  {
    const CrossedBars s(0.2);
    EXPECT_FALSE(detect(s.a, s.pa, s.b, s.pb).has_value());
  }
  {
    // Two unit icospheres with centres 2.1 apart: the polyhedra lie inside their spheres, which
    // are 0.1 apart.
    const ConvexPolyhedron sphere = make_icosphere(1.0, 2);
    EXPECT_FALSE(
        detect(sphere, pose_at(Vec3(0, 0, 0)), sphere, pose_at(Vec3(2.1, 0, 0))).has_value());
  }
}

TEST(Detect, ExactlyTouchingIsDetectedWithZeroDepth) {
  {
    // B's -x face at x = 0.5 exactly on A's +x face: A's +x centroids lie on B's boundary, inside
    // by the tolerance. All coordinates are dyadic (0.5, 1), so the depth is exactly 0.
    const FaceFace s(0.1);
    const auto hit = detect(s.a, s.pa, s.b, s.pb);
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->feature, "face");
    expect_vec_near(hit->point, Vec3(0.5, 0, 0), kDetectRoundOff);
    expect_vec_near(hit->normal, Vec3(-1, 0, 0), kDetectRoundOff);
    EXPECT_EQ(hit->depth, 0.0);
  }
  {
    // A's bottom edge exactly on B's top face (z = 0.5): the edge test still finds (0, -0.5, 0.5).
    const CrossedBars s(0.1);
    const auto hit = detect(s.a, s.pa, s.b, s.pb);
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->feature, "edge");
    expect_vec_near(hit->point, Vec3(0, -0.5, 0.5), kDetectRoundOff);
    expect_vec_near(hit->normal, Vec3(0, 0, 1), kDetectRoundOff);
    EXPECT_EQ(hit->depth, 0.0);
  }
}

TEST(Detect, GapsBelowTheToleranceCountAsTouching) {
  // The tolerance is 1e-9 of the larger shape's size (here the unit cube's diagonal sqrt 3):
  // a gap of a tenth of it is touching, a gap ten times larger is not.
  const FaceFace base;
  const double tol = point_in_mesh_tolerance(base.a, base.b);
  EXPECT_NEAR(tol, 1e-9 * std::sqrt(3.0), kDetectRoundOff * 1e-9);
  const FaceFace near(0.1 + 0.1 * tol), far(0.1 + 10 * tol);
  EXPECT_TRUE(detect(near.a, near.pa, near.b, near.pb).has_value());
  EXPECT_FALSE(detect(far.a, far.pa, far.b, far.pb).has_value());
}

TEST(Detect, RotatedPosesGiveWorldFrameResults) {
  // The same configurations in a world rotated by R: the point maps to R p, the normal to R n,
  // and the depth is unchanged (a projection length).
  const Quat r = generic_rotation();
  {
    const FaceFace s;
    const auto hit = detect(s.a, rotate_pose(r, s.pa), s.b, rotate_pose(r, s.pb));
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->feature, "face");
    expect_vec_near(hit->point, r * Vec3(0.5, 0, 0), kDetectRoundOff);
    expect_vec_near(hit->normal, r * Vec3(-1, 0, 0), kDetectRoundOff);
    EXPECT_NEAR(hit->depth, 0.1, kDetectRoundOff);
  }
  {
    const CornerIntoFace s;
    const auto hit = detect(s.a, rotate_pose(r, s.pa), s.b, rotate_pose(r, s.pb));
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->feature, "vertex");
    expect_vec_near(hit->point, r * Vec3(0, 0, 0.4), kDetectRoundOff);
    expect_vec_near(hit->normal, r * Vec3(0, 0, 1), kDetectRoundOff);
    EXPECT_NEAR(hit->depth, 0.1, kDetectRoundOff);
  }
  {
    const CrossedBars s;
    const auto hit = detect(s.a, rotate_pose(r, s.pa), s.b, rotate_pose(r, s.pb));
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->feature, "edge");
    expect_vec_near(hit->point, r * Vec3(0, -0.5, 0.4), kDetectRoundOff);
    expect_vec_near(hit->normal, r * Vec3(0, 0, 1), kDetectRoundOff);
    EXPECT_NEAR(hit->depth, 0.1, kDetectRoundOff);
  }
  {
    // Only B turned, by 90 deg about its long axis y: a (1, 4, 1) bar maps onto itself, so the
    // answer is that of the unrotated crossed bars, reached through B's body-to-world map.
    const CrossedBars s;
    const Pose pb = pose_at(s.pb.position, Quat(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitY())));
    const auto hit = detect(s.a, s.pa, s.b, pb);
    ASSERT_TRUE(hit.has_value());
    expect_vec_near(hit->normal, Vec3(0, 0, 1), kDetectRoundOff);
    EXPECT_NEAR(hit->depth, 0.1, kDetectRoundOff);
  }
}

TEST(Detect, TheAcceleratedDetectorMatchesTheFaithfulOne) {
  // One hand-built pose here; tests/engine/accelerated_detect_test.cpp holds the randomised check.
  const CrossedBars s;
  const auto faithful = detect(s.a, s.pa, s.b, s.pb, Detector::Faithful);
  const auto fast = detect(s.a, s.pa, s.b, s.pb, Detector::Accelerated);
  ASSERT_TRUE(faithful.has_value() && fast.has_value());
  expect_vec_near(fast->point, faithful->point, kDetectRoundOff);
  expect_vec_near(fast->normal, faithful->normal, kDetectRoundOff);
  EXPECT_NEAR(fast->depth, faithful->depth, kDetectRoundOff);
  EXPECT_EQ(fast->feature, faithful->feature);
}

TEST(Detect, TestBeforePrepareIsRejected) {
  DetectionCache cache;
  EXPECT_THROW(cache.test(Feature::Face), std::logic_error);
  EXPECT_THROW(cache.detect(), std::logic_error);
}

// ---- One test per seed correction ----------------------------------------------------------

TEST(SeedCorrection, PointInMeshUsesPMinusQ) {
  // seed correction 1 (point in mesh uses p - q_f). The seed dots p itself with each face normal
  // and calls p outside if any product is not negative. Take a unit cube centred at (10, 0, 0) and
  // its own centre p: p . n is +10 on the +x face, so the literal rule says "outside"; (p - q_f) .
  // n_f = -0.5 on every face, inside.
  const ConvexPolyhedron box = make_box(Vec3(1, 1, 1));
  const Pose pose = pose_at(Vec3(10, 0, 0));
  const Vec3 p(10, 0, 0);
  bool literal_inside = true;
  for (const Plane& plane : box.planes())
    if (p.dot(plane.normal) >= 0.0) literal_inside = false;  // normals unrotated: identity pose
  EXPECT_FALSE(literal_inside);
  EXPECT_TRUE(point_in_mesh(box, pose, p, 0.0));
  // Ours also rejects points outside: 0.01 beyond the +x face, and the world origin.
  EXPECT_FALSE(point_in_mesh(box, pose, Vec3(10.51, 0, 0), 1e-9));
  EXPECT_FALSE(point_in_mesh(box, pose, Vec3(0, 0, 0), 1e-9));
  // The tolerance is a distance outside the faces: 0.5e-9 beyond counts as in at tol = 1e-9
  // (the coordinates 10.5 +- 1e-9 are resolved to ~2e-15).
  EXPECT_TRUE(point_in_mesh(box, pose, Vec3(10.5 + 0.5e-9, 0, 0), 1e-9));
  EXPECT_FALSE(point_in_mesh(box, pose, Vec3(10.5 + 2e-9, 0, 0), 1e-9));
}

TEST(SeedCorrection, EdgeCrossingIsVjMinusVi) {
  // seed correction 2 (edge crossing at v_i + t (v_j - v_i)). Crossed bars, A's edge (0,1) from v_i
  // = (-2, -0.5, 0.4) to v_j = (2, -0.5, 0.4) against B's plane x = -0.5 (outward normal -x): d_i
  // = 1.5, d_j = -2.5, t = 1.5 / 4.
  const CrossedBars s;
  const Vec3 v_i(-2, -0.5, 0.4), v_j(2, -0.5, 0.4);
  const double t = 1.5 / 4.0;
  const Vec3 literal = v_i + t * (v_i - v_i);  // the seed's printed formula: always v_i
  const Vec3 corrected = v_i + t * (v_j - v_i);
  // The literal "crossing" is 1.5 off the plane, the corrected one on it.
  EXPECT_NEAR(literal.x(), -2.0, kDetectRoundOff);
  EXPECT_NEAR(corrected.x(), -0.5, kDetectRoundOff);
  // With the literal formula every crossing, and every average of crossings, is an end vertex
  // of A's edge; none of A's eight vertices is inside B, so the literal edge test can find
  // nothing. Ours finds the contact.
  for (const Vec3& v : s.a.vertices())
    EXPECT_FALSE(point_in_mesh(s.b, s.pb, s.pa.apply(v), point_in_mesh_tolerance(s.a, s.b)));
  const auto hit = edge_test(s.a, s.pa, s.b, s.pb);
  ASSERT_TRUE(hit.has_value());
  expect_vec_near(hit->point, Vec3(0, -0.5, 0.4), kDetectRoundOff);
}

TEST(SeedCorrection, BothOrdersSeeAVertexOfBInAFaceOfA) {
  // seed correction 8 (both orders, normal flipped). The corner configuration with the roles
  // swapped: the cube (now B) pokes its corner into the flat box (now A). Looping A's vertices
  // against B alone finds nothing; the (B, A) pass finds the corner at (0, 0, 0.4) with A's top
  // normal +z (from A toward B), flipped to -z: from B (above) toward A.
  const CornerIntoFace s;
  EXPECT_FALSE(vertex_test(s.b, s.pb, s.a, s.pa).has_value());  // the seed's single order
  const auto hit = detect_feature(Feature::Vertex, s.b, s.pb, s.a, s.pa);
  ASSERT_TRUE(hit.has_value());
  expect_vec_near(hit->point, Vec3(0, 0, 0.4), kDetectRoundOff);
  expect_vec_near(hit->normal, Vec3(0, 0, -1), kDetectRoundOff);
  EXPECT_NEAR(hit->depth, 0.1, kDetectRoundOff);
}

TEST(SeedCorrection, FaceNormalIsNegated) {
  // seed correction 9 (face normal negated). In the face-face configuration the first of A's
  // triangles inside B is triangle 2 ({1,3,7}, on the +x face): the seed takes its normal, +x,
  // which points from A toward B. Moving A along it deepens the overlap; moving A along ours by the
  // depth separates.
  const FaceFace s;
  const Vec3 literal = s.a.planes()[2].normal;
  expect_vec_near(literal, Vec3(1, 0, 0), kDetectRoundOff);
  const auto hit = face_test(s.a, s.pa, s.b, s.pb);
  ASSERT_TRUE(hit.has_value());
  const Vec3 b_to_a = s.pa.position - s.pb.position;
  EXPECT_LT(literal.dot(b_to_a), 0.0);
  EXPECT_GT(hit->normal.dot(b_to_a), 0.0);
  // Overlap after moving A by 0.05 along each: the literal grows it to 0.15 (measured along
  // the x axis), ours shrinks it to 0.05; by the full depth ours leaves the bodies touching.
  EXPECT_NEAR(overlap_along(s.a, shifted(s.pa, 0.05 * literal), s.b, s.pb, Vec3(-1, 0, 0)), 0.15,
              kDetectRoundOff);
  EXPECT_NEAR(overlap_along(s.a, shifted(s.pa, 0.05 * hit->normal), s.b, s.pb, Vec3(-1, 0, 0)),
              0.05, kDetectRoundOff);
  EXPECT_NEAR(overlap_along(s.a, shifted(s.pa, hit->depth * hit->normal), s.b, s.pb, hit->normal),
              0.0, kDetectRoundOff);
}

TEST(SeedCorrection, EdgeNormalIsEaCrossEb) {
  // seed correction 10 (edge normal e_a x e_b). The seed's "cross product of the edge with the
  // plane it is intersecting", e_a x n_plane, lies in that plane.
  {
    // Crossed bars: A's edge (along x) crosses B's planes x = -+0.5, whose normals are -+x, so
    // e_a x n_plane = 0: no direction at all. Ours is +z.
    const CrossedBars s;
    const Vec3 e_a(4, 0, 0);
    for (int f = 0; f < static_cast<int>(s.b.planes().size()); ++f)
      if (std::abs(s.b.planes()[f].normal.x()) == 1.0) {
        EXPECT_EQ(e_a.cross(s.b.planes()[f].normal).norm(), 0.0) << "face " << f;
      }
    const auto hit = edge_test(s.a, s.pa, s.b, s.pb);
    ASSERT_TRUE(hit.has_value());
    expect_vec_near(hit->normal, Vec3(0, 0, 1), kDetectRoundOff);
  }
  {
    // Tilted bar: e_a = (cos a, 0, -sin a) crosses B's top plane (normal z); the literal
    // e_a x z = (0, -cos a, 0) runs along B's edge, orthogonal to the true normal n, and A must
    // move 2.5 along -+y to clear B (B spans |y| <= 2, A |y| <= 0.5) against 0.1 along ours.
    const TiltedBar s;
    const Vec3 literal = s.e_a.cross(Vec3::UnitZ()).normalized();
    expect_vec_near(literal, Vec3(0, -1, 0), kDetectRoundOff);
    const auto hit = edge_test(s.a, s.pa, s.b, s.pb);
    ASSERT_TRUE(hit.has_value());
    EXPECT_NEAR(hit->normal.dot(literal), 0.0, kDetectRoundOff);
    expect_vec_near(hit->normal, s.n, kDetectRoundOff);
    EXPECT_NEAR(overlap_along(s.a, s.pa, s.b, s.pb, literal), 2.5, kDetectRoundOff);
    EXPECT_NEAR(overlap_along(s.a, s.pa, s.b, s.pb, -literal), 2.5, kDetectRoundOff);
    EXPECT_NEAR(hit->depth, 0.1, kDetectRoundOff);
  }
}

// ---- Cross-check against a separating-axis reference ------------------------------------------

// Independent reference: two convex polyhedra are disjoint iff some axis among their face normals
// and the cross products of their edge directions separates them. Returns the smallest overlap
// over those axes (the true penetration depth when positive; negative = separated).
double sat_min_overlap(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                       const Pose& pb) {
  std::vector<Vec3> va, vb, axes;
  for (const Vec3& v : a.vertices()) va.push_back(pa.apply(v));
  for (const Vec3& v : b.vertices()) vb.push_back(pb.apply(v));
  for (const Plane& p : a.planes()) axes.push_back(pa.orientation * p.normal);
  for (const Plane& p : b.planes()) axes.push_back(pb.orientation * p.normal);
  for (const Edge& ea : a.edges())
    for (const Edge& eb : b.edges()) {
      // Near-parallel edge pairs add no axis the face normals do not already cover, and their
      // cross product (edges are O(1) long) has an ill-defined direction below ~1e-9.
      const Vec3 c = (va[ea.b] - va[ea.a]).cross(vb[eb.b] - vb[eb.a]);
      if (c.norm() > 1e-9) axes.push_back(c.normalized());
    }
  double best = std::numeric_limits<double>::infinity();
  for (const Vec3& n : axes) {
    double amin = 1e300, amax = -1e300, bmin = 1e300, bmax = -1e300;
    for (const Vec3& v : va) amin = std::min(amin, v.dot(n)), amax = std::max(amax, v.dot(n));
    for (const Vec3& v : vb) bmin = std::min(bmin, v.dot(n)), bmax = std::max(bmax, v.dot(n));
    best = std::min(best, std::min(amax - bmin, bmax - amin));
  }
  return best;
}

TEST(Detect, AgreesWithSeparatingAxisOracle) {
  // Random poses (fixed seed) of a box against an icosahedron and against a prism, with centre
  // distances spread so roughly half the pairs touch. Invariants whatever the feature: a hit iff
  // the reference says the shapes overlap; unit normal; the point inside both shapes; the depth at
  // least the true penetration (overlap along any direction bounds the minimum from above).
  // Pairs within 1e-6 of touching are skipped: there the verdict rests on the 1e-9 tolerance.
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto random_rotation = [&] { return Quat(u(rng), u(rng), u(rng), u(rng)).normalized(); };
  const ConvexPolyhedron box = make_box(Vec3(1.0, 0.6, 0.8));
  const std::vector<ConvexPolyhedron> others = {make_icosphere(0.5, 0), make_prism(0.4, 1.0, 5)};
  int hits = 0, misses = 0;
  for (const ConvexPolyhedron& other : others) {
    for (int trial = 0; trial < 150; ++trial) {
      const Pose pa = pose_at(Vec3::Zero(), random_rotation());
      const double distance = 0.5 + 0.9 * (u(rng) + 1) / 2;  // m, in [0.5, 1.4]
      const Pose pb =
          pose_at(Vec3(u(rng), u(rng), u(rng)).normalized() * distance, random_rotation());
      const double truth = sat_min_overlap(box, pa, other, pb);
      if (std::abs(truth) < 1e-6) continue;
      const auto hit = detect(box, pa, other, pb);
      ASSERT_EQ(hit.has_value(), truth > 0) << "trial " << trial << " reference overlap " << truth;
      if (!hit) {
        ++misses;
        continue;
      }
      ++hits;
      const double tol = point_in_mesh_tolerance(box, other);
      EXPECT_NEAR(hit->normal.norm(), 1.0, kDetectRoundOff);
      EXPECT_TRUE(point_in_mesh(box, pa, hit->point, tol)) << "trial " << trial;
      EXPECT_TRUE(point_in_mesh(other, pb, hit->point, tol)) << "trial " << trial;
      EXPECT_GE(hit->depth, truth - kDetectRoundOff) << "trial " << trial;
    }
  }
  // Keep the sample representative: both outcomes well populated.
  EXPECT_GT(hits, 60);
  EXPECT_GT(misses, 60);
}

}  // namespace
}  // namespace rbx
