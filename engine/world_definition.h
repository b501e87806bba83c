// A world as plain data: simulation settings and body specifications (WorldDefinition). The
// harness's scenes (comparisons/scene/scene.h) add what they check; parsing lives in
// comparisons/scene/scene_file.h.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/mass_properties.h"
#include "engine/polyhedron.h"

namespace rbx {

/// Most steps a run can take: 2^53, the last integer a double counts exactly. Beyond it
/// duration / dt no longer names one step count, and a little further its cast to long overflows
/// (llround of 1e303 gave a negative count: a run of no steps that reported success).
constexpr double kMaxStepCount = 9007199254740992.0;

/// Number of steps of `dt` covering `duration` (rounded to the nearest; the last step may end past
/// it by < dt/2). Throws std::domain_error, naming duration and dt, when that count is not finite
/// or exceeds kMaxStepCount, so no caller casts an out-of-range value.
long step_count(double duration, double dt);

/// Time integrator.
enum class Integrator {
  Euler,       ///< the seed's: x += v dt, orientation by per-axis matrices with w dt
  Symplectic,  ///< semi-implicit: v from forces first, then x; torque-free rotation by splitting
};

/// Simulation settings ([sim] in a scene file). Defaults are the contract's.
struct SimSettings {
  double dt = 1e-3;             // s, > 0
  double duration = 1.0;        // s, >= 0
  Vec3 gravity = Vec3::Zero();  // m/s^2
  double restitution = 1.0;     // e in [0, 1]
  double friction = 0.0;        // Coulomb mu >= 0 (the seed omits friction)
  Integrator integrator = Integrator::Symplectic;
  double max_energy_ratio = 1e3;  // guard: stop when E > ratio * max(E0, tiny)

  /// Number of steps to cover `duration`: step_count(duration, dt) (throws std::domain_error when
  /// that is not a countable number).
  long steps() const;
};

/// How a body's shape was given in the scene ([[body]] shape = ...).
enum class ShapeKind {
  Box,        ///< box of full extents `size`
  Icosphere,  ///< subdivided icosahedron on a sphere
  Prism,      ///< regular n-gon prism
  Convex,     ///< listed vertices (and optionally triangles, or their hull)
  Mesh,       ///< a mesh file
};

/// "box" | "icosphere" | "prism" | "convex" | "mesh", as written in scene files.
const char* to_string(ShapeKind kind);
/// The kind named by a scene file's text; nothing for an unknown name.
std::optional<ShapeKind> shape_kind_from_string(const std::string& name);

/// One [[body]] of a scene, before mass properties are derived.
struct BodySpec {
  std::string name;
  ShapeKind shape_kind = ShapeKind::Box;
  Vec3 box_size = Vec3::Ones();                   // m, full extents (box only)
  std::shared_ptr<const ConvexPolyhedron> shape;  // in the scene's local frame
  double mass = 1.0;                              // kg
  bool is_static = false;
  MassModel mass_model = MassModel::Solid;
  // kg m^2 about the centre of mass, in the shape's local axes, where a body's inertia was
  // measured rather than follows from its shape (unset: from the shape and mass_model).
  std::optional<Mat3> inertia;
  Vec3 position = Vec3::Zero();  // m, world position of the shape's local origin
  Quat orientation = Quat::Identity();
  Vec3 velocity = Vec3::Zero();          // m/s, of the centre of mass
  Vec3 angular_velocity = Vec3::Zero();  // rad/s, world frame
};

/// What a world is made of, before any body is built: the simulation settings and the bodies'
/// specifications, as Box2D's b2WorldDef describes a world before it exists. A scene file
/// (comparisons/scene/scene.h) is one, with the comparisons' own vocabulary around it; the model
/// of contact a world steps with is named when the world is built (engine/world.h).
struct WorldDefinition {
  SimSettings sim;
  std::vector<BodySpec> bodies;
};

}  // namespace rbx
