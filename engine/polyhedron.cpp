#include "engine/polyhedron.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <sstream>
#include <utility>
#include <vector>

#include "engine/bvh.h"
#include "engine/gauss_map.h"
#include "engine/shape_hierarchy.h"

namespace rbx {

namespace {

std::string fmt_vec(const Vec3& v) {
  std::ostringstream s;
  s << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return s.str();
}

}  // namespace

namespace {

// Counts and finiteness: at least a tetrahedron, every vertex finite.
void check_counts(const std::vector<Vec3>& vertices,
                  const std::vector<std::array<int, 3>>& triangles) {
  const int nv = static_cast<int>(vertices.size());
  if (nv < 4)
    throw GeometryError("a polyhedron needs at least 4 vertices, got " + std::to_string(nv));
  if (triangles.size() < 4)
    throw GeometryError("a polyhedron needs at least 4 faces, got " +
                        std::to_string(triangles.size()));
  for (int i = 0; i < nv; ++i)
    if (!vertices[i].allFinite())
      throw GeometryError("vertex " + std::to_string(i) + " is not finite");
}

// Indices in range, no degenerate triangle (area against `scale`, m), no unused vertex.
void check_triangles(const std::vector<Vec3>& vertices,
                     const std::vector<std::array<int, 3>>& triangles, double scale) {
  const int nv = static_cast<int>(vertices.size());
  std::vector<int> uses(nv, 0);
  for (size_t f = 0; f < triangles.size(); ++f) {
    const auto& t = triangles[f];
    for (int k = 0; k < 3; ++k) {
      if (t[k] < 0 || t[k] >= nv)
        throw GeometryError("face " + std::to_string(f) + " refers to vertex " +
                            std::to_string(t[k]) + ", but there are " + std::to_string(nv));
      ++uses[t[k]];
    }
    const Vec3 n = (vertices[t[1]] - vertices[t[0]]).cross(vertices[t[2]] - vertices[t[0]]);
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || n.norm() <= 1e-12 * scale * scale)
      throw GeometryError("face " + std::to_string(f) + " is degenerate (zero area)");
  }
  for (int i = 0; i < nv; ++i)
    if (uses[i] == 0)
      throw GeometryError("vertex " + std::to_string(i) + " is not used by any face");
}

// Closed and consistently oriented: each directed edge once, and its reverse once. Fills the
// unique edges (a < b) and, for each, its two triangles (a -> b first).
void link_edges(const std::vector<std::array<int, 3>>& triangles, std::vector<Edge>& edges,
                std::vector<std::array<int, 2>>& edge_faces) {
  std::map<std::pair<int, int>, int> directed;
  for (size_t f = 0; f < triangles.size(); ++f) {
    const auto& t = triangles[f];
    for (int k = 0; k < 3; ++k) {
      const std::pair<int, int> e{t[k], t[(k + 1) % 3]};
      if (!directed.emplace(e, static_cast<int>(f)).second)
        throw GeometryError("faces " + std::to_string(directed[e]) + " and " + std::to_string(f) +
                            " are inconsistently oriented (both use edge " +
                            std::to_string(e.first) + "->" + std::to_string(e.second) + ")");
    }
  }
  for (const auto& [e, f] : directed) {
    if (!directed.count({e.second, e.first}))
      throw GeometryError("mesh is open: edge " + std::to_string(e.first) + "-" +
                          std::to_string(e.second) + " of face " + std::to_string(f) +
                          " has no neighbouring face");
    if (e.first < e.second) {
      edges.push_back({e.first, e.second});
      edge_faces.push_back({f, directed[{e.second, e.first}]});
    }
  }
}

}  // namespace

