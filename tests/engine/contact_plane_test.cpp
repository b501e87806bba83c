// The chosen contact plane: the direction of least overlap, the same from either body order.
#include "engine/contact_plane.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "engine/contact_plane_detail.h"
#include "engine/detect.h"
#include "tests/common/fixtures.h"

namespace rbx {
namespace {

using test::random_rotation;

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
    const auto hit = detect(a, pa, b, pb, Detector::Faithful);
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
    for (const PlaneMethod method : {PlaneMethod::Scan, PlaneMethod::Search}) {
      const ContactPlane ab = choose_contact_plane(a, pa, b, pb, method);
      const ContactPlane ba = choose_contact_plane(b, pb, a, pa, method);
      // Round-off: projections are climbed from different start vertices in the two orders, so
      // overlaps may differ by a few ulps of coordinates of order 1 m.
      EXPECT_NEAR((ab.normal + ba.normal).norm(), 0.0, 1e-9) << "trial " << trial;
      EXPECT_NEAR(ab.depth, ba.depth, 1e-12) << "trial " << trial;
    }
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

// An icosphere stretched along the axes: an ellipsoid-like hull whose face normals and edges
// are in no special position (a linear map keeps faces flat and the shape convex).
ConvexPolyhedron stretched_icosphere(int subdivisions, const Vec3& scale) {
  const ConvexPolyhedron s = make_icosphere(0.5, subdivisions);
  std::vector<Vec3> v;
  for (const Vec3& p : s.vertices()) v.push_back(p.cwiseProduct(scale));
  return ConvexPolyhedron::from_triangles(v, s.triangles());
}

// The least overlap by brute force, written without the chooser's search: along every face
// normal of either shape and every cross product of an edge of A and an edge of B, both signs.
// Every one of those directions overlaps by at least the least overlap, and the face normals of
// the Minkowski difference are among them, so the minimum is the least overlap.
double least_overlap_by_brute_force(const ConvexPolyhedron& a, const Pose& pa,
                                    const ConvexPolyhedron& b, const Pose& pb) {
  std::vector<Vec3> va, vb, axes;
  for (const Vec3& v : a.vertices()) va.push_back(pa.apply(v));
  for (const Vec3& v : b.vertices()) vb.push_back(pb.apply(v));
  for (const Plane& p : a.planes()) axes.push_back(pa.rotation() * p.normal);
  for (const Plane& p : b.planes()) axes.push_back(pb.rotation() * p.normal);
  for (const Edge& ea : a.edges())
    for (const Edge& eb : b.edges()) {
      const Vec3 d = (va[ea.b] - va[ea.a]).cross(vb[eb.b] - vb[eb.a]);
      if (d.norm() > 1e-9) axes.push_back(d.normalized());
    }
  // Along n, A must move max_b (b . n) - min_a (a . n) to clear B; along -n, the reverse.
  double least = std::numeric_limits<double>::infinity();
  for (const Vec3& n : axes) {
    double a_lo = 1e300, a_hi = -1e300, b_lo = 1e300, b_hi = -1e300;
    for (const Vec3& v : va) {
      a_lo = std::min(a_lo, v.dot(n));
      a_hi = std::max(a_hi, v.dot(n));
    }
    for (const Vec3& v : vb) {
      b_lo = std::min(b_lo, v.dot(n));
      b_hi = std::max(b_hi, v.dot(n));
    }
    least = std::min({least, b_hi - a_lo, a_hi - b_lo});
  }
  return std::max(least, 0.0);  // the chooser's depth is clamped at 0 likewise
}

TEST(ContactPlane, TheSearchFindsTheLeastOverlapOfEveryCandidate) {
  // The scan skips faces and edges on bounds, the search whole cones of them; on shapes in no
  // special position (stretched icospheres) and on ones full of ties (boxes, prisms, icospheres),
  // deep and shallow, it must find the same least overlap as trying every candidate.
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> stretch(0.5, 1.5);
  // Shapes of at most 120 edges, so that every pair of edges can be tried.
  std::vector<ConvexPolyhedron> all = {make_box(Vec3(1.0, 0.6, 0.3)),
                                       make_box(Vec3(2.0, 2.0, 0.05)), make_prism(0.4, 1.2, 24),
                                       make_icosphere(0.6, 1)};
  for (int k = 0; k < 4; ++k)
    all.push_back(stretched_icosphere(1, Vec3(stretch(rng), stretch(rng), stretch(rng))));
  int touching = 0;
  for (int trial = 0; trial < 500; ++trial) {
    const RandomPair r = random_pair(all, rng);
    if (!detect(*r.a, r.pa, *r.b, r.pb)) continue;
    ++touching;
    const double least = least_overlap_by_brute_force(*r.a, r.pa, *r.b, r.pb);
    for (const PlaneMethod method : {PlaneMethod::Scan, PlaneMethod::Search}) {
      const ContactPlane p = choose_contact_plane(*r.a, r.pa, *r.b, r.pb, method);
      // Round-off: projections of coordinates of order 1 m, by the chooser in the body frames
      // and here in the world frame.
      EXPECT_NEAR(p.depth, least, 1e-12) << "trial " << trial;
    }
  }
  EXPECT_GT(touching, 200);
}

TEST(ContactPlane, TheScanAndTheSearchChooseTheSamePlane) {
  // On shapes too large for the brute force (hulls of up to 2,562 vertices, stretched so that
  // no two directions tie by symmetry), deep and shallow: the two methods, one linear and one a
  // branch and bound, agree on the depth and the normal.
  std::mt19937 rng(19);
  const std::vector<ConvexPolyhedron> all = {
      stretched_icosphere(2, Vec3(1.3, 0.7, 1.0)), stretched_icosphere(3, Vec3(0.6, 1.4, 0.9)),
      stretched_icosphere(4, Vec3(1.0, 0.8, 1.2)), make_box(Vec3(0.9, 0.4, 0.7))};
  int touching = 0;
  for (int trial = 0; trial < 120; ++trial) {
    const RandomPair r = random_pair(all, rng);
    if (!detect(*r.a, r.pa, *r.b, r.pb)) continue;
    ++touching;
    const ContactPlane scan = choose_contact_plane(*r.a, r.pa, *r.b, r.pb, PlaneMethod::Scan);
    const ContactPlane search = choose_contact_plane(*r.a, r.pa, *r.b, r.pb, PlaneMethod::Search);
    // Round-off: the two compute the same overlaps in the world and in the body frames.
    EXPECT_NEAR(scan.depth, search.depth, 1e-12) << "trial " << trial;
    EXPECT_NEAR((scan.normal - search.normal).norm(), 0.0, 1e-9) << "trial " << trial;
  }
  EXPECT_GT(touching, 40);
}

TEST(ContactPlane, AKnownOverlapChangesNothing) {
  // The detector's normal and depth (the overlap along it) given as the known overlap: the plane
  // is the same bit for bit, by either method, whether the detector's normal was the answer or
  // a worse one (the second count: the bound was not the answer itself).
  std::mt19937 rng(23);
  const std::vector<ConvexPolyhedron> all = {
      stretched_icosphere(1, Vec3(1.3, 0.7, 1.0)), stretched_icosphere(3, Vec3(0.6, 1.4, 0.9)),
      make_prism(0.4, 1.2, 24), make_box(Vec3(0.9, 0.4, 0.7)), make_box(Vec3(1.0, 1.0, 1.0))};
  int touching = 0, worse = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const RandomPair r = random_pair(all, rng);
    const auto hit = detect(*r.a, r.pa, *r.b, r.pb);
    if (!hit) continue;
    ++touching;
    for (const PlaneMethod method : {PlaneMethod::Scan, PlaneMethod::Search}) {
      const ContactPlane plain = choose_contact_plane(*r.a, r.pa, *r.b, r.pb, method);
      const ContactPlane known =
          choose_contact_plane(*r.a, r.pa, *r.b, r.pb, hit->normal, hit->depth, method);
      EXPECT_EQ(known.normal, plain.normal) << "trial " << trial;
      EXPECT_EQ(known.depth, plain.depth) << "trial " << trial;
      EXPECT_EQ(known.axis, plain.axis) << "trial " << trial;
      if (method == PlaneMethod::Scan && hit->depth > plain.depth + 1e-6) ++worse;
    }
  }
  EXPECT_GT(touching, 150);
  EXPECT_GT(worse, 30);
}

TEST(ContactPlane, TheInnerPolytopeNarrowsTheSearchWithoutChangingThePlane) {
  // The search narrowed to the inner polytope's cone chooses the plane of the search over every
  // direction, bit for bit, in either body order: on shapes in general position, deep and
  // shallow, and on poses full of ties (axis-aligned boxes overlapping equally along two or three
  // axes, where every tied face must stay inside the cone for the keys to pick the same one).
  std::mt19937 rng(29);
  const std::vector<ConvexPolyhedron> all = {stretched_icosphere(2, Vec3(1.3, 0.7, 1.0)),
                                             stretched_icosphere(3, Vec3(0.6, 1.4, 0.9)),
                                             make_prism(0.4, 1.2, 24),
                                             make_icosphere(0.5, 2),
                                             make_box(Vec3(0.9, 0.4, 0.7)),
                                             make_box(Vec3(1.0, 1.0, 1.0))};
  std::vector<RandomPair> poses;
  for (int trial = 0; trial < 300; ++trial) poses.push_back(random_pair(all, rng));
  const ConvexPolyhedron& cube = all.back();
  for (const Vec3& c : {Vec3(0.8, 0.8, 0.0), Vec3(0.8, 0.0, 0.8), Vec3(0.9, 0.9, 0.9),
                        Vec3(-0.7, 0.7, 0.0), Vec3(0.0, 0.0, 0.6)})
    poses.push_back({&cube, &cube, Pose{c, Quat::Identity()}, Pose{}});
  int overlapping = 0;
  for (const RandomPair& r : poses) {
    const ContactPlane whole =
        choose_contact_plane(*r.a, r.pa, *r.b, r.pb, PlaneMethod::WholeSearch);
    if (whole.depth > 0) ++overlapping;
    const ContactPlane narrowed = choose_contact_plane(*r.a, r.pa, *r.b, r.pb, PlaneMethod::Search);
    EXPECT_EQ(narrowed.normal, whole.normal);
    EXPECT_EQ(narrowed.depth, whole.depth);
    EXPECT_EQ(narrowed.axis, whole.axis);
    const ContactPlane swapped = choose_contact_plane(*r.b, r.pb, *r.a, r.pa, PlaneMethod::Search);
    EXPECT_EQ(swapped.normal, Vec3(-whole.normal));
    EXPECT_EQ(swapped.depth, whole.depth);
  }
  EXPECT_GT(overlapping, 150);
}

TEST(ContactPlane, TheInnerPolytopeBoundsOverlappingShapesOnly) {
  ContactScratch scratch;  // reused by every query below: answers do not depend on it
  // Overlapping shapes: the polytope bounds the least overlap from above (to round-off, at most
  // the whole search's answer plus its tie margin) and leaves a narrow cone around the answer's
  // direction (D's direction is minus the normal). Apart or touching: it declines.
  const ConvexPolyhedron a = stretched_icosphere(3, Vec3(0.6, 1.4, 0.9));
  const ConvexPolyhedron b = make_icosphere(0.5, 2);
  std::mt19937 rng(31);
  int narrowed = 0;
  for (int trial = 0; trial < 50; ++trial) {
    const Pose pa{Vec3::Zero(), random_rotation(rng)};
    const Vec3 dir = random_rotation(rng) * Vec3::UnitX();
    for (const double gap : {-0.3, -0.01, 0.01}) {
      // Slide B along dir until it just touches, then by `gap` (negative: into A).
      double lo = 0.0, hi = 4.0;
      for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (lo + hi);
        (choose_contact_plane(a, pa, b, Pose{mid * dir, Quat::Identity()}).depth > 0 ? lo : hi) =
            mid;
      }
      const Pose pb{(lo + gap) * dir, Quat::Identity()};
      plane_detail::Side sa, sb;
      sa.set(a, pa);
      sb.set(b, pb);
      plane_detail::Candidates out;
      const double tie = 1e-12 * 4.0;
      const bool bounded = plane_detail::inner_polytope_bound(sa, sb, tie, out, scratch.lists());
      if (gap > 0) {
        EXPECT_FALSE(bounded) << "apart by " << gap;
        continue;
      }
      ASSERT_TRUE(bounded) << "trial " << trial;
      const ContactPlane whole = choose_contact_plane(a, pa, b, pb, PlaneMethod::WholeSearch);
      // Round-off of the polytope's support points against the search's projections.
      EXPECT_LE(out.known, whole.depth + 1e-12);
      EXPECT_GE(out.known, whole.depth - 1e-12);
      ASSERT_FALSE(out.within.whole);
      EXPECT_GE((-whole.normal).dot(out.within.axis), out.within.cos_angle);
      if (out.within.cos_angle > std::cos(1e-3)) ++narrowed;
    }
  }
  EXPECT_EQ(narrowed, 100);
}

