// Mass, centre of mass and inertia of a convex polyhedron under the two mass models.
#pragma once

#include "engine/polyhedron.h"

namespace rbx {

/// How a body's mass is distributed.
enum class MassModel {
  Solid,     ///< uniform density over the volume: exact (divergence theorem)
  Vertices,  ///< the seed's: equal point masses at the vertices
};

/// Mass properties in the shape's local frame. Inertia is about the centre of mass.
struct MassProperties {
  double mass = 0.0;                   // kg
  Vec3 center_of_mass = Vec3::Zero();  // m, shape-local frame
  Mat3 inertia = Mat3::Identity();     // kg m^2, about the centre of mass, shape-local axes
};

/// Exact uniform-density mass properties of a closed polyhedron of total mass `mass`
/// (tetrahedron decomposition from the origin: Tonon 2004 / Eberly's polyhedral integrals).
MassProperties solid_mass_properties(const ConvexPolyhedron& shape, double mass);

/// The seed's model: the centre of mass is the vertex average and the inertia tensor sums
/// point masses mass / N at the vertices, about that centre.
MassProperties vertex_mass_properties(const ConvexPolyhedron& shape, double mass);

/// Dispatches on the model.
MassProperties mass_properties(const ConvexPolyhedron& shape, double mass, MassModel model);

}  // namespace rbx
