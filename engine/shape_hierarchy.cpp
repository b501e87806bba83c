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
  // Triangles, with the bounds of their face planes per node, and the planes in leaf order.
  for (const auto& t : tris) {
    lo.push_back(v[t[0]].cwiseMin(v[t[1]]).cwiseMin(v[t[2]]));
    hi.push_back(v[t[0]].cwiseMax(v[t[1]]).cwiseMax(v[t[2]]));
  }
  h.triangles = Bvh::build(lo, hi, kLeafSize);
  h.boxes.resize(h.triangles.nodes.size());
  for (int f : h.triangles.order)
    h.planes.push_back({planes[f].normal, planes[f].normal.dot(v[tris[f][0]])});
  for (std::size_t k = 0; k < h.triangles.nodes.size(); ++k) {
    const BvhNode& node = h.triangles.nodes[k];
    NormalBox& box = h.boxes[k];
    box.center = node.center;
    box.nlo = box.nhi = planes[h.triangles.order[node.begin]].normal;
    box.e_min = std::numeric_limits<double>::infinity();
    box.e_max = -box.e_min;
    for (int i = node.begin; i < node.end; ++i) {
      const int f = h.triangles.order[i];
      box.nlo = box.nlo.cwiseMin(planes[f].normal);
      box.nhi = box.nhi.cwiseMax(planes[f].normal);
      const double e = planes[f].normal.dot(v[tris[f][0]] - node.center);
      box.e_min = std::min(box.e_min, e);
      box.e_max = std::max(box.e_max, e);
    }
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
  // Incidence by vertex (counting sort: each list in increasing index order).
  auto incidence = [&](int count, auto ends_of, std::vector<int>& start, std::vector<int>& list) {
    start.assign(v.size() + 1, 0);
    for (int i = 0; i < count; ++i)
      for (int end : ends_of(i)) ++start[end + 1];
    for (std::size_t k = 0; k < v.size(); ++k) start[k + 1] += start[k];
    list.resize(start.back());
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (int i = 0; i < count; ++i)
      for (int end : ends_of(i)) list[fill[end]++] = i;
  };
  incidence(
      static_cast<int>(s.edges().size()),
      [&](int i) {
        return std::array<int, 2>{s.edges()[i].a, s.edges()[i].b};
      },
      h.edge_start, h.vertex_edges);
  incidence(
      static_cast<int>(tris.size()), [&](int i) { return tris[i]; }, h.triangle_start,
      h.vertex_triangles);
  // Triangle adjacency: the other triangle holding each directed edge reversed.
  h.triangle_neighbors.assign(tris.size(), {-1, -1, -1});
  for (std::size_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int from = tris[t][k], to = tris[t][(k + 1) % 3];
      for (int j = h.triangle_start[to]; j < h.triangle_start[to + 1]; ++j) {
        const auto& u = tris[h.vertex_triangles[j]];
        if ((u[0] == to && u[1] == from) || (u[1] == to && u[2] == from) ||
            (u[2] == to && u[0] == from))
          h.triangle_neighbors[t][k] = h.vertex_triangles[j];
      }
    }
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
  // The inscribed ball about the vertex mean.
  for (const Vec3& p : v) h.ball_centre += p;
  h.ball_centre /= static_cast<double>(v.size());
  h.ball_radius = std::numeric_limits<double>::infinity();
  for (const Plane& plane : planes)
    h.ball_radius = std::min(h.ball_radius, plane.offset - plane.normal.dot(h.ball_centre));
  return h;
}

}  // namespace rbx
