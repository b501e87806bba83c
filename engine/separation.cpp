#include "engine/separation.h"

#include <algorithm>
#include <limits>

#include "engine/detect.h"

namespace rbx {

double separation_margin(const ConvexPolyhedron& a, const ConvexPolyhedron& b) {
  return 2.0 * point_in_mesh_tolerance(a, b);
}

namespace {

// The least signed distance of a's vertices beyond the plane of b's triangle `face`: the plane
// taken into a's frame once, then one dot product per vertex.
double least_beyond(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                    const Pose& pb, int face) {
  const Vec3 n = pb.orientation * b.planes()[face].normal;  // world, unit
  const Vec3 q = pb.apply(b.vertices()[b.triangles()[face][0]]);
  const Vec3 n_a = pa.orientation.conjugate() * n;  // in a's frame
  const double offset = (pa.position - q).dot(n);
  double least = std::numeric_limits<double>::infinity();
  for (const Vec3& v : a.vertices()) least = std::min(least, v.dot(n_a));
  return least + offset;
}

}  // namespace

bool beyond_face(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                 const Pose& pb, int face, double margin) {
  return least_beyond(a, pa, b, pb, face) > margin;
}

int find_face_beyond(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                     const Pose& pb, double margin) {
  const long work =
      static_cast<long>(b.triangles().size()) + static_cast<long>(a.vertices().size());
  if (work > kMaxSeparationWork) return -1;
  // The one triangle most likely to separate: its normal nearest the direction from b's centre
  // of mass toward a's (in b's frame). Trying every triangle cost more, on the pairs where
  // none separates, than it saved (many_1000).
  const Vec3 d = pb.inverse_apply(pa.position);
  int best = -1;
  double best_dot = -std::numeric_limits<double>::infinity();
  for (size_t f = 0; f < b.triangles().size(); ++f) {
    const double x = b.planes()[f].normal.dot(d);
    if (x > best_dot) {
      best_dot = x;
      best = static_cast<int>(f);
    }
  }
  return best >= 0 && beyond_face(a, pa, b, pb, best, margin) ? best : -1;
}

bool still_separated(const SeparationWitness& w, const ConvexPolyhedron& a, const Pose& pa,
                     const ConvexPolyhedron& b, const Pose& pb, double margin) {
  return w.face_of_b >= 0 && w.face_of_a >= 0 && beyond_face(a, pa, b, pb, w.face_of_b, margin) &&
         beyond_face(b, pb, a, pa, w.face_of_a, margin);
}

}  // namespace rbx
