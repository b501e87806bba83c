// JSON vocabulary of results (the contract's shape) and atomic output.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "comparisons/eval/timing.h"
#include "comparisons/scene/scene.h"
#include "engine/body.h"
#include "engine/contact.h"
#include "engine/world.h"
#include "reference/backend.h"

namespace rbx {

using Json = nlohmann::ordered_json;

/// [x, y, z].
Json to_json(const Vec3& v);
/// [w, x, y, z].
Json to_json(const Quat& q);
/// Row-major [[..], [..], [..]].
Json to_json(const Mat3& m);
/// A contact between named bodies at a time: bodies, time, feature, point, normal, depth.
Json contact_json(const std::string& a, const std::string& b, double time, const ContactPoint& c);
/// A collision event: contact_json plus step and impulse.
Json event_json(const CollisionEvent& e);
/// Mass properties at t = 0 in the world frame (mass, center_of_mass, inertia about the COM).
Json body_inputs_json(const RigidBody& b);
/// The contract's `bodies` block: NAME -> body_inputs_json, plus `final` from `finals` (same
/// order as `inputs`) when given. Every backend gets the same inputs, so contact and mass
/// results carry the scene's bodies without `final`.
Json bodies_json(const std::vector<RigidBody>& inputs,
                 const std::vector<BodyFinal>* finals = nullptr);
/// {"position", "orientation", "velocity", "angular_velocity"}.
Json final_json(const BodyFinal& f);
/// The scene's settings as written into results (every tunable, for reproducibility).
Json settings_json(const Scene& scene);

/// One backend's dynamics result in the contract's shape: status, message, runtime_s,
/// contacts (collision events), bodies (inputs at t = 0 and final state), first_impulse, and
/// when states were sampled, trajectory {time: [t], bodies: [names, in scene order],
/// states: [frame][body][px, py, pz, qw, qx, qy, qz]}.
Json dynamics_result_json(const std::vector<RigidBody>& inputs, const DynamicsResult& r,
                          double runtime_s);

/// A run's contact-law residuals (reference/contact_laws.h): the points scored and each law's
/// worst and median; when the backend reported no impulses, {"measured": false} with, when it
/// has events, their count as `contacts` and the penetration at their detection.
Json contact_laws_json(const DynamicsResult& r);

/// What the run's first impulse saw (FirstImpulse), or null when no impulse was applied:
/// pair, step, contact_points, normal, point, depth, impulse, approach_speed, entry_phase.
Json first_impulse_json(const FirstImpulse& f);

/// A timing (timing.h) into a JSON object: `runtime_s` (the median per call) and `timing`
/// {q25_s, q75_s, calls, rounds, cold_s}; read back by timing_of.
void put_timing(const Timing& t, Json& into);
Timing timing_of(const Json& from);

/// Writes text to `path` atomically (temporary file in the same folder, then rename), or to
/// standard output when path is "-". Throws std::runtime_error on failure.
void write_text(const std::string& path, const std::string& text);
/// Pretty JSON (2-space indent, trailing newline) through write_text.
void write_json(const std::string& path, const Json& j);

/// Wall-clock stopwatch for runtime_s fields (the only non-deterministic numbers we write).
class Stopwatch {
 public:
  Stopwatch();
  /// Seconds since construction.
  double seconds() const;

 private:
  long long start_ns_;
};

}  // namespace rbx
