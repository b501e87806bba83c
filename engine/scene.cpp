#include "engine/scene.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace rbx {

long step_count(double duration, double dt) {
  // Range-check the quotient before casting: the negated test also catches NaN and infinity.
  const double steps = duration / dt;
  if (!(steps >= 0.0 && steps <= kMaxStepCount)) {
    std::ostringstream s;
    s << "duration " << duration << " s at dt = " << dt << " s is " << steps
      << " steps, not a step count a run can take (at most 2^53)";
    throw std::domain_error(s.str());
  }
  return static_cast<long>(std::llround(steps));
}

long SimSettings::steps() const { return step_count(duration, dt); }

const char* to_string(ShapeKind kind) {
  switch (kind) {
    case ShapeKind::Box:
      return "box";
    case ShapeKind::Icosphere:
      return "icosphere";
    case ShapeKind::Prism:
      return "prism";
    case ShapeKind::Convex:
      return "convex";
    case ShapeKind::Mesh:
      return "mesh";
  }
  return "box";
}

std::optional<ShapeKind> shape_kind_from_string(const std::string& name) {
  for (ShapeKind k :
       {ShapeKind::Box, ShapeKind::Icosphere, ShapeKind::Prism, ShapeKind::Convex, ShapeKind::Mesh})
    if (name == to_string(k)) return k;
  return std::nullopt;
}

const char* to_string(CheckKind check) {
  switch (check) {
    case CheckKind::Contact:
      return "contact";
    case CheckKind::Impulse:
      return "impulse";
    case CheckKind::Trajectory:
      return "trajectory";
    case CheckKind::Stability:
      return "stability";
    case CheckKind::Mass:
      return "mass";
  }
  return "contact";
}

std::optional<CheckKind> check_kind_from_string(const std::string& name) {
  for (CheckKind c : {CheckKind::Contact, CheckKind::Impulse, CheckKind::Trajectory,
                      CheckKind::Stability, CheckKind::Mass})
    if (name == to_string(c)) return c;
  return std::nullopt;
}

bool Scene::has_check(CheckKind c) const {
  return std::find(checks.begin(), checks.end(), c) != checks.end();
}

std::vector<std::string> Scene::check_names() const {
  std::vector<std::string> names;
  for (CheckKind c : checks) names.push_back(to_string(c));
  return names;
}

}  // namespace rbx
