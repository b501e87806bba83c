// The accelerated detector against the faithful detector's loops (its reference): on thousands of
// fixed-seed poses of boxes, prisms and (sheared) icospheres from 8 to 642 vertices, touching, deep
// and separated, the fast path returns the same hit or miss, feature, point, normal and depth as
// the faithful path, for the full detector and for each feature test alone (the world calls those).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "engine/detect.h"
#include "engine/detect_accelerated.h"

namespace rbx {
namespace {

// The fast path evaluates the faithful path's own floating-point expressions on the same
// world-frame data and only skips evaluations a bound proves irrelevant, so its answers are
// expected to be bit-identical: every comparison below is exact (no tolerance).
void expect_same(const std::optional<ContactPoint>& fast,
                 const std::optional<ContactPoint>& faithful, const std::string& where) {
  ASSERT_EQ(fast.has_value(), faithful.has_value()) << where;
  if (!faithful) return;
  EXPECT_EQ(fast->feature, faithful->feature) << where;
  EXPECT_EQ(fast->point, faithful->point) << where << "\n fast " << fast->point.transpose()
                                          << "\n faithful " << faithful->point.transpose();
  EXPECT_EQ(fast->normal, faithful->normal) << where << "\n fast " << fast->normal.transpose()
                                            << "\n faithful " << faithful->normal.transpose();
  EXPECT_EQ(fast->depth, faithful->depth) << where;
}

Quat random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  return Quat(g(rng), g(rng), g(rng), g(rng)).normalized();
}

Vec3 random_direction(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  Vec3 d(g(rng), g(rng), g(rng));
  return d.normalized();
}

// An icosphere under a fixed shear and stretch: convex (a linear image of a convex polyhedron),
// with no symmetry left, so ties between faces are as rare as in generic hulls.
ConvexPolyhedron sheared_icosphere(int subdivisions) {
  const ConvexPolyhedron s = make_icosphere(0.5, subdivisions);
  Mat3 m;
  m << 1.0, 0.2, 0.0, 0.0, 0.8, 0.1, 0.1, 0.0, 0.6;
  std::vector<Vec3> v;
  for (const Vec3& p : s.vertices()) v.push_back(m * p);
  return ConvexPolyhedron::from_triangles(v, s.triangles());
}

// Extent (m) of a shape along a world direction d at a pose: its support value h(d).
double support(const ConvexPolyhedron& s, const Pose& p, const Vec3& d) {
  double h = -1e300;
  for (const Vec3& v : s.vertices()) h = std::max(h, p.apply(v).dot(d));
  return h;
}

constexpr Feature kFeatures[] = {Feature::Face, Feature::Vertex, Feature::Edge};

struct Tally {
  int hits = 0, misses = 0;
  std::map<std::string, int> features;
};

// Compares the two detectors at one pose: the full detector and each feature test alone.
void compare_at(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                const Pose& pb, const std::string& where, Tally& tally) {
  const auto faithful = detect(a, pa, b, pb, Detector::Faithful);
  const auto fast = detect(a, pa, b, pb, Detector::Accelerated);
  expect_same(fast, faithful, where);
  if (faithful) {
    ++tally.hits;
    ++tally.features[faithful->feature];
  } else {
    ++tally.misses;
  }
  for (Feature feature : kFeatures)
    expect_same(detect_feature(feature, a, pa, b, pb, Detector::Accelerated),
                detect_feature(feature, a, pa, b, pb, Detector::Faithful),
                where + " feature " + to_string(feature));
}

// Under the sanitizers (RBX_SANITIZE, CMakeLists.txt) a third of the random poses: there they look
// for memory errors and undefined behaviour, which the same code paths meet at a third of the
// count, while the faithful reference's tests cost ten times more; the Release pass runs every
// pose.
#if defined(RBX_SANITIZE)
constexpr int kPoseDivisor = 3;
#else
constexpr int kPoseDivisor = 1;
#endif

// Random poses of a pair: B placed along a random direction d at the support-plane distance
// h_A(d) + h_B(-d), then moved by `offset` times the larger size along d (negative: pushed
// in) and by a small random sideways shift. Offsets: touching (within 1% of the size either
// way), deep (10-30%), separated (1-10%).
void random_poses(const ConvexPolyhedron& a, const ConvexPolyhedron& b, int count, uint64_t seed,
                  const std::string& name, Tally& tally) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double size =
      std::max((a.bounds().max - a.bounds().min).norm(), (b.bounds().max - b.bounds().min).norm());
  for (int i = 0; i < count / kPoseDivisor; ++i) {
    Pose pa, pb;
    pa.position = Vec3(unit(rng), unit(rng), unit(rng)) - Vec3::Constant(0.5);
    pa.orientation = random_rotation(rng);
    pb.orientation = random_rotation(rng);
    const Vec3 d = random_direction(rng);
    pb.position = pa.position;
    const double reach =
        support(a, pa, d) + support(b, pb, -d) - pb.position.dot(d) + pa.position.dot(d);
    double offset;
    switch (i % 3) {
      case 0:
        offset = 0.02 * unit(rng) - 0.01;
        break;  // touching
      case 1:
        offset = -0.1 - 0.2 * unit(rng);
        break;  // deep
      default:
        offset = 0.01 + 0.09 * unit(rng);
        break;  // separated
    }
    pb.position = pa.position + (reach + offset * size) * d + 0.05 * size * random_direction(rng);
    compare_at(a, pa, b, pb, name + " pose " + std::to_string(i), tally);
  }
}

