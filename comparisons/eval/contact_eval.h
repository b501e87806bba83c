// Running contact queries through the registry and comparing them.
#pragma once

#include <string>

#include "reference/backend.h"

namespace rbx {

/// A contact query's result and its run time.
struct ContactRun {
  ContactResult result;
  double runtime_s = 0.0;  // median over the repeats
  bool cached = false;     // read from the reference-result cache (runtime_s is the stored one)
};

/// Runs backend `b` on (A, B) `repeats` times (median time); a thrown exception becomes status
/// Error with its message; a backend without contact queries gives Unsupported.
ContactRun run_contact(const Backend& b, const RigidBody& a, const RigidBody& bb, int repeats = 1);

/// The deepest contact point of a result, or nullptr when there is none.
const ContactPoint* deepest(const ContactResult& r);

/// Angle between two directions, degrees in [0, 180].
double angle_deg(const Vec3& u, const Vec3& v);

}  // namespace rbx
