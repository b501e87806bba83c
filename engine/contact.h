// Contact vocabulary shared by the engine, the references and the harness.
//
// Convention (everywhere): for a contact between A and B, in that order, `normal` is a unit
// vector in the world frame pointing from B toward A (the direction that pushes A out of B);
// `depth` >= 0 is the penetration along that normal; `point` is in world coordinates.
#pragma once

#include <string>
#include <vector>

#include "engine/math.h"

namespace rbx {

/// One contact point between two bodies, in the convention above.
struct ContactPoint {
  Vec3 point = Vec3::Zero();    // m, world
  Vec3 normal = Vec3::UnitZ();  // unit, world, from B toward A
  double depth = 0.0;           // m, >= 0
  std::string feature;          // "face" | "vertex" | "edge" (custom), or a backend's own label
};

}  // namespace rbx
