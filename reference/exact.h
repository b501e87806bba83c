// Exact contact oracle: separating-axis test over all face normals and edge-pair cross products, and the contact manifold by clipping the reference face against the incident face.
#pragma once

#include "reference/backend.h"

namespace rbx {

/// Result of the exact SAT query between two placed convex polyhedra.
struct SatResult {
  bool touching = false;       // overlap >= 0 on every axis (touching counts)
  Vec3 normal = Vec3::UnitZ();  // unit, world, from B toward A: minimum-translation direction
  double depth = 0.0;          // m: minimum translation distance (negative: separation lower bound)
  std::string axis_kind;       // "face_a" | "face_b" | "edge_edge"
  std::vector<Vec3> manifold;  // contact polygon (world): clipped reference/incident faces
};

/// Exact separating-axis query.
SatResult sat_query(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                    const Pose& pb);

/// Backend `exact`: one contact per manifold point, each with the SAT normal and depth;
/// the first contact is the manifold centroid.
ContactResult exact_contact(const RigidBody& a, const RigidBody& b);

}  // namespace rbx
