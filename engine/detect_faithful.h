// The faithful detector's shape view: the seed's loops over every primitive, on copies of both
// shapes placed in the world. It is the reference of the accelerated view (engine/features.h).
#pragma once

#include <optional>
#include <vector>

#include "engine/features.h"

namespace rbx::detail {

/// A shape placed in the world, answering the view queries of engine/features.h by looping
/// over all of its primitives with the seed's expressions.
struct FaithfulView {
  const ConvexPolyhedron* shape = nullptr;
  std::vector<Vec3> vertices;  // m, world
  std::vector<Vec3> normals;   // unit, world, outward; one per triangle
  double tol = 0.0;            // m, point-in-mesh tolerance of the pair

  /// Places `s` by `pose`: world vertices r v + position and normals r n.
  static FaithfulView place(const ConvexPolyhedron& s, const Pose& pose, double tol);

  Vec3 vertex(int i) const { return vertices[i]; }
  Vec3 normal(int f) const { return normals[f]; }
  /// Always true: the seed tests every pair of shapes.
  bool may_enter() const { return true; }
  /// Every primitive of the kind, in index order.
  void candidates(Primitive kind, const FaithfulView& other, std::vector<int>& out) const;
  /// seed correction 1 (point in mesh uses p - q_f): (p - q_f) . n_f <= tol for every face f.
  bool inside(const Vec3& p) const;
  /// max over the world vertices of v . n.
  double support_max(const Vec3& n) const;
  /// min over the world vertices of v . n.
  double support_min(const Vec3& n) const;
  /// The face whose plane is nearest v (ties: lowest index).
  int closest_face(const Vec3& v) const;
  /// The crossings of [v_i, v_j] with every face plane, in face order.
  void crossings(const Vec3& v_i, const Vec3& v_j, std::vector<Crossing>& out) const;
  /// The triangle nearest p (ties: lowest index).
  int nearest_triangle(const Vec3& p) const;
  /// Always false: the seed tests every edge.
  bool segment_outside(const FaithfulView&, const Vec3&, const Vec3&) const { return false; }
};

/// A pair ready for the faithful tests: both shapes placed in the world once.
struct FaithfulPair {
  FaithfulView a, b;

  /// Places a and b with the pair's tolerance (point_in_mesh_tolerance).
  void prepare(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
               const Pose& pb);
  /// One test in both orders (seed correction 8 (both orders, normal flipped)).
  std::optional<ContactPoint> test(Feature feature, FeatureScratch& scratch) const;
  /// Face, vertex, edge in turn, each in both orders: the first hit.
  std::optional<ContactPoint> detect(FeatureScratch& scratch) const;
};

}  // namespace rbx::detail
