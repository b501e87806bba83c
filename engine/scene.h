// A scene as plain data: simulation settings, body specifications and optional closed-form
// expectations. Parsing lives in comparisons/scene/scene_file.h; the engine only consumes this
// struct.
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
  std::vector<double> sweep_dt;   // s, time steps for error against run time
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

/// What a scene asks the harness to evaluate ([checks] in a scene file).
enum class CheckKind {
  Contact,     ///< contact at the t = 0 poses
  Impulse,     ///< velocities after a collision
  Trajectory,  ///< states along a run
  Stability,   ///< long-run energy and momentum
  Mass,        ///< mass properties
};

/// "contact" | "impulse" | "trajectory" | "stability" | "mass", as written in scene files.
const char* to_string(CheckKind check);
/// The check named by a scene file's text; nothing for an unknown name.
std::optional<CheckKind> check_kind_from_string(const std::string& name);

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

/// Expected state of one body at t = duration ([expect.body.NAME]).
struct ExpectBody {
  std::string name;
  std::optional<Vec3> position;          // centre of mass, m
  std::optional<Vec3> velocity;          // m/s
  std::optional<Vec3> angular_velocity;  // rad/s, world
};

/// Expected contact between the first two bodies at the t = 0 poses ([expect.contact]).
struct ExpectContact {
  std::optional<bool> touching;
  std::optional<Vec3> normal;  // unit, from B toward A
  bool either_sign = false;    // the normal is right with either sign (a tie by symmetry)
  std::optional<double> depth;
  std::optional<Vec3> point;
};

/// The [expect] block: closed-form ground truth with an absolute tolerance (SI).
struct Expect {
  double tolerance = 1e-6;
  /// What the block holds: "analytic" (a closed form) or "exact" (the exact oracle's answer,
  /// as `rbx explore` writes into the scenes it shrinks); metrics name it as their truth.
  std::string truth = "analytic";
  /// The engines under test it binds ("custom", "custom-seed"): their misses fail the scene.
  std::vector<std::string> engines = {"custom"};
  /// Non-empty: "ENGINE: why", an engine of `engines` known to miss this, and why.
  std::string known_failure;
  std::vector<ExpectBody> bodies;
  std::optional<ExpectContact> contact;
};

/// A scene's [ensemble] table: its nudged copies belong in the report's Predictability section
/// (comparisons/eval/ensemble.h has what an ensemble measures).
struct EnsembleSpec {
  long count = 50;         // copies, >= 2
  bool step_test = false;  // also every copy at a ten times smaller step
  double duration = 0.0;   // s: > 0, the copies run this long (whole steps); 0, the scene's
};

/// A whole scene.
struct Scene {
  std::string name;
  std::string description;
  std::string file;                   // path it was read from, as given
  std::vector<CheckKind> checks;      // in the order the scene lists them
  std::vector<std::string> backends;  // empty: every backend that serves the checks
  // What the loader changed in what the file says, one line each (a quaternion normalised).
  std::vector<std::string> input_notes;
  // The overrides ("--set KEY") that changed the physics [expect] was written for: non-empty,
  // [expect] is set aside and reported as not checked.
  std::vector<std::string> expect_set_aside_by;
  SimSettings sim;
  std::vector<BodySpec> bodies;
  std::optional<Expect> expect;
  std::optional<EnsembleSpec> ensemble;  // [ensemble]: in the report's Predictability section

  /// True when `checks` holds c.
  bool has_check(CheckKind c) const;
  /// The checks as their scene-file names, in order (for output).
  std::vector<std::string> check_names() const;
};

}  // namespace rbx