// Structured poses where ties decide the answer: axis-aligned orientations (multiples of 90
// degrees) and offsets on a grid of quarter sizes, so faces are coplanar, vertices land exactly
// on faces and edges on edges.
void grid_poses(const ConvexPolyhedron& a, const ConvexPolyhedron& b, const std::string& name,
                Tally& tally) {
  const Quat quarter_turns[] = {Quat::Identity(), Quat(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX())),
                                Quat(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ())),
                                Quat(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitZ()))};
  const double step = 0.25 * (b.bounds().max - b.bounds().min).maxCoeff();
  int i = 0;
  for (const Quat& q : quarter_turns)
    for (int x = 2; x <= 5; ++x)
      for (int y = -2; y <= 2; y += 2)
        for (int z = -1; z <= 1; ++z) {
          Pose pa, pb;
          pb.orientation = q;
          pb.position = Vec3(x * step, y * step, z * step);
          compare_at(a, pa, b, pb, name + " grid " + std::to_string(i++), tally);
        }
}

// A hit rate inside a band keeps the samples representative: every kind of answer is tested.
void expect_representative(const Tally& t, const std::string& name) {
  const int total = t.hits + t.misses;
  EXPECT_GE(t.hits, total / 5) << name << ": too few contacts for the sample to test hits";
  EXPECT_GE(t.misses, total / 10) << name << ": too few misses for the sample to test them";
}

TEST(AcceleratedDetect, BoxesMatchTheFaithfulDetector) {
  const ConvexPolyhedron a = make_box(Vec3(1, 1, 1)), b = make_box(Vec3(1.2, 0.6, 0.9));
  Tally t;
  random_poses(a, b, 3000, 1, "box-box", t);
  grid_poses(a, b, "box-box", t);
  expect_representative(t, "box-box");
  // Random box poses reach all three tests.
  EXPECT_GT(t.features["face"], 0);
  EXPECT_GT(t.features["vertex"], 0);
  EXPECT_GT(t.features["edge"], 0);
}