// Outline: counts, bounds and tolerance, triangles, edges (closed, oriented), volume (outward),
// planes, convexity, then the hierarchy.
ConvexPolyhedron ConvexPolyhedron::from_triangles(std::vector<Vec3> vertices,
                                                  std::vector<std::array<int, 3>> triangles) {
  check_counts(vertices, triangles);
  // Scale for tolerances: the largest extent of the vertex cloud.
  ConvexPolyhedron p;
  p.bounds_.min = p.bounds_.max = vertices[0];
  for (const Vec3& v : vertices) {
    p.bounds_.min = p.bounds_.min.cwiseMin(v);
    p.bounds_.max = p.bounds_.max.cwiseMax(v);
  }
  p.size_ = (p.bounds_.max - p.bounds_.min).norm();
  const double scale = std::max((p.bounds_.max - p.bounds_.min).maxCoeff(), 1e-300);
  // Round-off of plane offsets grows with |x| * eps; 1e-9 of the size leaves room for meshes
  // written with ~10 significant digits (OBJ files) while still catching real dents.
  const double tol = 1e-9 * std::max(scale, p.bounds_.max.cwiseAbs().maxCoeff());
  check_triangles(vertices, triangles, scale);
  link_edges(triangles, p.edges_, p.edge_faces_);
  p.vertices_ = std::move(vertices);
  p.triangles_ = std::move(triangles);

  // Positive volume means outward (counter-clockwise seen from outside) orientation.
  const double vol = p.volume();
  if (std::abs(vol) <= 1e-12 * scale * scale * scale)
    throw GeometryError("mesh has zero volume (all vertices are coplanar)");
  if (vol < 0)
    throw GeometryError("faces are oriented inward (clockwise seen from outside); reverse them");

  // Outward planes, then convexity: every vertex on or behind every face plane.
  for (const auto& t : p.triangles_) {
    const Vec3& a = p.vertices_[t[0]];
    const Vec3 n = (p.vertices_[t[1]] - a).cross(p.vertices_[t[2]] - a).normalized();
    p.planes_.push_back({n, n.dot(a)});
  }
  p.check_convex(tol);
  for (size_t f = 0; f < p.planes_.size(); ++f)
    p.new_plane_.push_back(f == 0 || p.planes_[f].normal != p.planes_[f - 1].normal);
  p.build_hierarchy();
  return p;
}

void ConvexPolyhedron::check_convex(double tol) const {
  // Every vertex against every plane is O(F V) (an icosphere of subdivision 6: 3.4e9 tests).
  // A box tree over the vertices prunes: a box lying behind a face plane by more than tol / 2
  // (far above the round-off of the two dot products) cannot hold an outside vertex, so only
  // the boxes the plane cuts are opened, and only their leaves are tested vertex by vertex.
  const int nv = static_cast<int>(vertices_.size());
  const Bvh tree = Bvh::build(vertices_, vertices_, 16);
  auto vertex_outside = [&](size_t f, int i) { return planes_[f].distance(vertices_[i]) > tol; };
  for (size_t f = 0; f < planes_.size(); ++f) {
    const Plane& plane = planes_[f];
    // Height of a node's box corner furthest along the normal: skipped when <= tol / 2.
    auto reach = [&](int k) {
      const BvhNode& node = tree.nodes[k];
      const Vec3 corner = (plane.normal.array() > 0).select(node.max, node.min);
      return plane.normal.dot(corner) - plane.offset;
    };
    const bool outside = tree.search(
        reach, [&](double r) { return r <= 0.5 * tol; },
        [&](int i) { return vertex_outside(f, i); });
    if (!outside) continue;
    // Name the lowest-numbered outside vertex of the first face that has one.
    for (int i = 0; i < nv; ++i) {
      if (!vertex_outside(f, i)) continue;
      throw GeometryError(
          "mesh is not convex: vertex " + std::to_string(i) + " " + fmt_vec(vertices_[i]) +
          " lies " + std::to_string(plane.distance(vertices_[i])) + " outside the plane of face " +
          std::to_string(f) + " (use hull = true for its convex hull)");
    }
  }
}

void ConvexPolyhedron::build_hierarchy() {
  hierarchy_.reset();
  if (static_cast<int>(triangles_.size()) > kSmallTriangles)
    hierarchy_ = std::make_shared<const ShapeHierarchy>(ShapeHierarchy::build(*this));
  gauss_map_ = std::make_shared<const GaussMap>(GaussMap::build(*this));
}

double ConvexPolyhedron::volume() const {
  double six_v = 0.0;
  for (const auto& t : triangles_)
    six_v += vertices_[t[0]].dot(vertices_[t[1]].cross(vertices_[t[2]]));
  return six_v / 6.0;
}

int ConvexPolyhedron::support_index(const Vec3& d) const {
  int best = 0;
  double best_dot = vertices_[0].dot(d);
  for (int i = 1; i < static_cast<int>(vertices_.size()); ++i) {
    const double s = vertices_[i].dot(d);
    if (s > best_dot) {
      best_dot = s;
      best = i;
    }
  }
  return best;
}

