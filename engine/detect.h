// Narrow phase after Moore & Wilhelms, as the seed describes it: the face, vertex and edge
// tests, each returning a contact point *and* plane in one pass (seed correction 12 (contact point
// and plane in one pass)).
//
// Every function here is a pure function of two shapes and two poses (no world). Shapes are in
// their body frames; poses map them to the world. Results follow engine/contact.h: the normal is
// unit, in the world frame, from B toward A; depth >= 0.
//
// Files: this entry point switches between two implementations of the same tests, written once
// in engine/features.h: the faithful loops (engine/detect_faithful.*) and the accelerated
// queries (engine/detect_accelerated.*), which return the same answers bit for bit.
#pragma once

#include <memory>
#include <optional>

#include "engine/contact.h"
#include "engine/polyhedron.h"

namespace rbx {

/// Which implementation of the tests to run (the detector; the contact model is the other axis,
/// ContactModel). `Faithful` loops over every primitive as the seed does and is the reference;
/// `Accelerated` culls with bounding volume trees and must return the same answers bit for bit
/// (tests/engine/accelerated_detect_test.cpp). Both `custom` and `custom-seed` run Accelerated;
/// the bench's "faithful" rows and custom's "faithful" query variant run Faithful.
enum class Detector { Faithful, Accelerated };

/// "faithful" | "accelerated".
const char* to_string(Detector detector);

/// The detector's state for one pair of shapes, passed in explicitly: both shapes placed at
/// their poses (prepared once, then shared by the face, vertex and edge tests) and reusable
/// scratch lists. Owned by the caller (the World keeps one); two caches never share state, so
/// interleaved queries on one thread do not interfere. The shapes must outlive the prepared pair.
class DetectionCache {
 public:
  DetectionCache();
  ~DetectionCache();
  DetectionCache(DetectionCache&&) noexcept;
  DetectionCache& operator=(DetectionCache&&) noexcept;

  /// Places a and b at pa and pb for the tests that follow, with the given implementation.
  void prepare(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b, const Pose& pb,
               Detector detector);
  /// One kind of test in both orders on the prepared pair: (A, B), then (B, A) with the normal
  /// flipped (seed correction 8 (both orders, normal flipped)). Throws std::logic_error when
  /// nothing was prepared.
  std::optional<ContactPoint> test(Feature feature);
  /// The full detector on the prepared pair: face, vertex, edge, each in both orders; the first
  /// hit. Throws std::logic_error when nothing was prepared.
  std::optional<ContactPoint> detect();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

/// Tolerance (m) for point-in-mesh, relative to the larger shape: points within this distance
/// outside a face plane count as inside, so exactly touching bodies are seen.
double point_in_mesh_tolerance(const ConvexPolyhedron& a, const ConvexPolyhedron& b);

/// seed correction 1 (point in mesh uses p - q_f): p is inside the convex mesh iff (p - q_f) . n_f
/// <= tol for every face f. `p_world` is in the world frame; the mesh is placed by `pose`.
bool point_in_mesh(const ConvexPolyhedron& mesh, const Pose& pose, const Vec3& p_world, double tol);

/// Penetration of A into B along the unit normal n (from B toward A): how far A must move along
/// n to separate, max_b (b . n) - min_a (a . n), clamped at 0. The seed defines no depth; this
/// is the overlap of the two shapes' projections on the contact normal.
double overlap_along(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                     const Pose& pb, const Vec3& n);

/// Face test, one order (faithful): centroids of A's triangles that lie inside B, averaged (the
/// seed's "better collision point"); normal = minus the outward normal of the first such
/// triangle of A (seed correction 9 (face normal negated)). feature = "face".
std::optional<ContactPoint> face_test(const ConvexPolyhedron& a, const Pose& pa,
                                      const ConvexPolyhedron& b, const Pose& pb);

/// Vertex test, one order (faithful): the first vertex of A inside B; normal = outward normal of
/// B's face closest to it. Departure from the seed: the point is the average of every vertex of
/// A inside B whose closest face of B has that same normal (an edge or face landing flat gets
/// its impulse at its middle, not at one end). feature = "vertex".
std::optional<ContactPoint> vertex_test(const ConvexPolyhedron& a, const Pose& pa,
                                        const ConvexPolyhedron& b, const Pose& pb);

/// Edge test, one order (faithful): each edge of A is cut where it crosses the planes of B's
/// triangles (seed correction 2 (edge crossing at v_i + t (v_j - v_i))), the crossing parameters
/// sorted with 0 and 1, and the midpoint of each consecutive pair tested in B; the first inside is
/// the point. Normal: e_a x e_b, e_b the edge of B's crossed triangle nearest the point, oriented
/// from B toward A (seed correction 10 (edge normal e_a x e_b)). Departure: where the crossed
/// triangle's outward normal separates the shapes with a smaller translation than e_a x e_b (an
/// edge piercing a face, not an edge), that face normal is taken. feature = "edge".
std::optional<ContactPoint> edge_test(const ConvexPolyhedron& a, const Pose& pa,
                                      const ConvexPolyhedron& b, const Pose& pb);

/// One kind of test in both orders (see DetectionCache::test), on the caller's cache.
std::optional<ContactPoint> detect_feature(Feature feature, const ConvexPolyhedron& a,
                                           const Pose& pa, const ConvexPolyhedron& b,
                                           const Pose& pb, Detector detector,
                                           DetectionCache& cache);
/// The same with a cache of its own (convenient; a caller making many queries keeps one).
std::optional<ContactPoint> detect_feature(Feature feature, const ConvexPolyhedron& a,
                                           const Pose& pa, const ConvexPolyhedron& b,
                                           const Pose& pb,
                                           Detector detector = Detector::Accelerated);

/// The full detector in the seed's order (face, vertex, edge; each in both orders): the first
/// hit, or nothing when the shapes do not touch. On the caller's cache.
std::optional<ContactPoint> detect(const ConvexPolyhedron& a, const Pose& pa,
                                   const ConvexPolyhedron& b, const Pose& pb, Detector detector,
                                   DetectionCache& cache);
/// The same with a cache of its own.
std::optional<ContactPoint> detect(const ConvexPolyhedron& a, const Pose& pa,
                                   const ConvexPolyhedron& b, const Pose& pb,
                                   Detector detector = Detector::Accelerated);

}  // namespace rbx
