// The chosen contact plane: the direction of least overlap, the same from either body order.
#include "engine/contact_plane.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "engine/detect.h"

namespace rbx {
namespace {

Quat random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  return Quat(g(rng), g(rng), g(rng), g(rng)).normalized();
}

// Shapes of every path of the chooser: small ones scanned (box, prism), hierarchies climbed
// (icospheres of 80 and 320 triangles, a 24-sided prism).
std::vector<ConvexPolyhedron> shapes() {
  return {make_box(Vec3(1.0, 0.6, 0.3)), make_box(Vec3(2.0, 2.0, 0.05)), make_prism(0.5, 0.8, 6),
          make_prism(0.4, 1.2, 24),      make_icosphere(0.6, 1),         make_icosphere(0.5, 2)};
}

double radius(const ConvexPolyhedron& s) {
  double r = 0.0;
  for (const Vec3& v : s.vertices()) r = std::max(r, v.norm());
  return r;
}

// Two of `all`, turned at random, A's centre a random fraction of the sum of their radii from
// B's in a random direction: overlapping, touching or apart.
struct RandomPair {
  const ConvexPolyhedron* a = nullptr;
  const ConvexPolyhedron* b = nullptr;
  Pose pa, pb;
};
RandomPair random_pair(const std::vector<ConvexPolyhedron>& all, std::mt19937& rng) {
  std::uniform_int_distribution<int> pick(0, static_cast<int>(all.size()) - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  RandomPair p;
  p.a = &all[pick(rng)];
  p.b = &all[pick(rng)];
  const Vec3 dir = random_rotation(rng) * Vec3::UnitX();
  p.pa = {dir * unit(rng) * (radius(*p.a) + radius(*p.b)), random_rotation(rng)};
  p.pb = {Vec3::Zero(), random_rotation(rng)};
  return p;
}

TEST(ContactPlane, AxisAlignedBoxesTakeTheAxisOfLeastOverlap) {
  // Closed form: two axis-aligned boxes overlap by (h_a + h_b) - |c_a - c_b| on each axis, and
  // the least of the three is the depth along that axis, pointing from B's centre to A's.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> size(0.1, 2.0), unit(-1.0, 1.0);
  int checked = 0, first_hit_wrong = 0;
  for (int trial = 0; trial < 1000; ++trial) {
    const Vec3 sa(size(rng), size(rng), size(rng)), sb(size(rng), size(rng), size(rng));
    const Vec3 reach = 0.5 * (sa + sb);
    const Vec3 d(unit(rng) * reach.x(), unit(rng) * reach.y(), unit(rng) * reach.z());
    const Vec3 overlap = reach - d.cwiseAbs();
    int axis = 0;
    overlap.minCoeff(&axis);
    // A near tie between two axes has either as its answer; skip it (1e-6 m, far above
    // round-off, so the expected axis is unambiguous).
    Vec3 others = overlap;
    others[axis] = 1e300;
    if (others.minCoeff() - overlap[axis] < 1e-6 || overlap[axis] < 1e-6) continue;
    const ConvexPolyhedron a = make_box(sa), b = make_box(sb);
    const Pose pa{d, Quat::Identity()}, pb{Vec3::Zero(), Quat::Identity()};
    const ContactPlane p = choose_contact_plane(a, pa, b, pb);
    Vec3 expected = Vec3::Zero();
    expected[axis] = d[axis] > 0 ? 1.0 : -1.0;
    EXPECT_NEAR((p.normal - expected).norm(), 0.0, 1e-12) << "trial " << trial;
    // Round-off: projections of coordinates of order 1 m.
    EXPECT_NEAR(p.depth, overlap[axis], 1e-12) << "trial " << trial;
    ++checked;
    // The seed's first hit, for contrast: the test above is one it fails.
    const auto hit = detect(a, pa, b, pb, DetectorVariant::Faithful);
    if (hit && (hit->normal - expected).norm() > 1e-6) ++first_hit_wrong;
  }
  EXPECT_GT(checked, 500);
  EXPECT_GT(first_hit_wrong, 0) << "the first-hit normal passes this test too: it proves nothing";
}

TEST(ContactPlane, EitherBodyOrderGivesTheSameContactReversed) {
  std::mt19937 rng(11);
  const std::vector<ConvexPolyhedron> all = shapes();
  int touching = 0;
  for (int trial = 0; trial < 1000; ++trial) {
    const RandomPair r = random_pair(all, rng);
    const ConvexPolyhedron &a = *r.a, &b = *r.b;
    const Pose &pa = r.pa, &pb = r.pb;
    if (!detect(a, pa, b, pb)) continue;
    ++touching;
    const ContactPlane ab = choose_contact_plane(a, pa, b, pb);
    const ContactPlane ba = choose_contact_plane(b, pb, a, pa);
    // Round-off: a hierarchy's projections are climbed from different start vertices in the two
    // orders, so overlaps may differ by a few ulps of coordinates of order 1 m.
    EXPECT_NEAR((ab.normal + ba.normal).norm(), 0.0, 1e-9) << "trial " << trial;
    EXPECT_NEAR(ab.depth, ba.depth, 1e-12) << "trial " << trial;
  }
  EXPECT_GT(touching, 300);
}

TEST(ContactPlane, NoDirectionSeparatesWithASmallerMove) {
  // The least overlap over all directions is the penetration depth: the chosen depth is the
  // overlap along the chosen normal, and no other direction (sampled) has a smaller one.
  std::mt19937 rng(13);
  const std::vector<ConvexPolyhedron> all = shapes();
  int touching = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const RandomPair r = random_pair(all, rng);
    const ConvexPolyhedron &a = *r.a, &b = *r.b;
    const Pose &pa = r.pa, &pb = r.pb;
    if (!detect(a, pa, b, pb)) continue;
    ++touching;
    const ContactPlane p = choose_contact_plane(a, pa, b, pb);
    // Round-off of a projection difference on coordinates of order 1 m.
    EXPECT_NEAR(overlap_along(a, pa, b, pb, p.normal), p.depth, 1e-12) << "trial " << trial;
    for (int k = 0; k < 200; ++k) {
      const Vec3 n = random_rotation(rng) * Vec3::UnitZ();
      EXPECT_GE(overlap_along(a, pa, b, pb, n), p.depth - 1e-12) << "trial " << trial;
    }
  }
  EXPECT_GT(touching, 100);
}

}  // namespace
}  // namespace rbx
