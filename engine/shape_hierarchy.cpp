#include "engine/shape_hierarchy.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/polyhedron.h"

namespace rbx {

namespace {

// Primitives per leaf of the detector's trees.
constexpr int kLeafSize = 4;

}  // namespace

ShapeHierarchy ShapeHierarchy::build(const ConvexPolyhedron& s) {
  ShapeHierarchy h;
  const auto& v = s.vertices();
  const auto& tris = s.triangles();
  const auto& planes = s.planes();
  std::vector<Vec3> lo, hi;
  // Triangles, with their normal cones and plane offsets per node.
  for (const auto& t : tris) {
    lo.push_back(v[t[0]].cwiseMin(v[t[1]]).cwiseMin(v[t[2]]));
    hi.push_back(v[t[0]].cwiseMax(v[t[1]]).cwiseMax(v[t[2]]));
  }
  h.triangles = Bvh::build(lo, hi, kLeafSize);
  h.cones.resize(h.triangles.nodes.size());
  for (std::size_t k = 0; k < h.triangles.nodes.size(); ++k) {
    const BvhNode& node = h.triangles.nodes[k];
    FaceCone& cone = h.cones[k];
    Vec3 sum = Vec3::Zero();
    for (int i = node.begin; i < node.end; ++i) sum += planes[h.triangles.order[i]].normal;
    cone.axis =
        sum.norm() > 1e-6 ? Vec3(sum.normalized()) : planes[h.triangles.order[node.begin]].normal;
    double c = 1.0;
    cone.e_min = std::numeric_limits<double>::infinity();
    cone.e_max = -cone.e_min;
    for (int i = node.begin; i < node.end; ++i) {
      const int f = h.triangles.order[i];
      c = std::min(c, cone.axis.dot(planes[f].normal));
      const double e = planes[f].normal.dot(v[tris[f][0]] - node.center);
      cone.e_min = std::min(cone.e_min, e);
      cone.e_max = std::max(cone.e_max, e);
    }
    // Widen the cone by more than the round-off of the dot products (a cosine of exactly 1 would
    // otherwise hide an angle of up to ~1e-8 rad).
    cone.cos_half = std::max(-1.0, c - 1e-15);
    cone.sin_half =
        std::min(1.0, std::sqrt(std::max(0.0, 1.0 - cone.cos_half * cone.cos_half)) + 1e-12);
  }
  // Vertices.
  h.vertices = Bvh::build(v, v, kLeafSize);
  // Edges.
  lo.clear();
  hi.clear();
  for (const Edge& e : s.edges()) {
    lo.push_back(v[e.a].cwiseMin(v[e.b]));
    hi.push_back(v[e.a].cwiseMax(v[e.b]));
  }
  h.edges = Bvh::build(lo, hi, kLeafSize);
  // The faces most along each axis direction: cull planes that approximate the bounding box.
  for (int k = 0; k < 6; ++k) {
    const Vec3 dir = (k % 2 == 0 ? 1.0 : -1.0) * Vec3::Unit(k / 2);
    double best = -2.0;
    for (std::size_t f = 0; f < planes.size(); ++f) {
      if (planes[f].normal.dot(dir) > best) {
        best = planes[f].normal.dot(dir);
        h.axis_faces[k] = static_cast<int>(f);
      }
    }
  }
  return h;
}

}  // namespace rbx