TEST(AcceleratedDetect, PrismsMatchTheFaithfulDetector) {
  // 8 sides: 28 triangles (plain loops); 24 sides: 92 triangles (hierarchies); both have
  // fan-triangulated caps, so several coplanar triangles share a plane.
  const ConvexPolyhedron p8 = make_prism(0.5, 0.8, 8), p24 = make_prism(0.5, 1.0, 24);
  const ConvexPolyhedron box = make_box(Vec3(1, 1, 1));
  Tally t;
  random_poses(p24, p8, 1000, 2, "prism24-prism8", t);
  random_poses(box, p24, 1000, 3, "box-prism24", t);
  random_poses(p24, p24, 500, 4, "prism24-prism24", t);
  // Two small shapes (plain loops and the plane table), one with 6-triangle fan caps.
  random_poses(p8, box, 1000, 9, "prism8-box", t);
  grid_poses(p8, box, "prism8-box", t);
  grid_poses(p24, box, "prism24-box", t);
  grid_poses(p24, p24, "prism24-prism24", t);
  expect_representative(t, "prisms");
  EXPECT_GT(t.features["edge"], 0);
}

TEST(AcceleratedDetect, IcospheresMatchTheFaithfulDetector) {
  const ConvexPolyhedron s1 = sheared_icosphere(1), s2 = sheared_icosphere(2);
  const ConvexPolyhedron i2 = make_icosphere(0.5, 2), i3 = make_icosphere(0.5, 3);
  const ConvexPolyhedron box = make_box(Vec3(1, 1, 1));
  Tally t;
  // Counts kept so that the seed reference (~16 N^2 primitive tests a pose) runs in about a second.
  random_poses(s1, s2, 600, 5, "sheared42-sheared162", t);
  random_poses(box, s2, 400, 6, "box-sheared162", t);
  random_poses(i2, s2, 200, 7, "ico162-sheared162", t);
  random_poses(i3, s1, 60, 8, "ico642-sheared42", t);
  grid_poses(i2, i2, "ico162-ico162", t);
  expect_representative(t, "icospheres");
}

// Hulls above kLinearVertices search their trees (caps grown over edges, bounded clusters of
// face planes); the smaller ones above scan. Both sizes against each other and a box.
TEST(AcceleratedDetect, HullsThatSearchTheirTreesMatchTheFaithfulDetector) {
  const ConvexPolyhedron s3 = sheared_icosphere(3), i3 = make_icosphere(0.5, 3);
  const ConvexPolyhedron s2 = sheared_icosphere(2), box = make_box(Vec3(1, 1, 1));
  ASSERT_GT(static_cast<int>(s3.vertices().size()), detail::kLinearVertices);
  ASSERT_LE(static_cast<int>(s2.vertices().size()), detail::kLinearVertices);
  Tally t;
  // Counts kept so that the seed reference (~16 N^2 primitive tests a pose) runs in seconds.
  random_poses(s3, i3, 90, 10, "sheared642-ico642", t);
  random_poses(s3, s2, 90, 11, "sheared642-sheared162", t);
  random_poses(box, s3, 90, 12, "box-sheared642", t);
  expect_representative(t, "large hulls");
}

