// ConvexPolyhedron: the builders (counts, Euler characteristic, volumes against closed forms)
// and validation (each rejected mesh names what is wrong).
#include "engine/polyhedron.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "engine/gauss_map.h"

namespace rbx {
namespace {

// Volumes are sums of a few dozen to a few thousand triple products of O(1) coordinates:
// round-off ~1e-15 relative per term, so 1e-12 relative is a safe bound.
constexpr double kVolumeRoundOff = 1e-12;

using Triangles = std::vector<std::array<int, 3>>;

// Unit right tetrahedron (0, e_x, e_y, e_z) with outward counter-clockwise triangles:
// {0,2,1} faces -z, {0,1,3} faces -y, {0,3,2} faces -x, {1,2,3} faces (1,1,1).
std::vector<Vec3> tetra_vertices() { return {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}; }
Triangles tetra_triangles() { return {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}; }

// The unit cube's vertices and triangles, as make_box builds them (vertex i has x, y, z
// signs from bits 0, 1, 2), so a test can damage one triangle.
std::vector<Vec3> cube_vertices() { return make_box(Vec3(1, 1, 1)).vertices(); }
Triangles cube_triangles() { return make_box(Vec3(1, 1, 1)).triangles(); }

// Expects from_triangles to throw a GeometryError whose message contains every fragment.
void expect_rejected(std::vector<Vec3> vertices, Triangles triangles,
                     const std::vector<std::string>& fragments) {
  try {
    ConvexPolyhedron::from_triangles(std::move(vertices), std::move(triangles));
    ADD_FAILURE() << "mesh accepted, expected an error containing '" << fragments.front() << "'";
  } catch (const GeometryError& e) {
    const std::string message = e.what();
    for (const std::string& f : fragments)
      EXPECT_NE(message.find(f), std::string::npos) << "'" << f << "' not in: " << message;
  }
}

// ---- Builders -------------------------------------------------------------------------------

TEST(PolyhedronBuilders, BoxCountsAndVolume) {
  const ConvexPolyhedron box = make_box(Vec3(2, 3, 5));
  // 8 corners, 6 faces x 2 triangles, 12 cube edges + 6 face diagonals.
  EXPECT_EQ(box.vertices().size(), 8u);
  EXPECT_EQ(box.triangles().size(), 12u);
  EXPECT_EQ(box.edges().size(), 18u);
  EXPECT_EQ(box.planes().size(), 12u);
  EXPECT_NEAR(box.volume(), 2.0 * 3.0 * 5.0, 30.0 * kVolumeRoundOff);
  // Bounds are the half extents around the origin.
  EXPECT_EQ(box.bounds().min, Vec3(-1, -1.5, -2.5));
  EXPECT_EQ(box.bounds().max, Vec3(1, 1.5, 2.5));
}

TEST(PolyhedronBuilders, EdgesAreUniqueAndOrdered) {
  const ConvexPolyhedron sphere = make_icosphere(1.0, 2);
  std::vector<std::pair<int, int>> seen;
  for (const Edge& e : sphere.edges()) {
    EXPECT_LT(e.a, e.b);
    seen.emplace_back(e.a, e.b);
  }
  std::sort(seen.begin(), seen.end());
  EXPECT_EQ(std::unique(seen.begin(), seen.end()), seen.end());
}

TEST(PolyhedronBuilders, PlanesAreUnitAndOutward) {
  // Every shape here is centred on the origin, so each outward plane has a positive offset and
  // every vertex is on or behind every plane (convexity, to round-off of O(1) coordinates).
  for (const ConvexPolyhedron& s :
       {make_box(Vec3(1, 2, 3)), make_icosphere(2.0, 1), make_prism(1.0, 0.5, 7)}) {
    for (const Plane& p : s.planes()) {
      EXPECT_NEAR(p.normal.norm(), 1.0, kVolumeRoundOff);
      EXPECT_GT(p.offset, 0.0);
      for (const Vec3& v : s.vertices()) EXPECT_LE(p.distance(v), 1e-12);
    }
  }
}

TEST(PolyhedronBuilders, IcosphereEulerCharacteristicAndCounts) {
  // Each subdivision splits a triangle in four and adds one vertex per edge:
  // F = 20 * 4^s, E = 30 * 4^s, V = 12 + (edges of all previous levels) = 10 * 4^s + 2.
  for (int s = 0; s <= 3; ++s) {
    const ConvexPolyhedron sphere = make_icosphere(1.0, s);
    const int p = 1 << (2 * s);  // 4^s
    const int v = static_cast<int>(sphere.vertices().size());
    const int e = static_cast<int>(sphere.edges().size());
    const int f = static_cast<int>(sphere.triangles().size());
    EXPECT_EQ(v, 10 * p + 2) << "subdivisions " << s;
    EXPECT_EQ(e, 30 * p) << "subdivisions " << s;
    EXPECT_EQ(f, 20 * p) << "subdivisions " << s;
    EXPECT_EQ(v - e + f, 2) << "subdivisions " << s;
  }
}

TEST(PolyhedronBuilders, PrismEulerCharacteristicAndCounts) {
  // n-gon prism: V = 2n; caps are fans of n - 2 triangles, sides 2 per side: F = 4n - 4;
  // every triangle has 3 edges, each shared by 2: E = 3F/2 = 6n - 6.
  for (int n : {3, 4, 5, 8, 31}) {
    const ConvexPolyhedron prism = make_prism(1.0, 2.0, n);
    const int v = static_cast<int>(prism.vertices().size());
    const int e = static_cast<int>(prism.edges().size());
    const int f = static_cast<int>(prism.triangles().size());
    EXPECT_EQ(v, 2 * n) << "sides " << n;
    EXPECT_EQ(f, 4 * n - 4) << "sides " << n;
    EXPECT_EQ(e, 6 * n - 6) << "sides " << n;
    EXPECT_EQ(v - e + f, 2) << "sides " << n;
  }
}

TEST(PolyhedronBuilders, PrismVolume) {
  // A regular n-gon of circumradius r is n isosceles triangles of apex angle 2 pi / n:
  // area (n/2) r^2 sin(2 pi / n); times the height.
  const double r = 0.7, h = 1.3;
  for (int n : {3, 4, 6, 17, 64}) {
    const double expected = 0.5 * n * r * r * std::sin(2 * M_PI / n) * h;
    EXPECT_NEAR(make_prism(r, h, n).volume(), expected, expected * kVolumeRoundOff)
        << "sides " << n;
  }
}

TEST(PolyhedronBuilders, IcosahedronVolume) {
  // Regular icosahedron with circumradius R: edge a = 4R / sqrt(10 + 2 sqrt 5),
  // V = (5/12)(3 + sqrt 5) a^3.
  const double radius = 1.7;
  const double a = 4 * radius / std::sqrt(10 + 2 * std::sqrt(5.0));
  const double expected = 5.0 / 12.0 * (3 + std::sqrt(5.0)) * a * a * a;
  EXPECT_NEAR(make_icosphere(radius, 0).volume(), expected, expected * kVolumeRoundOff);
}

TEST(PolyhedronBuilders, IcosphereVolumeIncreasesTowardTheBall) {
  // The icospheres are inscribed in the ball and each subdivision adds material outside the
  // previous faces, so the volume grows and stays below 4/3 pi r^3.
  const double ball = 4.0 / 3.0 * M_PI;
  double previous = 0.0;
  for (int s = 0; s <= 3; ++s) {
    const double v = make_icosphere(1.0, s).volume();
    EXPECT_GT(v, previous) << "subdivisions " << s;
    EXPECT_LT(v, ball) << "subdivisions " << s;
    previous = v;
  }
}

TEST(PolyhedronBuilders, TranslatedMovesVerticesPlanesAndBounds) {
  const ConvexPolyhedron box = make_box(Vec3(1, 2, 3));
  const Vec3 offset(0.5, -1.25, 2);  // dyadic: exact in binary
  const ConvexPolyhedron moved = box.translated(offset);
  EXPECT_NEAR(moved.volume(), 6.0, 6.0 * 1e-12);  // triple products of larger numbers
  for (size_t i = 0; i < box.vertices().size(); ++i)
    EXPECT_EQ(moved.vertices()[i], box.vertices()[i] + offset);
  // Each moved vertex is on its moved triangle's plane.
  for (size_t f = 0; f < moved.triangles().size(); ++f)
    EXPECT_NEAR(moved.planes()[f].distance(moved.vertices()[moved.triangles()[f][0]]), 0.0,
                kVolumeRoundOff);
  EXPECT_EQ(moved.bounds().min, box.bounds().min + offset);
}

TEST(PolyhedronBuilders, SupportIndexIsTheFurthestVertex) {
  // Corner (+,+,-) of the box is index 1 + 2 = 3; direction (1, 1, -1) picks it.
  EXPECT_EQ(make_box(Vec3(1, 1, 1)).support_index(Vec3(1, 1, -1)), 3);
}

// 2,000 directions at random, then the cube's axes and diagonals (and zero): the boundaries of
// the cube map's cells, and directions along which a box's vertices tie.
std::vector<Vec3> probe_directions(std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Vec3> directions;
  for (int k = 0; k < 2000; ++k) directions.push_back(Vec3(g(rng), g(rng), g(rng)));
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z) directions.push_back(Vec3(x, y, z));
  return directions;
}

TEST(PolyhedronBuilders, ClimbsFromTheCubeMapReachTheFurthestVertex) {
  // On a convex polyhedron a vertex with no higher neighbour is highest, so a climb from any
  // start reaches the furthest projection: from the cube map's cell of the direction, and from
  // the better of that and an arbitrary vertex. Directions at random, along the cube's axes and
  // diagonals (cell boundaries), and a zero, NaN or infinite direction (any valid start).
  std::mt19937 rng(3);
  const std::vector<Vec3> directions = probe_directions(rng);
  for (const ConvexPolyhedron& s : {make_box(Vec3(1.0, 0.6, 0.3)), make_prism(0.4, 1.2, 24),
                                    make_icosphere(0.5, 1), make_icosphere(0.5, 4)}) {
    const GaussMap& map = s.gauss_map();
    const int nv = static_cast<int>(s.vertices().size());
    ASSERT_EQ(map.cell_vertices.size(), static_cast<std::size_t>(6 * map.cells * map.cells));
    for (const Vec3& d : directions) {
      const int cell = map.start_for(d);
      ASSERT_TRUE(cell >= 0 && cell < nv);
      if (d == Vec3::Zero()) continue;
      double furthest = -1e300;
      for (const Vec3& v : s.vertices()) furthest = std::max(furthest, v.dot(d));
      double h = 0.0;
      map.climb(s.vertices(), d, -1, h);
      EXPECT_EQ(h, furthest);
      const int start = std::uniform_int_distribution<int>(0, nv - 1)(rng);
      map.climb(s.vertices(), d, map.better_start(s.vertices(), d, start), h);
      EXPECT_EQ(h, furthest);
    }
    const double nan = std::nan("");
    for (const Vec3& d : {Vec3(nan, nan, nan), Vec3(nan, 1.0, 2.0), Vec3(1.0, nan, 0.0),
                          Vec3(std::numeric_limits<double>::infinity(), 1.0, 1.0)}) {
      const int start = map.start_for(d);
      EXPECT_TRUE(start >= 0 && start < nv);
    }
  }
}

TEST(PolyhedronBuilders, TheVertexScanIsTheLoopsFirstHighestBitForBit) {
  // The lanes of scan_vertices must give what a plain loop over the vertices in order gives:
  // the same height to the bit and, on a tie (a box's face along an axis, the padded copies of
  // vertex 0), the first of the highest. Vertex counts of every remainder modulo four.
  std::mt19937 rng(5);
  const std::vector<Vec3> directions = probe_directions(rng);
  std::vector<ConvexPolyhedron> shapes = {make_box(Vec3(1.0, 0.6, 0.3)), make_prism(0.4, 1.2, 3),
                                          make_prism(0.4, 1.2, 24), make_icosphere(0.5, 1)};
  // Bipyramids over a k-gon: k + 2 vertices, odd counts the builders above do not make.
  for (const int k : {3, 5, 31, 95}) {
    std::vector<Vec3> v;
    std::vector<std::array<int, 3>> t;
    for (int i = 0; i < k; ++i) {
      const double angle = 2.0 * M_PI * i / k;
      v.emplace_back(std::cos(angle), std::sin(angle), 0.0);
      t.push_back({i, (i + 1) % k, k});
      t.push_back({(i + 1) % k, i, k + 1});
    }
    v.emplace_back(0.0, 0.0, 0.7);
    v.emplace_back(0.0, 0.0, -0.7);
    shapes.push_back(ConvexPolyhedron::from_triangles(v, t));
  }
  std::set<std::size_t> remainders;
  for (const ConvexPolyhedron& s : shapes) {
    remainders.insert(s.vertices().size() % 4);
    for (const Vec3& d : directions) {
      double furthest = s.vertices()[0].dot(d);
      int first = 0;
      for (int i = 1; i < static_cast<int>(s.vertices().size()); ++i)
        if (s.vertices()[i].dot(d) > furthest) {
          furthest = s.vertices()[i].dot(d);
          first = i;
        }
      // Every unit the processor runs (one it lacks would only repeat the next narrower).
      for (const auto unit : {GaussMap::ScanUnit::Widest, GaussMap::ScanUnit::Avx,
                              GaussMap::ScanUnit::Sse2, GaussMap::ScanUnit::Plain}) {
        double h = 0.0;
        ASSERT_EQ(s.gauss_map().scan_vertices(d, h, unit), first) << static_cast<int>(unit);
        ASSERT_EQ(h, furthest) << static_cast<int>(unit);
      }
    }
  }
  EXPECT_EQ(remainders.size(), 4u);
}

// ---- Validation -----------------------------------------------------------------------------

TEST(PolyhedronValidation, AcceptsTheTetrahedron) {
  const ConvexPolyhedron t = ConvexPolyhedron::from_triangles(tetra_vertices(), tetra_triangles());
  EXPECT_NEAR(t.volume(), 1.0 / 6.0, kVolumeRoundOff);
  EXPECT_EQ(t.edges().size(), 6u);
}

TEST(PolyhedronValidation, OpenMeshNamesTheBorderEdge) {
  // The cube without its triangle {0,4,6}: the directed edge 6->0 is gone, so 0->6 (now in
  // face 0, {0,6,2}) is the first edge in sorted order without a reverse.
  Triangles t = cube_triangles();
  t.erase(t.begin());
  expect_rejected(cube_vertices(), t, {"open", "edge 0-6", "face 0"});
}

TEST(PolyhedronValidation, InconsistentOrientationNamesBothFaces) {
  // Triangle 0 reversed to {0,6,4}: its edge 0->6 is also used, in that direction, by
  // triangle 1 {0,6,2}.
  Triangles t = cube_triangles();
  t[0] = {0, 6, 4};
  expect_rejected(cube_vertices(), t, {"inconsistently oriented", "faces 0 and 1", "0->6"});
}

TEST(PolyhedronValidation, InwardOrientationIsRejected) {
  // Every triangle reversed: closed and consistent, but the signed volume is -1.
  Triangles t = cube_triangles();
  for (auto& tri : t) std::swap(tri[1], tri[2]);
  expect_rejected(cube_vertices(), t, {"oriented inward"});
}

TEST(PolyhedronValidation, NonConvexNamesTheVertexAndFace) {
  // The cube with its top face (z = 0.5) replaced by a fan around a dent vertex 8 = (0,0,0.3):
  // faces 0..9 are the other cube triangles, then {4,5,8}, {5,7,8}, {7,6,8}, {6,4,8}.
  // Face 10 = {4,5,8} has normal (5-4) x (8-4) = (1,0,0) x (0.5,0.5,-0.2) = (0, 0.2, 0.5); of
  // the vertices in index order, 6 = (-0.5,0.5,0.5) is the first in front of it:
  // (6-4) . n = (0,1,0) . (0,0.2,0.5) = 0.2 > 0. (Faces 0..9 have the dent behind them.)
  std::vector<Vec3> v = cube_vertices();
  v.emplace_back(0, 0, 0.3);
  Triangles t = cube_triangles();
  t.erase(t.begin() + 10, t.end());
  for (const auto& tri : Triangles{{4, 5, 8}, {5, 7, 8}, {7, 6, 8}, {6, 4, 8}}) t.push_back(tri);
  expect_rejected(v, t, {"not convex", "vertex 6", "face 10"});
}

TEST(PolyhedronValidation, PrunedConvexityCheckNamesWhatTheFullScanNames) {
  // The convexity check prunes with a box tree over the vertices. Reference: the plain scan of
  // every vertex against every face plane, with the check's tolerance (1e-9 of the size), which
  // names the first face with an outside vertex and its lowest-numbered outside vertex. Every
  // 7th vertex of a 642-vertex icosphere in turn is pushed out by 5% of the radius (a face
  // here sags ~1% below the sphere, so each push makes a dent).
  const ConvexPolyhedron sphere = make_icosphere(1.0, 3);
  const Triangles& t = sphere.triangles();
  for (int k = 0; k < static_cast<int>(sphere.vertices().size()); k += 7) {
    std::vector<Vec3> v = sphere.vertices();
    v[k] *= 1.05;
    Vec3 lo = v[0], hi = v[0];
    for (const Vec3& x : v) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
    const double tol = 1e-9 * std::max((hi - lo).maxCoeff(), hi.cwiseAbs().maxCoeff());
    std::string expected;
    for (size_t f = 0; f < t.size() && expected.empty(); ++f) {
      const Vec3 n = (v[t[f][1]] - v[t[f][0]]).cross(v[t[f][2]] - v[t[f][0]]).normalized();
      for (int i = 0; i < static_cast<int>(v.size()) && expected.empty(); ++i)
        if (n.dot(v[i]) - n.dot(v[t[f][0]]) > tol) expected = "vertex " + std::to_string(i) + " ";
      if (!expected.empty()) expected += "* face " + std::to_string(f) + " ";
    }
    ASSERT_FALSE(expected.empty()) << "the push of vertex " << k << " made no dent";
    try {
      ConvexPolyhedron::from_triangles(v, t);
      ADD_FAILURE() << "vertex " << k << " pushed out was accepted";
    } catch (const GeometryError& e) {
      const std::string m = e.what();
      const std::string vertex = expected.substr(0, expected.find('*'));
      const std::string face = expected.substr(expected.find('*') + 2);
      EXPECT_NE(m.find("not convex: " + vertex), std::string::npos) << m << " / " << expected;
      EXPECT_NE(m.find("plane of " + face + "("), std::string::npos) << m << " / " << expected;
    }
  }
}

TEST(PolyhedronValidation, ZeroVolumeIsRejected) {
  // The tetrahedron's topology on four coplanar points: no triangle is degenerate (each spans
  // half the unit square) but the enclosed volume is 0.
  const std::vector<Vec3> v = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  expect_rejected(v, tetra_triangles(), {"zero volume"});
}

TEST(PolyhedronValidation, DegenerateTriangleIsNamed) {
  // A repeated index (face 0 = {0,2,2}) and three collinear points (vertex 3 moved to (2,0,0)
  // puts face 1 = {0,1,3} on the x axis).
  Triangles repeated = tetra_triangles();
  repeated[0] = {0, 2, 2};
  expect_rejected(tetra_vertices(), repeated, {"face 0", "degenerate"});
  std::vector<Vec3> collinear = tetra_vertices();
  collinear[3] = Vec3(2, 0, 0);
  expect_rejected(collinear, tetra_triangles(), {"face 1", "degenerate"});
}

TEST(PolyhedronValidation, UnusedVertexIsNamed) {
  std::vector<Vec3> v = tetra_vertices();
  v.emplace_back(5, 5, 5);
  expect_rejected(v, tetra_triangles(), {"vertex 4", "not used"});
}

TEST(PolyhedronValidation, OutOfRangeIndexAndTooFewElements) {
  Triangles t = tetra_triangles();
  t[3] = {1, 2, 7};
  expect_rejected(tetra_vertices(), t, {"face 3", "vertex 7"});
  expect_rejected({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}, {0, 2, 1}}, {"at least 4"});
}

TEST(PolyhedronValidation, BuilderArgumentsAreChecked) {
  EXPECT_THROW(make_box(Vec3(1, 0, 1)), GeometryError);
  EXPECT_THROW(make_icosphere(1.0, -1), GeometryError);
  EXPECT_THROW(make_icosphere(0.0, 1), GeometryError);
  EXPECT_THROW(make_prism(1.0, 1.0, 2), GeometryError);
}

}  // namespace
}  // namespace rbx
