// Why a contact query's answer is marked against the truth: the first measured sign on that
// answer (the report's "Why" list and the scorecard's causes). A library's explanation is
// attached to a result only through the sign measured on it (report_writer's pinned causes).
#pragma once

#include <optional>
#include <string>

#include "comparisons/eval/harness.h"
#include "reference/backend.h"

namespace rbx {

/// The signs, in the order they are tested; each is the `kind` of a contact Cause.
namespace contact_sign {
inline constexpr const char* kTouchingWhenDeep =
    "touching with no normal on a penetrating pair (a miss)";
inline constexpr const char* kTouchingAtZeroDepth =
    "touching with no normal at zero depth (a convention, scored as touching)";
inline constexpr const char* kMissed = "misses a contact";
inline constexpr const char* kFalseContact = "reports a contact where there is none";
inline constexpr const char* kMixedNormals =
    "some points carry another face's normal (others the true one)";
inline constexpr const char* kCentreLine = "normal along the line between the centres";
inline constexpr const char* kWrongNormal = "wrong normal";
inline constexpr const char* kNegatedDepth = "depth of the wrong sign, normal right";
inline constexpr const char* kHalfDepth = "half the depth, normal right";
inline constexpr const char* kTooDeep = "too deep, normal right";
inline constexpr const char* kTooShallow = "too shallow, normal right";
}  // namespace contact_sign

/// The truth a contact answer is measured against, and the pair's geometry the signs need.
struct ContactTruth {
  bool touching = false;
  Vec3 normal = Vec3::UnitZ();   // from B toward A, as ContactPoint's
  double depth = 0.0;            // >= 0
  double size = 1.0;             // the smaller body's size: the scale of the marks
  Vec3 centres = Vec3::UnitZ();  // unit, from B's centre of mass toward A's (zero if they meet)
};

/// The first measured sign on backend `backend`'s answer `r` to a pair whose truth is `t`, with
/// `deepest_angle` its deepest point's normal error (deg) as the harness scores it (ties already
/// resolved).
/// A Touching answer gets kTouchingAtZeroDepth or kTouchingWhenDeep (over the mark, 1 % of the
/// size); any other answer gets a sign only when it is marked ✗ (kMarkAngleDeg, kMarkDepthRel),
/// else nothing. `scene` names the scene in the cause.
std::optional<Cause> contact_cause(const std::string& backend, const std::string& scene,
                                   const ContactResult& r, const ContactTruth& t,
                                   double deepest_angle);

}  // namespace rbx
