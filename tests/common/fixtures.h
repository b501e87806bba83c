// Fixtures shared by the test suites: bodies and poses built by hand, named and random rotations,
// the exact box-box penetration depth by the separating-axis theorem, a temporary folder. Engine
// types only, so every suite (engine, reference, comparisons) can use them.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "engine/body.h"
#include "engine/polyhedron.h"

namespace rbx::test {

/// An empty folder of the system's temporary directory for one test process, named by `name`
/// and the process id (ctest runs each test in a process of its own).
inline std::filesystem::path temp_dir(const std::string& name) {
  const std::filesystem::path p =
      std::filesystem::temp_directory_path() / ("rbx_" + name + "_" + std::to_string(getpid()));
  std::filesystem::remove_all(p);
  std::filesystem::create_directories(p);
  return p;
}

/// The pose at `p`, turned by `q`.
inline Pose at(const Vec3& p, const Quat& q = Quat::Identity()) { return {p, q}; }

/// A rotation drawn uniformly: a normalised four-dimensional Gaussian.
inline Quat random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  return Quat(g(rng), g(rng), g(rng), g(rng)).normalized();
}

/// A sharp wedge: a triangular prism whose edge angle is about 11 degrees (the detector's
/// tolerance reaches far beyond its sharp edge: tolerance_reach above 5).
inline ConvexPolyhedron sharp_wedge() {
  return ConvexPolyhedron::from_triangles(
      {Vec3(0, 0, 0), Vec3(1, 0.1, 0), Vec3(1, -0.1, 0), Vec3(0, 0, 0.5), Vec3(1, 0.1, 0.5),
       Vec3(1, -0.1, 0.5)},
      {{0, 1, 2}, {3, 5, 4}, {0, 4, 1}, {0, 3, 4}, {1, 5, 2}, {1, 4, 5}, {2, 3, 0}, {2, 5, 3}});
}

/// The same double to the bit (-0 and 0 differ, a NaN equals itself).
inline bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// A box body with the given full extents, mass, pose and velocities (solid mass model).
inline RigidBody box_body(const std::string& name, const Vec3& size, double mass,
                          const Vec3& position, const Quat& orientation = Quat::Identity(),
                          const Vec3& velocity = Vec3::Zero(),
                          const Vec3& angular_velocity = Vec3::Zero(), bool is_static = false) {
  BodySpec spec;
  spec.name = name;
  spec.shape = std::make_shared<const ConvexPolyhedron>(make_box(size));
  spec.box_size = size;
  spec.mass = mass;
  spec.position = position;
  spec.orientation = orientation;
  spec.velocity = velocity;
  spec.angular_velocity = angular_velocity;
  spec.is_static = is_static;
  return make_body(spec);
}

/// Scene body: a box of full extents `size`, centre (its centre of mass) at `position`.
inline BodySpec box_spec(const std::string& name, const Vec3& size, const Vec3& position,
                         double mass = 1.0, const Quat& orientation = Quat::Identity()) {
  BodySpec s;
  s.name = name;
  s.shape_kind = ShapeKind::Box;
  s.box_size = size;
  s.shape = std::make_shared<const ConvexPolyhedron>(make_box(size));
  s.mass = mass;
  s.position = position;
  s.orientation = orientation;
  return s;
}

/// A box body of full extents `size` (mass 1 kg) whose centre is at `position`.
inline RigidBody box_at(const std::string& name, const Vec3& size, const Vec3& position,
                        const Quat& orientation = Quat::Identity(),
                        MassModel mass_model = MassModel::Solid) {
  BodySpec spec = box_spec(name, size, position, 1.0, orientation);
  spec.mass_model = mass_model;
  return make_body(spec);
}

/// Unit cube (1 kg) centred at `position`.
inline RigidBody unit_cube(const std::string& name, const Vec3& position,
                           const Quat& orientation = Quat::Identity()) {
  return box_at(name, Vec3::Ones(), position, orientation);
}

/// Square pyramid: base (+-0.5, +-0.5, 0) (two coplanar triangles), apex (0, 0, 1), local frame.
inline BodySpec pyramid_spec(const std::string& name, const Vec3& position,
                             const Quat& orientation) {
  BodySpec s;
  s.name = name;
  s.shape_kind = ShapeKind::Convex;
  s.shape = std::make_shared<const ConvexPolyhedron>(ConvexPolyhedron::from_triangles(
      {Vec3(-0.5, -0.5, 0), Vec3(0.5, -0.5, 0), Vec3(0.5, 0.5, 0), Vec3(-0.5, 0.5, 0),
       Vec3(0, 0, 1)},
      {{0, 2, 1}, {0, 3, 2}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}}));
  s.position = position;
  s.orientation = orientation;
  return s;
}

/// Unit cube turned so its body diagonal (1,1,1) points along +x: its vertex (0.5,0.5,0.5) leads
/// sqrt(3)/2 ahead of the centre, on the line of centres (a 1-D impact with no lever arm).
inline Quat diagonal_along_x() {
  return Quat::FromTwoVectors(Vec3(1, 1, 1).normalized(), Vec3::UnitX());
}

/// A generic rotation (0.7 rad about (1, 2, 3)/|.|): no axis aligned, no symmetry of the cube.
inline Quat generic_rotation() { return Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized())); }

/// The six orientations of a cube that map it onto itself used by FCL's box-box tests
/// (test_fcl_box_box.cpp): identity, pi about x, pi/2 and 3pi/2 about x, pi/2 and 3pi/2 about y.
inline std::vector<Quat> cube_symmetries() {
  return {Quat::Identity(),
          Quat(Eigen::AngleAxisd(M_PI, Vec3::UnitX())),
          Quat(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX())),
          Quat(Eigen::AngleAxisd(3 * M_PI / 2, Vec3::UnitX())),
          Quat(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitY())),
          Quat(Eigen::AngleAxisd(3 * M_PI / 2, Vec3::UnitY()))};
}

/// Extent of a body's world vertices along u: {min, max}.
inline std::pair<double, double> extent(const RigidBody& body, const Vec3& u) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (int i = 0; i < static_cast<int>(body.shape->vertices().size()); ++i) {
    const double s = body.world_vertex(i).dot(u);
    lo = std::min(lo, s);
    hi = std::max(hi, s);
  }
  return {lo, hi};
}

/// How far A must move along the unit direction n (ours: from B toward A) to separate from B:
/// until its lowest point along n reaches B's highest, max_B(n) - min_A(n).
inline double depth_along(const RigidBody& a, const RigidBody& b, const Vec3& n) {
  return extent(b, n).second - extent(a, n).first;
}

/// Exact minimum penetration depth of two box bodies by the separating-axis theorem: the least
/// of the two-sided overlaps over A's 3 and B's 3 face normals and the 9 edge cross products
/// (the minimum translation of two convex polytopes is attained on one of them). Negative when
/// separated (the largest gap).
inline double sat_depth(const RigidBody& a, const RigidBody& b) {
  const Mat3 ra = a.pose().rotation(), rb = b.pose().rotation();
  std::vector<Vec3> axes;
  for (int i = 0; i < 3; ++i) {
    axes.push_back(ra.col(i));
    axes.push_back(rb.col(i));
    for (int j = 0; j < 3; ++j) {
      const Vec3 c = ra.col(i).cross(rb.col(j));
      if (c.norm() > 1e-9) axes.push_back(c.normalized());  // parallel edges add no axis
    }
  }
  double best = std::numeric_limits<double>::infinity();
  for (const Vec3& u : axes) best = std::min({best, depth_along(a, b, u), depth_along(a, b, -u)});
  return best;
}

}  // namespace rbx::test