// The cap of a shape with a hierarchy (engine/detect_accelerated.h) must hold every vertex
// whose plane distance from the other shape's facing face is within the tolerance: a vertex
// missing from it would be a hit never tested. Checked against the seed's expression on every
// vertex, at touching poses, for a scanned and a searched hull; the cap must also leave most
// vertices out (otherwise it culls nothing and the check proves little).
TEST(AcceleratedDetect, TheCapHoldsEveryVertexNearTheFacingPlane) {
  for (int subdivisions : {2, 3}) {
    const ConvexPolyhedron a = sheared_icosphere(subdivisions), b = make_icosphere(0.5, 3);
    std::mt19937_64 rng(20 + subdivisions);
    int caps = 0, small_caps = 0;
    for (int i = 0; i < 200; ++i) {
      Pose pa, pb;
      pa.orientation = random_rotation(rng);
      pb.orientation = random_rotation(rng);
      const Vec3 d = random_direction(rng);
      // Touching along d: the support planes meet, then B pushed in by up to 1 % of its size.
      const double reach = support(a, pa, d) + support(b, pb, -d);
      pb.position = (reach - 0.01 * std::uniform_real_distribution<double>(0.0, 1.0)(rng)) * d;
      detail::AcceleratedWorkspace ws;
      detail::AcceleratedPair pair;
      pair.prepare(a, pa, b, pb, ws);
      if (!pair.a.cap || pair.b.facing < 0) continue;
      ++caps;
      const auto& tri = b.triangles()[pair.b.facing];
      const Vec3 q = pb.apply(b.vertices()[tri[0]]);
      const Vec3 n = pb.rotation() * b.planes()[pair.b.facing].normal;
      const std::vector<int>& cap = *pair.a.cap;
      for (int v = 0; v < static_cast<int>(a.vertices().size()); ++v) {
        const double s = (pa.apply(a.vertices()[v]) - q).dot(n);
        if (s <= pair.a.tol) {
          EXPECT_TRUE(std::binary_search(cap.begin(), cap.end(), v))
              << "subdivisions " << subdivisions << " pose " << i << " vertex " << v << " at " << s;
        }
      }
      small_caps += 4 * static_cast<int>(cap.size()) < static_cast<int>(a.vertices().size());
    }
    EXPECT_GT(caps, 150) << "subdivisions " << subdivisions;
    EXPECT_GT(small_caps, caps / 2) << "subdivisions " << subdivisions;
  }
}

// Shapes destroyed and rebuilt, likely at reused addresses: the hierarchies each shape carries
// (built with it) always belong to the shape asked about.
TEST(AcceleratedDetect, CacheFollowsShapes) {
  Tally t;
  for (int round = 0; round < 20; ++round) {
    // A new shape each round, likely at the address of the last one, with a different size.
    const ConvexPolyhedron a = make_prism(0.3 + 0.02 * round, 0.5, 20);
    const ConvexPolyhedron b = make_prism(0.4, 0.3 + 0.03 * round, 20);
    random_poses(a, b, 30, 100 + round, "round " + std::to_string(round), t);
  }
  expect_representative(t, "rebuilt shapes");
}

// A different shape at the same poses must give its own answer, never the last pair's (the
// accelerated path once reused the last pair's world data when poses matched). Boxes of growing
// size, at the same fixed poses, one after the other.
TEST(AcceleratedDetect, SamePosesNewShapes) {
  Pose pa, pb;
  pb.position = Vec3(1.0, 0.1, 0.05);
  pb.orientation = Quat(Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()));
  int hits = 0;
  for (int k = 0; k < 20; ++k) {
    const ConvexPolyhedron a = make_box(Vec3::Constant(0.5 + 0.05 * k));
    const ConvexPolyhedron b = make_box(Vec3(1.0, 0.8, 0.6));
    for (Feature feature : kFeatures)
      expect_same(detect_feature(feature, a, pa, b, pb, Detector::Accelerated),
                  detect_feature(feature, a, pa, b, pb, Detector::Faithful),
                  "size " + std::to_string(k) + " " + to_string(feature));
    const auto seed = detect(a, pa, b, pb, Detector::Faithful);
    expect_same(detect(a, pa, b, pb, Detector::Accelerated), seed, "size " + std::to_string(k));
    hits += seed ? 1 : 0;
  }
  // B (half extents 0.5, 0.4, 0.3, any rotation) lies within its circumsphere of radius
  // sqrt(0.25 + 0.16 + 0.09) = 0.707 m and contains its insphere of radius 0.3 m, centred at
  // (1.0, 0.1, 0.05). A's half size grows from 0.25 m (k = 0: B starts at x >= 0.293 > 0.25,
  // no contact) to 0.725 m (k = 19: B reaches x <= 0.7 with |y|, |z| < 0.725, the bodies
  // overlap, and an edge crossing the overlap is found by the edge test): both answers occur.
  EXPECT_GT(hits, 0);
  EXPECT_LT(hits, 20);
}

