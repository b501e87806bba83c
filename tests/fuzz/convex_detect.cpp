// Fuzz target `convex_detect`: the custom detector on random convex pairs (see targets.h).
#include <cmath>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "comparisons/scene/mesh_io.h"
#include "engine/contact_plane.h"
#include "engine/detect.h"
#include "tests/fuzz/byte_reader.h"
#include "tests/fuzz/targets.h"

namespace rbx::fuzz {

namespace {

// A power of two from 2^-12 to 2^12 (m): shapes from ~0.2 mm to ~4 km, size ratios to 2^24.
double scale_from(ByteReader& in) { return std::ldexp(1.0, in.u8() % 25 - 12); }

// 4 to 16 points on a 1/8 grid times the shape's scale: coplanar, collinear and coincident
// points are common, which is what the hull and the detector's degenerate branches need.
std::vector<Vec3> decode_points(ByteReader& in) {
  const double scale = scale_from(in);
  const int n = 4 + in.u8() % 13;
  std::vector<Vec3> points;
  for (int i = 0; i < n; ++i)
    points.emplace_back(in.i8() / 8.0 * scale, in.i8() / 8.0 * scale, in.i8() / 8.0 * scale);
  return points;
}

// A pose: position in units of `reach` (so the shapes overlap often), orientation from four
// signed bytes normalised (small integers give exact 90 and 180 degree turns too).
Pose decode_pose(ByteReader& in, double reach) {
  Pose p;
  p.position = Vec3(in.i8(), in.i8(), in.i8()) * (reach / 64.0);
  const Quat q(in.i8(), in.i8(), in.i8(), in.i8());
  if (q.norm() > 0) p.orientation = q.normalized();
  return p;
}

// World bounding box of a placed shape.
Aabb world_box(const ConvexPolyhedron& s, const Pose& pose) {
  Aabb box;
  box.min = box.max = pose.apply(s.vertices()[0]);
  for (const Vec3& v : s.vertices()) {
    const Vec3 w = pose.apply(v);
    box.min = box.min.cwiseMin(w);
    box.max = box.max.cwiseMax(w);
  }
  return box;
}

std::string describe_vec(const Vec3& v) {
  std::ostringstream s;
  s.precision(17);
  s << v.transpose();
  return s.str();
}

std::string describe_num(double x) {
  std::ostringstream s;
  s.precision(17);
  s << x;
  return s.str();
}

std::string describe(const ContactPoint& c) {
  std::ostringstream s;
  s.precision(17);
  s << c.feature << " point (" << c.point.transpose() << ") normal (" << c.normal.transpose()
    << ") depth " << c.depth;
  return s.str();
}

// The contract of a contact (engine/contact.h): unit normal, finite point, finite depth >= 0.
void check_contact(const ContactPoint& c, const std::string& detector) {
  const std::string what = detector + ": " + describe(c);
  require(c.point.allFinite(), "non-finite point: " + what);
  require(c.normal.allFinite(), "non-finite normal: " + what);
  // Unit to round-off: a normalised vector is within a few ulps of length 1.
  require(std::abs(c.normal.norm() - 1.0) < 1e-12, "normal not unit: " + what);
  require(std::isfinite(c.depth) && c.depth >= 0, "depth negative or non-finite: " + what);
  require(c.feature == "face" || c.feature == "vertex" || c.feature == "edge",
          "unknown feature: " + what);
}

}  // namespace

void convex_detect(const uint8_t* data, size_t size) {
  ByteReader in(data, size);
  const std::vector<Vec3> points_a = decode_points(in);
  const std::vector<Vec3> points_b = decode_points(in);
  std::optional<ConvexPolyhedron> a, b;
  try {
    a = convex_hull(points_a);
    b = convex_hull(points_b);
  } catch (const GeometryError&) {
    return;  // flat or too few distinct points: not a pair to test
  }
  const double reach = shape_size(*a) + shape_size(*b);
  const Pose pa = decode_pose(in, reach);
  const Pose pb = decode_pose(in, reach);

  const std::optional<ContactPoint> faithful = detect(*a, pa, *b, pb, Detector::Faithful);
  const std::optional<ContactPoint> accelerated = detect(*a, pa, *b, pb, Detector::Accelerated);
  if (faithful) check_contact(*faithful, "Faithful");
  if (accelerated) check_contact(*accelerated, "Accelerated");

  // Apart shapes have no contact. The detector counts points up to its tolerance outside a face
  // plane as inside; near a sharp vertex that slab reaches tol / sin(angle) out, and the 1/8
  // grid allows angles down to ~1e-5 rad, so only a gap above 1e-3 of the larger size is
  // certainly no touch.
  const Aabb box_a = world_box(*a, pa), box_b = world_box(*b, pb);
  const double gap =
      std::max((box_a.min - box_b.max).maxCoeff(), (box_b.min - box_a.max).maxCoeff());
  const double larger = std::max(shape_size(*a), shape_size(*b));
  // The message is built only when there is a contact to describe (an empty optional has none).
  if (gap > 1e-3 * larger && faithful)
    require(false,
            "contact between shapes " + std::to_string(gap) + " m apart: " + describe(*faithful));

  // Accelerated must give Faithful's answer (engine/detect.h), to round-off: both sum the same
  // handful of terms of order `reach`, so 1e-9 of it is ~10^6 ulps of room for a different order of
  // sums.
  require(faithful.has_value() == accelerated.has_value(),
          "Accelerated and Faithful disagree on touching");
  if (faithful && accelerated) {
    const double tol = 1e-9 * reach;
    require(faithful->feature == accelerated->feature,
            "Accelerated and Faithful disagree on the feature: " + describe(*faithful) + " vs " +
                describe(*accelerated));
    require((faithful->point - accelerated->point).norm() <= tol &&
                (faithful->normal - accelerated->normal).norm() <= 1e-9 &&
                std::abs(faithful->depth - accelerated->depth) <= tol,
            "Accelerated and Faithful disagree: " + describe(*faithful) + " vs " +
                describe(*accelerated));
  }

  // The contact plane of a touching pair (engine/contact_plane.h), by both of its methods: a
  // unit normal, a depth >= 0 that is the overlap along that normal, and the same least overlap
  // from the scan and the search (on an exact tie they may name different axes of it). The
  // same round-off room as above: projections of coordinates of order `reach`.
  if (accelerated) {
    const double tol = 1e-9 * reach;
    double depth[2] = {0.0, 0.0};
    for (const PlaneMethod method : {PlaneMethod::Scan, PlaneMethod::Search}) {
      const ContactPlane p = choose_contact_plane(*a, pa, *b, pb, method);
      const std::string what = std::string(method == PlaneMethod::Scan ? "scan" : "search") +
                               " plane: normal (" + describe_vec(p.normal) + ") depth " +
                               describe_num(p.depth);
      require(p.normal.allFinite() && std::abs(p.normal.norm() - 1.0) < 1e-12,
              "normal not unit: " + what);
      require(std::isfinite(p.depth) && p.depth >= 0, "depth negative or non-finite: " + what);
      require(std::abs(overlap_along(*a, pa, *b, pb, p.normal) - p.depth) <= tol,
              "depth is not the overlap along the normal: " + what);
      depth[method == PlaneMethod::Scan ? 0 : 1] = p.depth;
    }
    require(std::abs(depth[0] - depth[1]) <= tol,
            "scan and search disagree on the depth: " + describe_num(depth[0]) + " vs " +
                describe_num(depth[1]));
  }
}

}  // namespace rbx::fuzz
