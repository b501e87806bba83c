// Why an impact missed its closed form: the first measured sign in what a backend's first
// impulse saw against the exact oracle (the report's "Why" list).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "comparisons/eval/harness.h"
#include "comparisons/eval/metrics.h"
#include "comparisons/scene/scene.h"
#include "reference/backend.h"

namespace rbx {

/// "as written" or "1/3 of a step later" for a contact-phase label ("written", "1_3", "2_3").
std::string phase_text(const std::string& label);

/// Why backend `name` missed the impact's closed form, from its first impulse `fi` against the
/// truth: the exact oracle at the poses of the step that detected it, reached in free flight
/// from `start` (the bodies at t = 0 of the run with the larger error; valid up to the first
/// impulse; spinning bodies are not reconstructed). The sign, in this order: a wrong normal, one
/// point on a face patch, an error only when contact begins inside a step, a contact first seen
/// deep, else the response itself. `written` and `worst` are the velocity errors as written and
/// at the worst phase; `inputs` the scene's bodies and `expected` the closed form.
Cause impact_cause(const Scene& scene, const std::vector<RigidBody>& inputs,
                   const std::string& name, const FirstImpulse& fi,
                   const std::vector<RigidBody>& start, double written, double worst,
                   const std::string& worst_phase,
                   const std::vector<std::optional<RefState>>& expected);

}  // namespace rbx