TEST(ContactPlane, AThinBoxTouchingAnInclineToRoundOffIsNotProvedToOverlap) {
  // Found by `rbx explore --kind slide --seed 5151` (sample 115, 22 steps into its slide): a
  // 0.49 x 0.20 x 0.049 box lying on a 2 x 2 x 1 slab turned 8 degrees, touching it to round-off
  // (the exact oracle: depth 0). The inner polytope of A - B lost the triangles of its flat side
  // and converged on the far one, claiming an overlap of the whole far extent; the
  // plane came out reversed, the box was pushed through the slab. No proof now: the detector
  // decides, and the plane is the incline's normal at depth 0 (round-off of the projections).
  const ConvexPolyhedron box =
      make_box(Vec3(0.49186999693005107, 0.20303316519286502, 0.04851776049023319));
  const ConvexPolyhedron slab = make_box(Vec3(2.0, 2.0, 1.0));
  const Pose pa{
      Vec3(-0.024349626091067424, -0.00082976707039938166, 0.021004003527903884),
      Quat(0.74784455522919169, -0.045377256200631641, -0.055088174476571057, 0.66002630164758869)};
  const Pose pb{Vec3(0.0711475739288374, 0.0024245100834058343, -0.4949061976525411),
                Quat(0.9974498471865847, 0.0024307087621943373, -0.071329474990163, 0.0)};
  ContactScratch scratch;
  EXPECT_FALSE(choose_overlap_plane(box, pa, slab, pb, scratch));
  EXPECT_FALSE(choose_overlap_plane(slab, pb, box, pa, scratch));
  const Vec3 up = pb.orientation * Vec3::UnitZ();
  for (const PlaneMethod m :
       {PlaneMethod::Automatic, PlaneMethod::Scan, PlaneMethod::WholeSearch}) {
    const ContactPlane p = choose_contact_plane(box, pa, slab, pb, m);
    EXPECT_GT(p.normal.dot(up), 1.0 - 1e-12) << static_cast<int>(m);
    EXPECT_LE(p.depth, 1e-12) << static_cast<int>(m);
  }
}

