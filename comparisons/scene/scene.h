// A scene of the harness as plain data: a world definition (engine/world_definition.h: settings
// and bodies) with what the harness checks on it, the closed-form expectations of [expect], its
// ensemble and the backends it names. Parsing lives in comparisons/scene/scene_file.h.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "engine/world_definition.h"

namespace rbx {

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
  /// The contact patch's corners, world (one: a point; two: a segment's ends; more: a convex
  /// polygon's corners, in any order), compared across the normal: the bound engines' and the
  /// oracle's points must span it and lie on it (docs/contact_manifold.md). Empty: not stated.
  std::vector<Vec3> patch;
};

/// [expect.distance]: the first two bodies' separation at t = 0, as `rbx distance` asks it.
struct ExpectDistance {
  bool overlapping = false;
  double distance = 0.0;  // m, when apart
};

/// [expect.toi]: the first two bodies' first touch as they move over the interval dt, as
/// `rbx toi` asks it.
struct ExpectToi {
  bool touch = false;
  double fraction = 0.0;  // of the interval, when they touch
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
  std::optional<ExpectDistance> distance;
  std::optional<ExpectToi> toi;
};

/// A scene's [ensemble] table: its nudged copies belong in the report's Predictability section
/// (comparisons/eval/ensemble.h has what an ensemble measures).
struct EnsembleSpec {
  long count = 50;         // copies, >= 2
  bool step_test = false;  // also every copy at a ten times smaller step
  double duration = 0.0;   // s: > 0, the copies run this long (whole steps); 0, the scene's
};

/// A whole scene: a world (the settings and bodies, engine/world_definition.h) and what the
/// harness does with it.
struct Scene : WorldDefinition {
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
  std::optional<Expect> expect;
  std::optional<EnsembleSpec> ensemble;  // [ensemble]: in the report's Predictability section
  // [sim] dt_study: the time steps (s) each dynamics backend also runs at for error against run
  // time; empty, the scene's dt scaled by 4, 2, 1, 1/2 and 1/4 (dt_study_steps).
  std::vector<double> dt_study;

  /// True when `checks` holds c.
  bool has_check(CheckKind c) const;
  /// The checks as their scene-file names, in order (for output).
  std::vector<std::string> check_names() const;
};

}  // namespace rbx
