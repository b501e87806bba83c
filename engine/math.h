// Small math vocabulary shared by the engine: vectors, rotations, poses.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace rbx {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;

/// Rigid transform: world point = orientation * local point + position.
struct Pose {
  Vec3 position = Vec3::Zero();
  Quat orientation = Quat::Identity();

  /// Maps a point from the body frame to the world frame.
  Vec3 apply(const Vec3& local) const { return orientation * local + position; }
  /// Maps a world point into the body frame.
  Vec3 inverse_apply(const Vec3& world) const {
    return orientation.conjugate() * (world - position);
  }
  /// Rotation matrix of the orientation.
  Mat3 rotation() const { return orientation.toRotationMatrix(); }
};

/// The seed's per-axis rotation matrices (Rx, Ry, Rz), angle in radians.
Mat3 rotation_x(double angle_rad);
Mat3 rotation_y(double angle_rad);
Mat3 rotation_z(double angle_rad);

/// Scene rotation: degrees about world x, then world y, then world z (R = Rz * Ry * Rx).
Mat3 rotation_from_euler_deg(const Vec3& angles_deg);

/// Skew-symmetric cross-product matrix: skew(a) * b == a.cross(b).
Mat3 skew(const Vec3& a);

}  // namespace rbx