TEST(ContactPlane, TheInnerPolytopeProvesOverlapOnPosesOfRoundCoordinates) {
  ContactScratch scratch;  // reused by every query below: answers do not depend on it
  // Stacked axis-aligned boxes at offsets of round decimals, as scenes place them: GJK's
  // tetrahedron then often has the origin exactly on a face plane, which the polytope must grow
  // past rather than give up. Closed form: the overlap along z is the depth, the normal is +-z.
  const ConvexPolyhedron b = make_box(Vec3(1.0, 1.0, 1.0));
  int proved = 0, cases = 0;
  for (const Vec3& size : {Vec3(1.0, 1.0, 1.0), Vec3(0.5, 0.8, 0.6), Vec3(2.0, 2.0, 0.3)}) {
    const ConvexPolyhedron a = make_box(size);
    for (int i = -3; i <= 3; ++i)
      for (int j = -3; j <= 3; ++j)
        for (const double depth : {0.05, 0.1})
          for (const double up : {1.0, -1.0}) {
            const double z = up * (0.5 * (size.z() + 1.0) - depth);
            const Pose pa{Vec3(0.1 * i, 0.1 * j, z), Quat::Identity()}, pb{};
            ++cases;
            plane_detail::Side sa, sb;
            sa.set(a, pa);
            sb.set(b, pb);
            plane_detail::Candidates out;
            if (plane_detail::inner_polytope_bound(sa, sb, 1e-12 * 4.0, out, scratch.lists()))
              ++proved;
            for (const bool swap : {false, true}) {
              const auto p = swap ? choose_overlap_plane(b, pb, a, pa, scratch)
                                  : choose_overlap_plane(a, pa, b, pb, scratch);
              ASSERT_TRUE(p) << "offset " << i << " " << j << " depth " << depth;
              // Round-off of coordinates of order 1 m.
              EXPECT_NEAR(p->depth, depth, 1e-12);
              EXPECT_NEAR(std::abs(p->normal.z()), 1.0, 1e-12);
            }
          }
  }
  EXPECT_EQ(proved, cases);
}