// A preparation must not keep pointing at an earlier pair's shapes:
// equal shapes at the same poses, the first ones destroyed before the second query (found by
// the convex_detect fuzzer: a read of a dead shape, reported by ASan, which `./rbx test
// --sanitize` turns into a failure here).
TEST(AcceleratedDetect, EqualShapesAfterTheFirstAreDestroyed) {
  Pose pa, pb;
  pb.position = Vec3(0.9, 0.1, 0.05);
  pb.orientation = Quat(Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()));
  auto a = std::make_unique<ConvexPolyhedron>(make_box(Vec3::Constant(1.0)));
  auto b = std::make_unique<ConvexPolyhedron>(make_box(Vec3(1.0, 0.8, 0.6)));
  const auto first = detect(*a, pa, *b, pb, Detector::Accelerated);
  ASSERT_TRUE(first.has_value());
  // New objects, built while the old ones are alive so that they get other addresses.
  auto a2 = std::make_unique<ConvexPolyhedron>(make_box(Vec3::Constant(1.0)));
  auto b2 = std::make_unique<ConvexPolyhedron>(make_box(Vec3(1.0, 0.8, 0.6)));
  a.reset();
  b.reset();
  for (Feature feature : kFeatures)
    expect_same(detect_feature(feature, *a2, pa, *b2, pb, Detector::Accelerated),
                detect_feature(feature, *a2, pa, *b2, pb, Detector::Faithful), to_string(feature));
  expect_same(detect(*a2, pa, *b2, pb, Detector::Accelerated), first, "equal shapes");
}

// The detector's state is passed in (DetectionCache), not kept per thread: two pairs prepared
// in two caches and queried alternately on one thread give exactly the answers each gives on
// its own. The pairs differ in size class (a hierarchy-carrying icosphere against a box, two
// small boxes), so both paths of the accelerated view hold state at the same time.
TEST(AcceleratedDetect, InterleavedQueriesOnTwoCachesDoNotInterfere) {
  const ConvexPolyhedron sphere = sheared_icosphere(2);
  const ConvexPolyhedron box = make_box(Vec3(1.0, 0.8, 0.6));
  const ConvexPolyhedron cube = make_box(Vec3::Constant(0.7));
  std::mt19937_64 rng(7);
  int hits = 0;
  for (int i = 0; i < 40; ++i) {
    Pose p1a, p1b, p2a, p2b;
    p1b.orientation = random_rotation(rng);
    p1b.position = 0.7 * random_direction(rng);
    p2b.orientation = random_rotation(rng);
    p2b.position = 0.8 * random_direction(rng);
    for (Detector v : {Detector::Accelerated, Detector::Faithful}) {
      // Alone: each pair on a fresh cache.
      std::optional<ContactPoint> alone1[3], alone2[3];
      for (int f = 0; f < 3; ++f) {
        alone1[f] = detect_feature(kFeatures[f], sphere, p1a, box, p1b, v);
        alone2[f] = detect_feature(kFeatures[f], cube, p2a, box, p2b, v);
      }
      // Interleaved: both prepared first, then the tests alternate between the caches.
      DetectionCache c1, c2;
      c1.prepare(sphere, p1a, box, p1b, v);
      c2.prepare(cube, p2a, box, p2b, v);
      for (int f = 0; f < 3; ++f) {
        const std::string where =
            "pose " + std::to_string(i) + " " + to_string(kFeatures[f]) + " " + to_string(v);
        expect_same(c1.test(kFeatures[f]), alone1[f], where + " pair 1");
        expect_same(c2.test(kFeatures[f]), alone2[f], where + " pair 2");
        hits += alone1[f].has_value() + alone2[f].has_value();
      }
      expect_same(c2.detect(), detect(cube, p2a, box, p2b, v), "full, pair 2");
      expect_same(c1.detect(), detect(sphere, p1a, box, p1b, v), "full, pair 1");
    }
  }
  // Centres 0.7-0.8 m apart with half sizes ~0.3-0.5 m: some feature tests hit, some miss.
  EXPECT_GT(hits, 0);
  EXPECT_LT(hits, 40 * 2 * 3 * 2);
}

}  // namespace
}  // namespace rbx
