// Running contact queries through the registry and comparing them.
#pragma once

#include <string>

#include "comparisons/eval/timing.h"
#include "comparisons/scene/scene.h"
#include "reference/backend.h"
#include "reference/isolate.h"

namespace rbx {

/// A contact query's result and its run time.
struct ContactRun {
  ContactResult result;
  Timing timing;        // cold_s: the answering call; the rest once timed (time_contacts)
  bool cached = false;  // read from the reference-result cache (the timing is the stored one)
};

/// Backend `b`'s answer on (A, B): one call, timed alone as the cold call (timing.cold_s); a
/// thrown exception becomes status Error with its message; a backend without contact queries
/// gives Unsupported. A library's call is isolated (reference/isolate.h).
ContactRun run_contact(const Backend& b, const RigidBody& a, const RigidBody& bb);

/// Whether a query's answer is worth timing: it answered (a contact, none, or touching).
bool timeable(const ContactRun& run);

/// Times, interleaved (timing.h), the queries on (A, B) of the backends whose runs are timeable
/// and not cached; each such run's timing is filled in, its cold call kept.
void time_contacts(const std::vector<const Backend*>& backends, std::vector<ContactRun*> runs,
                   const RigidBody& a, const RigidBody& b, const TimingPlan& plan);

/// Runs backend `b`'s dynamics on `scene` (a thrown exception becomes status Error); a library's
/// run is isolated under its deadline (reference/isolate.h), so an abort or an endless loop is
/// that run's `error` or `timeout`. The run time is the run's own, measured where it ran.
TimedDynamics run_dynamics_isolated(const Backend& b, const WorldDefinition& scene,
                                    const DynamicsOptions& opt);

/// Backend `b`'s dynamics as a function that runs it through run_dynamics_isolated.
DynamicsFn isolated_dynamics_fn(const Backend& b);

/// The deepest contact point of a result, or nullptr when there is none.
const ContactPoint* deepest(const ContactResult& r);

/// Angle between two directions, degrees in [0, 180].
double angle_deg(const Vec3& u, const Vec3& v);

/// The harness's rule for ties, as the scene checks, `rbx explore` and `rbx contacts` apply it:
/// true when A and B overlap along `normal` by `true_depth` within round-off (1e-12 of `size`,
/// the smaller body's). Where several directions give the same least overlap (a cube on
/// another's diagonal), any of them is as right as the truth's own normal.
bool ties_true_depth(const RigidBody& a, const RigidBody& b, const Vec3& normal, double true_depth,
                     double size);

/// Violations of [expect.contact] by one subject's (`who`'s) answer, appended to `failures` as
/// "who: what": touching, then (where it touches) the normal and the depth, each within `tol`.
void expect_contact_failures(const std::string& who, const ExpectContact& ex, bool touch,
                             const Vec3& normal, double depth, double tol,
                             std::vector<std::string>& failures);

/// Violations of [expect.contact]'s patch by one subject's points (world), across the unit
/// `normal`: a corner of the stated patch more than `tol` from the points' hull (they do not
/// span it), or a point more than `tol` from the patch (it lies off the contact).
void expect_patch_failures(const std::string& who, const std::vector<Vec3>& patch,
                           const std::vector<Vec3>& points, const Vec3& normal, double tol,
                           std::vector<std::string>& failures);

/// The unit direction from B's centre of mass toward A's (zero where they coincide): the ray
/// along which MPR searches.
Vec3 centres_direction(const RigidBody& a, const RigidBody& b);

}  // namespace rbx
