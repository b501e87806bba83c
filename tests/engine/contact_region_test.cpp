// The extended engine's contact: the chosen plane and the centre of the contact region.
#include "engine/contact_region.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "engine/detect.h"
#include "engine/manifold.h"
#include "tests/common/fixtures.h"

namespace rbx {
namespace {

using test::random_rotation;

std::optional<ContactPoint> contact(const ConvexPolyhedron& a, const Pose& pa,
                                    const ConvexPolyhedron& b, const Pose& pb) {
  DetectionCache cache;
  ContactScratch scratch;
  return find_contact(a, pa, b, pb, Detector::Accelerated, cache, scratch);
}

TEST(ContactRegion, StackedBoxesTakeTheCentreOfTheirFacesOverlap) {
  // Closed form: a unit cube whose bottom face (z = 0.45) sits 0.05 into the top face of a unit
  // cube below (z = 0.5), offset by (0.3, 0.2): the faces overlap on [-0.2, 0.5] x [-0.3, 0.5],
  // centre (0.15, 0.1), and the point lies midway between the two faces, at z = 0.475. The
  // seed's point (the mean of A's triangle centroids inside B) is not there.
  const ConvexPolyhedron cube = make_box(Vec3::Ones());
  const Pose pa{Vec3(0.3, 0.2, 0.95), Quat::Identity()}, pb{};
  const auto c = contact(cube, pa, cube, pb);
  ASSERT_TRUE(c);
  // Round-off of coordinates of order 1 m through the projections and the clipping.
  EXPECT_NEAR((c->point - Vec3(0.15, 0.1, 0.475)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((c->normal - Vec3::UnitZ()).norm(), 0.0, 1e-12);
  EXPECT_NEAR(c->depth, 0.05, 1e-12);
  EXPECT_EQ(c->feature, "face");
  const auto seed = detect(cube, pa, cube, pb);
  ASSERT_TRUE(seed);
  EXPECT_GT((seed->point - c->point).norm(), 1e-3);
}

TEST(ContactRegion, CrossedEdgesMeetAtTheirClosestPoints) {
  // Closed form: B, a unit cube turned 45 degrees about y, has its top edge along y at
  // z = sqrt(2)/2; A, turned 45 degrees about x and centred at z = 1.4, its bottom edge along x
  // at z = 1.4 - sqrt(2)/2. The edges cross above the origin, 2 sqrt(2)/2 - 1.4 apart, and the
  // point is their closest points' midpoint, (0, 0, 0.7).
  const ConvexPolyhedron cube = make_box(Vec3::Ones());
  const double q = std::sqrt(0.5);
  const Pose pa{Vec3(0.0, 0.0, 1.4), Quat(std::cos(M_PI / 8), std::sin(M_PI / 8), 0.0, 0.0)};
  const Pose pb{Vec3::Zero(), Quat(std::cos(M_PI / 8), 0.0, std::sin(M_PI / 8), 0.0)};
  const auto c = contact(cube, pa, cube, pb);
  ASSERT_TRUE(c);
  EXPECT_NEAR((c->point - Vec3(0.0, 0.0, 0.7)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(c->depth, 2.0 * q - 1.4, 1e-12);
  EXPECT_NEAR((c->normal - Vec3::UnitZ()).norm(), 0.0, 1e-12);
  EXPECT_EQ(c->feature, "edge");
}

TEST(ContactRegion, TheCentreIsTheSameFromEitherBodyOrder) {
  ContactScratch scratch;
  // Random overlapping pairs of boxes, prisms and icospheres (the scan's shapes and the search's):
  // the centre lies between the two shapes' features along the normal, and (B, A) gives the
  // same point bit for bit, the normal negated and the same depth. Tied poses (aligned shapes,
  // faces parallel, where the plane's keys may take either face as the reference) are among
  // them. (`rbx explore` scores the point against the exact oracle's manifold.)
  const std::vector<ConvexPolyhedron> all = {
      make_box(Vec3(1.0, 0.6, 0.3)), make_box(Vec3::Ones()), make_prism(0.5, 0.8, 6),
      make_prism(0.4, 1.2, 24),      make_icosphere(0.6, 1), make_icosphere(0.5, 3)};
  std::mt19937 rng(37);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(all.size()) - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int overlapping = 0, faces = 0, vertices = 0, edges = 0;
  for (int trial = 0; trial < 1000; ++trial) {
    const ConvexPolyhedron& a = all[pick(rng)];
    const ConvexPolyhedron& b = all[pick(rng)];
    const bool aligned = trial % 10 == 0;
    const Vec3 dir = aligned ? Vec3(0.0, 0.0, 1.0) : Vec3(random_rotation(rng) * Vec3::UnitX());
    const Pose pa{dir * unit(rng) * 1.2, aligned ? Quat::Identity() : random_rotation(rng)};
    const Pose pb{Vec3::Zero(), aligned ? Quat::Identity() : random_rotation(rng)};
    if (!choose_overlap_plane(a, pa, b, pb, scratch)) continue;
    ++overlapping;
    const auto ab = contact(a, pa, b, pb);
    const auto ba = contact(b, pb, a, pa);
    ASSERT_TRUE(ab && ba) << "trial " << trial;
    EXPECT_EQ(ab->point, ba->point) << "trial " << trial;
    EXPECT_EQ(ab->normal, Vec3(-ba->normal)) << "trial " << trial;
    EXPECT_EQ(ab->depth, ba->depth) << "trial " << trial;
    // Along the normal, the centre lies between the two features: no lower than A's lowest
    // point and no higher than B's highest (the depth apart), to round-off.
    const Vec3& n = ab->normal;
    double low_a = std::numeric_limits<double>::infinity();
    double high_b = -low_a;
    for (const Vec3& v : a.vertices()) low_a = std::min(low_a, pa.apply(v).dot(n));
    for (const Vec3& v : b.vertices()) high_b = std::max(high_b, pb.apply(v).dot(n));
    EXPECT_GE(ab->point.dot(n), low_a - 1e-12) << "trial " << trial;
    EXPECT_LE(ab->point.dot(n), high_b + 1e-12) << "trial " << trial;
    EXPECT_NEAR(high_b - low_a, ab->depth, 1e-12) << "trial " << trial;
    faces += ab->feature == "face";
    vertices += ab->feature == "vertex";
    edges += ab->feature == "edge";
  }
  EXPECT_GT(overlapping, 500);
  // Every kind of region is among them (faces from the aligned poses, the rarest).
  EXPECT_GT(faces, 5);
  EXPECT_GT(vertices, 100);
  EXPECT_GT(edges, 100);
}

TEST(ContactRegion, AScratchReusedByEveryQueryGivesTheAnswersOfAFreshOne) {
  // The scratch a world's step or a backend keeps is only storage: a query on a scratch that
  // earlier queries of other shapes, sizes and kinds of contact have filled gives, to the last
  // bit, the answer of a scratch made for that query alone.
  const std::vector<ConvexPolyhedron> all = {make_box(Vec3(1.0, 0.6, 0.3)), make_box(Vec3::Ones()),
                                             make_prism(0.4, 1.2, 24), make_icosphere(0.5, 3),
                                             make_icosphere(0.6, 1)};
  std::mt19937 rng(4242);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(all.size()) - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  DetectionCache kept_cache;
  ContactScratch kept;
  int hits = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const ConvexPolyhedron& a = all[pick(rng)];
    const ConvexPolyhedron& b = all[pick(rng)];
    const Pose pa{random_rotation(rng) * Vec3::UnitX() * unit(rng) * 1.4, random_rotation(rng)};
    const Pose pb{Vec3::Zero(), random_rotation(rng)};
    const auto reused = find_contact(a, pa, b, pb, Detector::Accelerated, kept_cache, kept);
    const auto fresh = contact(a, pa, b, pb);
    ASSERT_EQ(reused.has_value(), fresh.has_value()) << "trial " << trial;
    if (!fresh) continue;
    ++hits;
    EXPECT_EQ(reused->point, fresh->point) << "trial " << trial;
    EXPECT_EQ(reused->normal, fresh->normal) << "trial " << trial;
    EXPECT_EQ(reused->depth, fresh->depth) << "trial " << trial;
    EXPECT_EQ(reused->feature, fresh->feature) << "trial " << trial;
    const auto manifold_reused =
        build_manifold(a, pa, b, pb, Detector::Accelerated, 1e-4, kept_cache, kept);
    const auto manifold_fresh = build_manifold(a, pa, b, pb, Detector::Accelerated, 1e-4);
    ASSERT_EQ(manifold_reused.has_value(), manifold_fresh.has_value()) << "trial " << trial;
    if (!manifold_fresh) continue;
    EXPECT_EQ(manifold_reused->normal, manifold_fresh->normal) << "trial " << trial;
    ASSERT_EQ(manifold_reused->points.size(), manifold_fresh->points.size()) << "trial " << trial;
    for (size_t k = 0; k < manifold_fresh->points.size(); ++k)
      EXPECT_EQ(manifold_reused->points[k].point, manifold_fresh->points[k].point);
  }
  // Most poses overlap or touch (centres at most 1.4 apart, shapes of radius 0.3-0.87).
  EXPECT_GT(hits, 150);
}

TEST(ContactRegion, ShapesNotProvedToOverlapAreLeftToTheDetector) {
  ContactScratch scratch;
  // Touching faces (no overlap to prove) and a gap: the detector decides, as for `custom-seed`'s
  // tests; touching gives its point on the plane, apart gives nothing.
  const ConvexPolyhedron cube = make_box(Vec3::Ones());
  const Pose pb{};
  const Pose touching{Vec3(0.2, 0.1, 1.0), Quat::Identity()};
  EXPECT_FALSE(choose_overlap_plane(cube, touching, cube, pb, scratch));
  const auto c = contact(cube, touching, cube, pb);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->depth, 0.0);
  EXPECT_EQ(c->point, detect(cube, touching, cube, pb)->point);
  EXPECT_FALSE(contact(cube, Pose{Vec3(0.0, 0.0, 1.01), Quat::Identity()}, cube, pb));
}

}  // namespace
}  // namespace rbx
