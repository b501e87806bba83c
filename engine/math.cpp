#include "engine/math.h"

#include <cmath>

namespace rbx {

Mat3 rotation_x(double a) {
  Mat3 r;
  r << 1, 0, 0, 0, std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a);
  return r;
}

Mat3 rotation_y(double a) {
  Mat3 r;
  r << std::cos(a), 0, std::sin(a), 0, 1, 0, -std::sin(a), 0, std::cos(a);
  return r;
}

Mat3 rotation_z(double a) {
  Mat3 r;
  r << std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1;
  return r;
}

Mat3 rotation_from_euler_deg(const Vec3& deg) {
  const double k = M_PI / 180.0;
  return rotation_z(deg.z() * k) * rotation_y(deg.y() * k) * rotation_x(deg.x() * k);
}

Mat3 skew(const Vec3& a) {
  Mat3 s;
  s << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return s;
}

}  // namespace rbx
