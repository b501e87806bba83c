// Contact vocabulary shared by the engine and every user of its contacts (the reference
// libraries' adapters, the comparisons).
//
// Convention (everywhere): for a contact between A and B, in that order, `normal` is a unit
// vector in the world frame pointing from B toward A (the direction that pushes A out of B);
// `depth` >= 0 is the penetration along that normal; `point` is in world coordinates.
#pragma once

#include <string>
#include <vector>

#include "engine/math.h"

namespace rbx {

/// Which of the custom detector's tests found a contact (Moore & Wilhelms).
enum class Feature {
  Face,    ///< a triangle centroid of one shape inside the other
  Vertex,  ///< a vertex of one shape inside the other
  Edge,    ///< a point of an edge of one shape inside the other
};

/// "face" | "vertex" | "edge": the label the custom detector writes into ContactPoint::feature.
inline const char* to_string(Feature feature) {
  switch (feature) {
    case Feature::Face:
      return "face";
    case Feature::Vertex:
      return "vertex";
    case Feature::Edge:
      return "edge";
  }
  return "face";
}

/// One contact point between two bodies, in the convention above.
struct ContactPoint {
  Vec3 point = Vec3::Zero();    // m, world
  Vec3 normal = Vec3::UnitZ();  // unit, world, from B toward A
  double depth = 0.0;           // m, >= 0
  // What found the point, as written into results: to_string(Feature) for the custom detector,
  // a library's own label ("mpr", "gjk-epa", ...) for a reference library. A label, not a type:
  // the libraries' labels are open-ended, and the custom engine dispatches on Feature.
  std::string feature;
};

/// One point of a contact manifold (engine/manifold.h): the points of a pair share its normal.
struct ManifoldPoint {
  Vec3 point = Vec3::Zero();  // m, world
  double depth = 0.0;         // m, >= 0, penetration along the manifold normal at this point
};

}  // namespace rbx
