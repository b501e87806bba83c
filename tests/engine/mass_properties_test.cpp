// Mass properties under the two models (solid: exact uniform density; vertices: the seed's
// point masses) against closed forms.
#include "engine/mass_properties.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace rbx {
namespace {

// The properties are sums over at most a few thousand triangles or vertices of O(1)
// coordinates; round-off is ~1e-15 relative per term, so 1e-12 relative is a safe bound.
constexpr double kRelRoundOff = 1e-12;

void expect_mat_near(const Mat3& actual, const Mat3& expected, double tol) {
  EXPECT_LE((actual - expected).cwiseAbs().maxCoeff(), tol) << "actual\n"
                                                            << actual << "\nexpected\n"
                                                            << expected;
}

// Unit right tetrahedron (0, e_x, e_y, e_z), outward triangles.
ConvexPolyhedron unit_tetrahedron() {
  return ConvexPolyhedron::from_triangles({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                                          {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}});
}

// Pyramid: a regular n-gon of circumradius 1 in the plane z = 0 (vertices 0..n-1) and an apex
// (vertex n) at (0, 0, h). Most vertices sit on the base.
ConvexPolyhedron pyramid(int n, double h) {
  std::vector<Vec3> v;
  for (int k = 0; k < n; ++k)
    v.emplace_back(std::cos(2 * M_PI * k / n), std::sin(2 * M_PI * k / n), 0);
  v.emplace_back(0, 0, h);
  std::vector<std::array<int, 3>> t;
  for (int k = 1; k + 1 < n; ++k) t.push_back({0, k + 1, k});    // base fan, facing -z
  for (int k = 0; k < n; ++k) t.push_back({k, (k + 1) % n, n});  // sides
  return ConvexPolyhedron::from_triangles(std::move(v), std::move(t));
}

// ---- Box ------------------------------------------------------------------------------------

TEST(MassProperties, SolidBox) {
  // Uniform box a x b x c: I_xx = m (b^2 + c^2) / 12 and cyclic; products zero; COM at centre.
  const double a = 1, b = 2, c = 3, m = 2.5;
  const MassProperties mp = solid_mass_properties(make_box(Vec3(a, b, c)), m);
  EXPECT_EQ(mp.mass, m);
  EXPECT_LE(mp.center_of_mass.norm(), kRelRoundOff);
  const Mat3 expected =
      Vec3(m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12)
          .asDiagonal();
  expect_mat_near(mp.inertia, expected, expected.maxCoeff() * kRelRoundOff);
}

TEST(MassProperties, VertexBox) {
  // Eight point masses m/8 at (+-a/2, +-b/2, +-c/2): I_xx = 8 (m/8) ((b/2)^2 + (c/2)^2)
  // = m (b^2 + c^2) / 4; the sums of x y etc. cancel in sign pairs.
  const double a = 1, b = 2, c = 3, m = 2.5;
  const MassProperties mp = vertex_mass_properties(make_box(Vec3(a, b, c)), m);
  EXPECT_EQ(mp.mass, m);
  EXPECT_LE(mp.center_of_mass.norm(), kRelRoundOff);
  const Mat3 expected =
      Vec3(m * (b * b + c * c) / 4, m * (a * a + c * c) / 4, m * (a * a + b * b) / 4).asDiagonal();
  expect_mat_near(mp.inertia, expected, expected.maxCoeff() * kRelRoundOff);
}

// ---- Tetrahedron ----------------------------------------------------------------------------

TEST(MassProperties, SolidTetrahedron) {
  // Unit right tetrahedron, volume 1/6, density rho = 6 m. Dirichlet's integral over the
  // standard simplex, int x^a y^b z^c dV = a! b! c! / (a + b + c + 3)!, gives
  // int x dV = 1/24 (centroid 1/24 / (1/6) = 1/4), int x^2 dV = 2/120, int x y dV = 1/120.
  // About the origin: C_xx = rho/60 = m/10, C_xy = rho/120 = m/20.
  // About the centroid (parallel axis, subtract m c c^T): C_xx = m/10 - m/16 = 3m/80,
  // C_xy = m/20 - m/16 = -m/80. I = tr(C) 1 - C: I_xx = 2 (3m/80) = 3m/40, I_xy = +m/80.
  const double m = 3.0;
  const MassProperties mp = solid_mass_properties(unit_tetrahedron(), m);
  EXPECT_LE((mp.center_of_mass - Vec3(0.25, 0.25, 0.25)).norm(), kRelRoundOff);
  Mat3 expected = Mat3::Constant(m / 80);
  expected.diagonal().setConstant(3 * m / 40);
  expect_mat_near(mp.inertia, expected, m * kRelRoundOff);
}

TEST(MassProperties, VertexTetrahedron) {
  // Four masses m/4 at 0, e_x, e_y, e_z; average (1/4, 1/4, 1/4). Offsets in y from it:
  // -1/4, -1/4, 3/4, -1/4, squares summing to 3/4, and the same in z: I_xx = (m/4)(3/2) = 3m/8.
  // Products (x - 1/4)(y - 1/4): 1/16 - 3/16 - 3/16 + 1/16 = -1/4, so I_xy = +(m/4)(1/4) = m/16.
  const double m = 3.0;
  const MassProperties mp = vertex_mass_properties(unit_tetrahedron(), m);
  EXPECT_LE((mp.center_of_mass - Vec3(0.25, 0.25, 0.25)).norm(), kRelRoundOff);
  Mat3 expected = Mat3::Constant(m / 16);
  expected.diagonal().setConstant(3 * m / 8);
  expect_mat_near(mp.inertia, expected, m * kRelRoundOff);
}

TEST(MassProperties, DispatchFollowsTheModel) {
  const ConvexPolyhedron t = unit_tetrahedron();
  EXPECT_EQ(mass_properties(t, 2.0, MassModel::Solid).inertia,
            solid_mass_properties(t, 2.0).inertia);
  EXPECT_EQ(mass_properties(t, 2.0, MassModel::Vertices).inertia,
            vertex_mass_properties(t, 2.0).inertia);
}

// ---- Icosphere ------------------------------------------------------------------------------

TEST(MassProperties, IcosphereIsIsotropicInBothModels) {
  // The icospheres keep the icosahedron's rotation group, and the only symmetric tensor that
  // group leaves invariant is a multiple of 1: equal diagonal, zero products, COM at the centre.
  const double r = 1.5, m = 2.0;
  for (int s = 0; s <= 3; ++s) {
    const ConvexPolyhedron sphere = make_icosphere(r, s);
    for (const MassModel model : {MassModel::Solid, MassModel::Vertices}) {
      const MassProperties mp = mass_properties(sphere, m, model);
      const double i = mp.inertia(0, 0);
      EXPECT_LE(mp.center_of_mass.norm(), r * kRelRoundOff) << "subdivisions " << s;
      expect_mat_near(mp.inertia, i * Mat3::Identity(), i * kRelRoundOff);
    }
    // Vertex model: every vertex at radius r, so sum (m/N)(|x|^2 1 - x x^T) = m r^2 1 -
    // (m/N) sum x x^T, and isotropy makes (1/N) sum x x^T = (r^2/3) 1: I = (2/3) m r^2 exactly,
    // the thin spherical shell at every level.
    EXPECT_NEAR(vertex_mass_properties(sphere, m).inertia(0, 0), 2.0 / 3.0 * m * r * r,
                m * r * r * kRelRoundOff);
  }
}

TEST(MassProperties, SolidIcosphereConvergesToTheBall) {
  // For an isotropic body I = (2/3) m <|x|^2>. A body between the balls of radii r_in (its
  // nearest face plane) and r (its vertices) has (3/5) r_in^2 <= <|x|^2> <= (3/5) r^2: adding
  // points at |x| >= r_in to the inner ball can only raise the mean above (3/5) r_in^2, and
  // removing points at |x|^2 >= r_in^2 >= (3/5) r^2 from the outer ball can only lower it (the
  // icosahedron already has (r_in/r)^2 = 0.63 >= 0.6). So (2/5) m r_in^2 <= I <= (2/5) m r^2,
  // and each subdivision, moving r_in toward r, must bring I closer to (2/5) m r^2.
  const double r = 1.5, m = 2.0;
  const double ball = 0.4 * m * r * r;
  double previous_error = ball;
  for (int s = 0; s <= 3; ++s) {
    const ConvexPolyhedron sphere = make_icosphere(r, s);
    double r_in = r;
    for (const Plane& p : sphere.planes()) r_in = std::min(r_in, p.offset);
    const double i = solid_mass_properties(sphere, m).inertia(0, 0);
    EXPECT_GE(i, 0.4 * m * r_in * r_in) << "subdivisions " << s;
    EXPECT_LE(i, ball) << "subdivisions " << s;
    EXPECT_LT(ball - i, previous_error) << "subdivisions " << s;
    previous_error = ball - i;
  }
  // At 3 subdivisions r_in / r = cos(angle from face centre to corner) >= 0.99, so the
  // sandwich alone bounds the error by 1 - 0.99^2 < 2%.
  EXPECT_LT(previous_error / ball, 0.02);
}

// ---- Translation, bias ----------------------------------------------------------------------

TEST(MassProperties, InertiaAboutTheComIsTranslationInvariant) {
  // Moving the shape moves its centre of mass by the same offset and leaves the inertia about
  // the centre of mass unchanged. Round-off: second moments about the origin grow to
  // ~m |offset|^2 before the parallel-axis subtraction, so the tolerance scales with it.
  const ConvexPolyhedron t = unit_tetrahedron();
  const Vec3 offset(3, -2, 5);
  const double m = 1.7;
  for (const MassModel model : {MassModel::Solid, MassModel::Vertices}) {
    const MassProperties here = mass_properties(t, m, model);
    const MassProperties there = mass_properties(t.translated(offset), m, model);
    EXPECT_LE((there.center_of_mass - (here.center_of_mass + offset)).norm(),
              offset.norm() * kRelRoundOff);
    expect_mat_near(there.inertia, here.inertia, m * offset.squaredNorm() * kRelRoundOff);
  }
}

TEST(MassProperties, VertexAverageIsBiasedTowardDenseVertices) {
  // A pyramid on a 32-gon base of radius 1 with its apex at height 2: 32 of the 33 vertices sit
  // on the base. The vertex average is at z = h / (n + 1) = 2/33 (the seed admits this bias);
  // the solid centre of mass of any pyramid is a quarter of the height above the base
  // centroid, z = 0.5. Both are on the axis by the base's symmetry.
  const int n = 32;
  const double h = 2.0, m = 1.0;
  const ConvexPolyhedron p = pyramid(n, h);
  const MassProperties solid = solid_mass_properties(p, m);
  const MassProperties vertices = vertex_mass_properties(p, m);
  EXPECT_LE((solid.center_of_mass - Vec3(0, 0, h / 4)).norm(), kRelRoundOff);
  EXPECT_LE((vertices.center_of_mass - Vec3(0, 0, h / (n + 1))).norm(), kRelRoundOff);
}

}  // namespace
}  // namespace rbx
