// What explore.cpp (contact kind) and explore_dynamics.cpp (impact and landing kinds) share:
// bodies built as the scene loader builds them, random bodies, scene text, and the rounding
// used while shrinking. Internal to comparisons/eval/explore*.cpp.
#pragma once

#include <memory>
#include <string>

#include "comparisons/eval/explore.h"
#include "engine/body.h"

namespace rbx::explore_detail {

/// The body's shape exactly as the scene loader builds it (box or convex hull of the points).
std::shared_ptr<const ConvexPolyhedron> build_shape(const ExploreBody& e);
/// Orientation exactly as the scene loader builds it from what sample_scene_text writes.
Quat build_orientation(const ExploreBody& e);
/// The body as the scene loader builds it, named `name`.
RigidBody build_body(const ExploreBody& e, const std::string& name);
/// A random body of roughly `scale` metres: a box, a hull of 4 to 2000 points, or a sliver.
ExploreBody random_body(SampleRng& r, double scale);

/// The shortest text that reads back as the same double (TOML float syntax).
std::string num(double x);
/// A vector as a TOML array of num()s.
std::string vec(const Vec3& v);
/// A body's [[body]] table (shape, points, pose) as sample_scene_text writes it.
std::string body_text(const ExploreBody& e, const std::string& name);

/// Angle (rad, in [0, pi]) of the rotation taking orientation `from` to `to`; NaN when either
/// is not finite.
double rotation_angle(const Quat& from, const Quat& to);
/// Euler angles (degrees, R = Rz Ry Rx as the scene format) of a rotation.
Vec3 euler_deg(const Quat& q);
/// x to the nearest multiple of grid, as the decimal number a reader would write.
double round_to(double x, double grid);
/// Each coordinate to the nearest multiple of grid (as above).
Vec3 round_to(const Vec3& v, double grid);

}  // namespace rbx::explore_detail
