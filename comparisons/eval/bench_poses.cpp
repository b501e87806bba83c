// `rbx bench`'s cases: the shapes (a unit box, hulls of random points on a sphere), the poses at
// which every contact backend is timed (touching, deep, separated along a random direction), the
// crowd of cubes of the broad-phase cases, and the exponent of a time's growth with N
// (comparisons/eval/bench_cases.h).
#include <cmath>
#include <memory>
#include <random>
#include <utility>

#include "comparisons/eval/bench_cases.h"
#include "comparisons/scene/mesh_io.h"
#include "comparisons/scene/scene_file.h"

namespace rbx {

namespace {

// Three draws as a vector's x, y, z, taken z first: the order in which GCC evaluated
// `Vec3(g(rng), g(rng), g(rng))` when the benchmark's shapes and poses were first drawn. C++
// leaves that order unspecified (clang takes x first), so each draw is its own statement: the
// same cases under every compiler.
template <class Dist>
Vec3 draw_zyx(Dist& d, std::mt19937_64& rng) {
  const double z = d(rng), y = d(rng), x = d(rng);
  return Vec3(x, y, z);
}

}  // namespace

ConvexPolyhedron sphere_hull(int n, std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Vec3> points;
  while (static_cast<int>(points.size()) < n) {
    const Vec3 v = draw_zyx(g, rng);
    if (v.norm() > 1e-9) points.push_back(0.5 * kBenchShapeSize * v.normalized());
  }
  return convex_hull(points);
}

namespace {

RigidBody body_of(const std::string& name, const ConvexPolyhedron& shape, bool box) {
  BodySpec spec;
  spec.name = name;
  spec.shape_kind = box ? ShapeKind::Box : ShapeKind::Convex;
  spec.box_size = Vec3::Constant(kBenchShapeSize);
  spec.shape = std::make_shared<const ConvexPolyhedron>(shape);
  return make_body(spec);
}

Quat random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  // w, x, y, z drawn last to first, as GCC did (draw_zyx).
  const Vec3 xyz = draw_zyx(g, rng);
  const double w = g(rng);
  return Quat(w, xyz.x(), xyz.y(), xyz.z()).normalized();
}

}  // namespace

PosedPair make_poses(const ConvexPolyhedron& shape, bool box, const PoseKind& kind, int count,
                     std::mt19937_64& rng) {
  PosedPair p{body_of("A", shape, box), body_of("B", shape, box), {}, {}};
  const ContactFn ccd = find_backend("libccd-mpr")->contact;
  for (int k = 0; k < count; ++k) {
    p.a.position = Vec3::Zero();
    p.a.orientation = random_rotation(rng);
    p.b.orientation = random_rotation(rng);
    const Vec3 d = random_rotation(rng) * Vec3::UnitX();
    double lo = 0.0, hi = 2.0 * kBenchShapeSize * std::sqrt(3.0);  // overlapping at lo, apart at hi
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      p.b.position = mid * d;
      (ccd(p.a, p.b).contacts.empty() ? hi : lo) = mid;
    }
    p.b.position = (lo + kind.offset * kBenchShapeSize) * d;
    p.poses_a.push_back(p.a.pose());
    p.poses_b.push_back(p.b.pose());
  }
  return p;
}

std::vector<RigidBody> cube_crowd(int n, std::mt19937_64& rng) {
  std::vector<RigidBody> bodies;
  const double side = 0.5 * std::cbrt(static_cast<double>(n));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto cube = std::make_shared<const ConvexPolyhedron>(make_box(Vec3::Constant(0.2)));
  for (int i = 0; i < n; ++i) {
    BodySpec spec;
    spec.name = "c" + std::to_string(i);
    spec.box_size = Vec3::Constant(0.2);
    spec.shape = cube;
    spec.position = side * draw_zyx(unit, rng);
    spec.orientation = random_rotation(rng);
    bodies.push_back(make_body(spec));
  }
  return bodies;
}

double series_exponent(const std::vector<NarrowRow>& rows, const std::string& backend,
                       const std::string& variant, const std::string& pose) {
  std::vector<std::pair<double, double>> pts;
  for (const NarrowRow& r : rows)
    if (r.backend == backend && r.variant == variant && r.pose == pose && r.vertices > 8 &&
        std::isfinite(r.ns_per_query.median))
      pts.push_back({static_cast<double>(r.vertices), r.ns_per_query.median});
  return fit_exponent(pts);
}

std::string narrow_series(const std::string& backend, const std::string& variant,
                          const std::string& pose) {
  return backend + "/" + variant + "/" + pose;
}

void fill_exponents(BenchResults& results) {
  for (const NarrowBackend& b : narrow_backends())
    for (const PoseKind& k : kPoseKinds)
      results.narrow_exponents[narrow_series(b.backend, b.variant, k.name)] =
          series_exponent(results.narrow, b.backend, b.variant, k.name);
  for (BroadPhaseMethod m : kBenchBroadPhaseMethods) {
    std::vector<std::pair<double, double>> pts;
    for (const BroadRow& r : results.broad)
      if (r.method == to_string(m) && std::isfinite(r.ns_per_step.median))
        pts.push_back({static_cast<double>(r.bodies), r.ns_per_step.median});
    results.broad_exponents[to_string(m)] = fit_exponent(pts);
  }
}

double fit_exponent(const std::vector<std::pair<double, double>>& points) {
  if (points.size() < 2) return NAN;
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const auto& [n, t] : points) {
    const double x = std::log(n), y = std::log(t);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  const double m = static_cast<double>(points.size());
  return (m * sxy - sx * sy) / (m * sxx - sx * sx);
}

}  // namespace rbx