ConvexPolyhedron ConvexPolyhedron::translated(const Vec3& offset) const {
  ConvexPolyhedron p = *this;
  for (Vec3& v : p.vertices_) v += offset;
  for (Plane& pl : p.planes_) pl.offset += pl.normal.dot(offset);
  p.bounds_.min += offset;
  p.bounds_.max += offset;
  p.size_ = (p.bounds_.max - p.bounds_.min).norm();
  p.build_hierarchy();
  return p;
}

ConvexPolyhedron make_box(const Vec3& size) {
  if (!(size.minCoeff() > 0)) throw GeometryError("box size must be positive in every axis");
  const Vec3 h = 0.5 * size;
  std::vector<Vec3> v;
  for (int i = 0; i < 8; ++i)
    v.emplace_back((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(), (i & 4) ? h.z() : -h.z());
  // Two counter-clockwise triangles per face, seen from outside.
  std::vector<std::array<int, 3>> t = {
      {0, 4, 6}, {0, 6, 2},  // -x
      {1, 3, 7}, {1, 7, 5},  // +x
      {0, 1, 5}, {0, 5, 4},  // -y
      {2, 6, 7}, {2, 7, 3},  // +y
      {0, 2, 3}, {0, 3, 1},  // -z
      {4, 5, 7}, {4, 7, 6},  // +z
  };
  return ConvexPolyhedron::from_triangles(std::move(v), std::move(t));
}

ConvexPolyhedron make_icosphere(double radius, int subdivisions) {
  if (!(radius > 0)) throw GeometryError("icosphere radius must be positive");
  if (subdivisions < 0 || subdivisions > 6)
    throw GeometryError("icosphere subdivisions must be in 0..6");
  const double g = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> v = {{-1, g, 0},  {1, g, 0},  {-1, -g, 0}, {1, -g, 0}, {0, -1, g},  {0, 1, g},
                         {0, -1, -g}, {0, 1, -g}, {g, 0, -1},  {g, 0, 1},  {-g, 0, -1}, {-g, 0, 1}};
  std::vector<std::array<int, 3>> t = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (Vec3& p : v) p.normalize();
  // Split every triangle in four; midpoints shared through an edge map.
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const std::pair<int, int> key{std::min(a, b), std::max(a, b)};
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      const int idx = static_cast<int>(v.size()) - 1;
      mid.emplace(key, idx);
      return idx;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& f : t) {
      const int ab = midpoint(f[0], f[1]), bc = midpoint(f[1], f[2]), ca = midpoint(f[2], f[0]);
      next.push_back({f[0], ab, ca});
      next.push_back({f[1], bc, ab});
      next.push_back({f[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    t = std::move(next);
  }
  for (Vec3& p : v) p *= radius;
  return ConvexPolyhedron::from_triangles(std::move(v), std::move(t));
}

ConvexPolyhedron make_prism(double radius, double height, int sides) {
  if (!(radius > 0) || !(height > 0))
    throw GeometryError("prism radius and height must be positive");
  if (sides < 3 || sides > 100000) throw GeometryError("prism sides must be in 3..100000");
  std::vector<Vec3> v;
  for (int k = 0; k < sides; ++k) {
    const double a = 2.0 * M_PI * k / sides;
    v.emplace_back(radius * std::cos(a), radius * std::sin(a), -0.5 * height);
  }
  for (int k = 0; k < sides; ++k) {
    const double a = 2.0 * M_PI * k / sides;
    v.emplace_back(radius * std::cos(a), radius * std::sin(a), 0.5 * height);
  }
  std::vector<std::array<int, 3>> t;
  // Caps as fans (bottom seen from below is clockwise in xy), sides as two triangles each.
  for (int k = 1; k + 1 < sides; ++k) {
    t.push_back({0, k + 1, k});
    t.push_back({sides, sides + k, sides + k + 1});
  }
  for (int k = 0; k < sides; ++k) {
    const int k1 = (k + 1) % sides;
    t.push_back({k, k1, sides + k1});
    t.push_back({k, sides + k1, sides + k});
  }
  return ConvexPolyhedron::from_triangles(std::move(v), std::move(t));
}

}  // namespace rbx
