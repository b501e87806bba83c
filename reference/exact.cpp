#include "reference/exact.h"

namespace rbx {
ContactResult exact_contact(const RigidBody&, const RigidBody&) { return {Status::Unsupported, "not built yet", {}}; }
}  // namespace rbx
namespace rbx { SatResult sat_query(const ConvexPolyhedron&, const Pose&, const ConvexPolyhedron&, const Pose&) { return {}; } }
