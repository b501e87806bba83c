#include "engine/world_definition.h"

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

}  // namespace rbx
