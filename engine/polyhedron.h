// Convex polyhedron: the one shape type of the engine (the seed's "mesh held by an actor").
#pragma once

#include <array>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/math.h"

namespace rbx {

struct ShapeHierarchy;
struct GaussMap;

/// Raised when a mesh is not a valid closed convex polyhedron; the message names the feature.
class GeometryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Range of lengths (m) a shape may have: extents, radii, heights, and the magnitude of vertex
/// coordinates. Validation squares lengths (L^2), takes triple products (L^3, volumes) and the
/// inertia integrates r^2 over the volume (L^5); at L = 1e12 m those stay near 1e60, far below
/// the double limit of 1.8e308 (a 1e150 m box overflowed and was called "zero volume"), and
/// 1e12 m is already 7 astronomical units. The lower end keeps L^5 near 1e-60, far above the
/// double underflow near 1e-308; nothing physical in a rigid-body scene is below a picometre.
constexpr double kMaxLength = 1e12;
constexpr double kMinLength = 1e-12;

/// Oriented plane: points x with normal . x == offset; normal is unit and outward.
struct Plane {
  Vec3 normal = Vec3::UnitZ();
  double offset = 0.0;
  /// Signed distance of x from the plane (positive outside).
  double distance(const Vec3& x) const { return normal.dot(x) - offset; }
};

/// Undirected edge between two vertex indices (a < b).
struct Edge {
  int a = 0;
  int b = 0;
};

/// Axis-aligned box given by its corners.
struct Aabb {
  Vec3 min = Vec3::Zero();
  Vec3 max = Vec3::Zero();
  /// Centre of the box (m).
  Vec3 center() const { return 0.5 * (min + max); }
  /// Half the box's extent along each axis (m).
  Vec3 half_extents() const { return 0.5 * (max - min); }
};

/// A closed convex polyhedron with counter-clockwise (outward) triangles, unique edges and one
/// outward plane per triangle. Immutable once built; every constructor validates.
class ConvexPolyhedron {
 public:
  /// Builds from vertices and triangles and validates: closed, consistently oriented
  /// (outward, counter-clockwise), convex, positive volume, no degenerate triangle, no unused
  /// vertex. Throws GeometryError naming the offending face or vertex.
  static ConvexPolyhedron from_triangles(std::vector<Vec3> vertices,
                                         std::vector<std::array<int, 3>> triangles);

  /// Vertices (m), in the shape's frame.
  const std::vector<Vec3>& vertices() const { return vertices_; }
  /// Triangles as vertex indices, counter-clockwise seen from outside.
  const std::vector<std::array<int, 3>>& triangles() const { return triangles_; }
  /// Unique edges of the triangulation (each once, whatever its two triangles).
  const std::vector<Edge>& edges() const { return edges_; }
  /// The two triangles of edge i (edges()[i]): the one using it from a to b, then the other.
  const std::vector<std::array<int, 2>>& edge_faces() const { return edge_faces_; }
  /// Outward plane of triangle i.
  const std::vector<Plane>& planes() const { return planes_; }
  /// 1 where triangle i's normal differs (bit for bit) from triangle i - 1's, so a new plane
  /// starts (always 1 for triangle 0); 0 for the second triangle of a box face and the like.
  const std::vector<unsigned char>& new_plane() const { return new_plane_; }
  /// Axis-aligned bounds of the vertices, in the shape's frame.
  const Aabb& bounds() const { return bounds_; }
  /// The accelerated detector's trees over this shape (engine/shape_hierarchy.h), built with it;
  /// null for shapes of at most kSmallTriangles triangles, which are tested with plain loops.
  const ShapeHierarchy* hierarchy() const { return hierarchy_.get(); }
  /// The Gauss map's cone trees over this shape (engine/gauss_map.h), built with it for every
  /// shape: the contact plane's search.
  const GaussMap& gauss_map() const { return *gauss_map_; }

  /// Enclosed volume (m^3), by the divergence theorem.
  double volume() const;
  /// Vertex furthest along direction d (ties: lowest index).
  int support_index(const Vec3& d) const;
  /// The same polyhedron with every vertex moved by offset.
  ConvexPolyhedron translated(const Vec3& offset) const;

  friend double shape_size(const ConvexPolyhedron& s);

 private:
  std::vector<Vec3> vertices_;
  std::vector<std::array<int, 3>> triangles_;
  std::vector<Edge> edges_;
  std::vector<std::array<int, 2>> edge_faces_;
  std::vector<Plane> planes_;
  std::vector<unsigned char> new_plane_;
  Aabb bounds_;
  double size_ = 0.0;  // shape_size: the diagonal of bounds_, kept (every query asks for it)
  std::shared_ptr<const ShapeHierarchy> hierarchy_;  // shared by copies: the shape is immutable
  std::shared_ptr<const GaussMap> gauss_map_;        // likewise

  // Builds hierarchy_ (or clears it for a small shape) and gauss_map_ from the shape's current
  // geometry.
  void build_hierarchy();
  // Throws GeometryError naming the first face with a vertex more than `tol` (m) outside its
  // plane.
  void check_convex(double tol) const;
};

/// The size of a shape: the diagonal of its bounding box (m). Every tolerance and error that is
/// relative to a body is a fraction of it (of the smaller body's, for a pair).
inline double shape_size(const ConvexPolyhedron& s) { return s.size_; }

/// Box with full extents `size`, centred at the origin (12 triangles).
ConvexPolyhedron make_box(const Vec3& size);
/// Icosahedron subdivided `subdivisions` times and projected onto the sphere of `radius`.
ConvexPolyhedron make_icosphere(double radius, int subdivisions);
/// Regular `sides`-gon prism along local z, circumradius `radius`, centred at the origin.
ConvexPolyhedron make_prism(double radius, double height, int sides);

}  // namespace rbx