TEST(ContactPlane, LevelAndStackedPosesAreProvedAndReversedInEitherOrder) {
  ContactScratch scratch;  // reused by every query below: answers do not depend on it
  // Poses as scenes write them: shapes turned about z by multiples of 15 degrees, placed at
  // decimal offsets, many level with each other (equal overlap along +z and -z) or centred on
  // each other. Every pair that overlaps by more than round-off must be proved to overlap in
  // both body orders (not left to the seed's detector) and give the normal reversed: where the
  // two senses of an axis tie, the bodies' positions decide. Identical poses are skipped (there
  // the two orders are the same query).
  const std::vector<ConvexPolyhedron> all = {make_box(Vec3(1.0, 0.6, 0.3)), make_box(Vec3::Ones()),
                                             make_prism(0.5, 0.8, 6), make_icosphere(0.6, 1)};
  int overlapping = 0, level = 0;
  for (const ConvexPolyhedron& a : all)
    for (const ConvexPolyhedron& b : all)
      for (int turn = 0; turn < 4; ++turn)
        for (int i = -4; i <= 4; ++i)
          for (int j = -4; j <= 4; j += 2)
            for (int k = 0; k < 6; ++k) {
              const Vec3 at =
                  k < 4 ? Vec3(0.1 * i, 0.1 * j, 0.2 * k) : Vec3(0.2 * (k - 3), 0.1 * i, 0.05 * j);
              const Pose pa{at, Quat(Eigen::AngleAxisd(turn * M_PI / 12, Vec3::UnitZ()))};
              const Pose pb{};
              if (turn == 0 && at == Vec3::Zero()) continue;
              const ContactPlane whole =
                  choose_contact_plane(a, pa, b, pb, PlaneMethod::WholeSearch);
              if (!(whole.depth > 1e-9)) continue;
              ++overlapping;
              if (at.z() == 0) ++level;
              const auto ab = choose_overlap_plane(a, pa, b, pb, scratch);
              const auto ba = choose_overlap_plane(b, pb, a, pa, scratch);
              ASSERT_TRUE(ab && ba) << "turn " << turn << " at " << at.transpose();
              // Round-off: the two orders climb from different vertices (as in
              // EitherBodyOrderGivesTheSameContactReversed).
              EXPECT_NEAR((ab->normal + ba->normal).norm(), 0.0, 1e-9)
                  << "turn " << turn << " at " << at.transpose();
              EXPECT_NEAR(ab->depth, whole.depth, 1e-12);
              EXPECT_NEAR(ba->depth, whole.depth, 1e-12);
            }
  EXPECT_GT(overlapping, 10000);
  EXPECT_GT(level, 2000);
}

}  // namespace
}  // namespace rbx
