#include "engine/mass_properties.h"

namespace rbx {

MassProperties solid_mass_properties(const ConvexPolyhedron& shape, double mass) {
  // Each triangle with the origin forms a signed tetrahedron (0, a, b, c). Integrals of 1, x and
  // x x^T over a tetrahedron with one vertex at the origin have closed forms:
  //   V = det / 6,   int x = V (a + b + c) / 4,
  //   int x x^T = det / 120 * (a a^T + b b^T + c c^T + s s^T),  s = a + b + c.
  double volume = 0.0;
  Vec3 first = Vec3::Zero();
  Mat3 second = Mat3::Zero();
  const auto& v = shape.vertices();
  for (const auto& t : shape.triangles()) {
    const Vec3 &a = v[t[0]], &b = v[t[1]], &c = v[t[2]];
    const double det = a.dot(b.cross(c));
    const Vec3 s = a + b + c;
    volume += det / 6.0;
    first += det / 24.0 * s;
    second += det / 120.0 *
              (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
  }
  MassProperties mp;
  mp.mass = mass;
  const double density = mass / volume;
  mp.center_of_mass = first / volume;
  // Second moment about the centre of mass (parallel-axis shift), then I = tr(C) 1 - C.
  const Mat3 c = density * second - mass * mp.center_of_mass * mp.center_of_mass.transpose();
  mp.inertia = c.trace() * Mat3::Identity() - c;
  return mp;
}

MassProperties vertex_mass_properties(const ConvexPolyhedron& shape, double mass) {
  const auto& v = shape.vertices();
  MassProperties mp;
  mp.mass = mass;
  // The seed: "adding all of the vertices in the mesh and dividing by the total number".
  Vec3 com = Vec3::Zero();
  for (const Vec3& p : v) com += p;
  com /= static_cast<double>(v.size());
  mp.center_of_mass = com;
  // The seed's I11 = sum m_k (y^2 + z^2), I12 = -sum m_k x y, ... with m_k = mass / N, about
  // the centre of mass (seed correction 5 (world-frame inverse inertia, static bodies zero)).
  const double mk = mass / static_cast<double>(v.size());
  Mat3 inertia = Mat3::Zero();
  for (const Vec3& p : v) {
    const Vec3 r = p - com;
    inertia += mk * (r.squaredNorm() * Mat3::Identity() - r * r.transpose());
  }
  mp.inertia = inertia;
  return mp;
}

MassProperties mass_properties(const ConvexPolyhedron& shape, double mass, MassModel model) {
  return model == MassModel::Solid ? solid_mass_properties(shape, mass)
                                   : vertex_mass_properties(shape, mass);
}

}  // namespace rbx
