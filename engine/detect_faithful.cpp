// The faithful view: the seed's loops, each over every primitive of a shape placed in the world.
#include "engine/detect_faithful.h"

#include <limits>

#include "engine/detect.h"

namespace rbx::detail {

FaithfulView FaithfulView::place(const ConvexPolyhedron& s, const Pose& pose, double tol) {
  FaithfulView w;
  w.shape = &s;
  w.tol = tol;
  const Mat3 r = pose.rotation();
  w.vertices.reserve(s.vertices().size());
  for (const Vec3& v : s.vertices()) w.vertices.push_back(r * v + pose.position);
  w.normals.reserve(s.planes().size());
  for (const Plane& p : s.planes()) w.normals.push_back(r * p.normal);
  return w;
}

void FaithfulView::candidates(Primitive kind, const FaithfulView&, std::vector<int>& out) const {
  const std::size_t n = kind == Primitive::Triangles  ? shape->triangles().size()
                        : kind == Primitive::Vertices ? shape->vertices().size()
                                                      : shape->edges().size();
  out.resize(n);
  for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<int>(i);
}

// seed correction 1 (point in mesh uses p - q_f). The seed text says "taking the dot product of the
// point with every face normal" and then gives two contradictory sign rules; p . n_f depends on
// where the world origin is and is no inside test. The half-space test is (p - q_f) . n_f <= tol
// for every face f, q_f a vertex of f (here its first vertex).
bool FaithfulView::inside(const Vec3& p) const {
  const auto& tris = shape->triangles();
  for (std::size_t f = 0; f < tris.size(); ++f)
    if ((p - vertices[tris[f][0]]).dot(normals[f]) > tol) return false;
  return true;
}

double FaithfulView::support_max(const Vec3& n) const {
  double best = -std::numeric_limits<double>::infinity();
  for (const Vec3& v : vertices) best = std::max(best, v.dot(n));
  return best;
}

double FaithfulView::support_min(const Vec3& n) const {
  double best = std::numeric_limits<double>::infinity();
  for (const Vec3& v : vertices) best = std::min(best, v.dot(n));
  return best;
}

// For a point inside a convex body the nearest boundary point lies on the nearest face plane,
// so plane distance suffices.
int FaithfulView::closest_face(const Vec3& v) const {
  const auto& tris = shape->triangles();
  int closest = 0;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t f = 0; f < tris.size(); ++f) {
    const double d = std::abs((v - vertices[tris[f][0]]).dot(normals[f]));
    if (d < best) {
      best = d;
      closest = static_cast<int>(f);
    }
  }
  return closest;
}

void FaithfulView::crossings(const Vec3& v_i, const Vec3& v_j, std::vector<Crossing>& out) const {
  out.clear();
  const int n = static_cast<int>(shape->triangles().size());
  for (int f = 0; f < n; ++f) crossing_of(*this, f, v_i, v_j, out);
}

int FaithfulView::nearest_triangle(const Vec3& p) const {
  int face = -1;
  double best = std::numeric_limits<double>::infinity();
  const int n = static_cast<int>(shape->triangles().size());
  for (int f = 0; f < n; ++f) {
    const double d = triangle_distance(*this, f, p);
    if (face < 0 || d < best) {
      best = d;
      face = f;
    }
  }
  return face;
}

void FaithfulPair::prepare(const ConvexPolyhedron& sa, const Pose& pa, const ConvexPolyhedron& sb,
                           const Pose& pb) {
  const double tol = point_in_mesh_tolerance(sa, sb);
  a = FaithfulView::place(sa, pa, tol);
  b = FaithfulView::place(sb, pb, tol);
}

std::optional<ContactPoint> FaithfulPair::test(Feature feature, FeatureScratch& scratch) const {
  return both_orders(feature, a, b, scratch);
}

std::optional<ContactPoint> FaithfulPair::detect(FeatureScratch& scratch) const {
  return all_features(a, b, scratch);
}

}  // namespace rbx::detail
