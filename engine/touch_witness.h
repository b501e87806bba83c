// The detector's answer near a touch it has found, settled without running it where the features
// of that touch can tell. A time-of-impact bisection asks the detector at every halving, about
// poses ever closer to one touch; the features that touched (the normal, the deepest vertices,
// the edges at the touch point), followed rigidly with their bodies, answer most of those asks
// at a small part of a detection's cost.
#pragma once

#include <optional>

#include "engine/contact.h"
#include "engine/polyhedron.h"

namespace rbx {

/// The features of one touch of two shapes, as the detector found it, and what they prove at
/// other poses of the same two shapes:
/// - apart: the shapes are farther apart than `reach` (separation_margin) along one of a few
///   axes: the touch's normal as found, the same turned with B, turned with A (it is a face
///   normal of one of them), and the cross product of the two edges nearest the touch point (an
///   edge-on-edge touch). Past the margin the detector finds nothing (engine/separation.h), the
///   proof ExtendedStep::separated skips the detector by.
/// - touching: a vertex of either shape deepest along the normal is strictly inside the other
///   (below each of its triangle planes), or one of the edges nearest the touch point passes
///   through the other along more than twice the pair's tolerance `tol` (point_in_mesh_tolerance)
///   of its length. The detector's vertex and edge tests then find a point (engine/detect.h):
///   the vertex, or a point of the edge's inside part. Its inside test accepts a point up to tol
///   outside, and that tol covers the round-off of this arithmetic against the detector's, as
///   the extra tolerance of separation_margin does.
/// Where neither holds, only the detector can tell. Shapes of more than kMaxSeparationWork
/// vertices and triangles together keep no witness (the detector's trees are the cheaper way).
class TouchWitness {
 public:
  /// The witness of the detector's touch `hit` of a at pa and b at pb; nothing for shapes too
  /// large. The shapes must outlive it.
  static std::optional<TouchWitness> of(const ConvexPolyhedron& a, const Pose& pa,
                                        const ConvexPolyhedron& b, const Pose& pb,
                                        const ContactPoint& hit);

  /// The detector's answer for the same shapes at pa and pb: false when apart, true when
  /// touching, nothing when the witness cannot tell. `reach`: the pair's separation_margin;
  /// `tol`: its point_in_mesh_tolerance.
  std::optional<bool> settle(const Pose& pa, const Pose& pb, double reach, double tol);

 private:
  TouchWitness(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b, const Pose& pb,
               const ContactPoint& hit);

  const ConvexPolyhedron *a_, *b_;
  Vec3 normal_;                     // world, from B toward A
  Vec3 normal_in_a_, normal_in_b_;  // the same in each shape's frame
  int vertex_a_, vertex_b_;         // each shape's vertex deepest along the normal
  int edge_a_, edge_b_;             // each shape's edge nearest the touch point (-1: none)
  int last_axis_ = 0;               // the axis that proved the pair apart last, tried first
};

}  // namespace rbx
