// Time of impact for the extended engine: the first contact time of two bodies that were
// separated at the start of a step, found on the Moore & Wilhelms detector itself. The seed
// names this as missing ("a time-of-impact method ... is obvious when the bounding box check
// passes", seed correction 12 (what the seed admits it lacks)); without it a body crossing
// another's thickness within one step passes through (stress/tunnel_thin_wall).
#pragma once

#include <optional>

#include "engine/body.h"
#include "engine/body_facts.h"
#include "engine/detect.h"
#include "engine/distance.h"
#include "engine/integrate.h"

namespace rbx {

/// Thickness of a convex shape (m): its smallest extent along any of its face normals (the
/// least width a segment crossing it can have, to the face directions).
double shape_thickness(const ConvexPolyhedron& shape);

/// The body moved torque-free with its current velocities over time t (s): centre by v t,
/// orientation by the symplectic integrator's free rotation (engine/integrate.h), no gravity.
/// `frame`, when given, is the body's principal frame kept by the caller (the same numbers).
RigidBody advanced(const RigidBody& body, double t, const PrincipalFrame* frame = nullptr);

/// advanced(body, t, frame).pose(), without copying the body.
Pose advanced_pose(const RigidBody& body, double t, const PrincipalFrame* frame = nullptr);

/// The same, with the body's world angular momentum (world_momentum) given: it stays fixed along
/// the motion, so a caller asking for many times takes it once.
Pose advanced_pose(const RigidBody& body, const Vec3& momentum, double t,
                   const PrincipalFrame* frame = nullptr);

/// Largest distance (m) a point of the body can travel over time t with its current velocity:
/// |v| t + |w| r t, r = `radius`, its bounding radius about the centre of mass (BodyFacts), a
/// bound, not exact.
double sweep_length(const RigidBody& body, double radius, double t);

/// Largest distance (m) any point of the body can move as advanced(body, t) moves it: |v| t,
/// plus the free rotation's turn (at most free_turn_rate(frame) |L| t, L the world angular
/// momentum) times `radius`, the body's bounding radius about its centre of mass (a chord is no
/// longer than its arc). `turn_rate`: free_turn_rate of the body's principal frame, kept by the
/// caller. Zero for a static body.
double travel_bound(const RigidBody& body, double turn_rate, double radius, double t);

/// What travel_bound multiplies out: a body's speed |v| (m/s) and its turn rate times |L|
/// (rad/s), so that `over(radius, t)` is travel_bound(body, turn_rate, radius, t) bit for bit, for
/// a caller asking with several radii. Both zero for a static body.
struct TravelRate {
  double speed = 0.0, turn = 0.0;
  double over(double radius, double t) const { return (speed + turn * radius) * t; }
};
TravelRate travel_rate(const RigidBody& body, double turn_rate);

/// A gap between A and B along a fixed unit direction `u` from B toward A (gap_along): the
/// least over A's points of u . x less the most over B's (m).
struct GapAlong {
  Vec3 u = Vec3::UnitZ();
  double gap = 0.0;
};

/// True when A and B, moved as time_of_impact moves them from their current poses, are proved
/// farther apart than `margin` all through [0, dt] by `start` (a gap at time 0) and `end` (a
/// gap at dt): along a fixed direction the gap shrinks no faster than the approach along it
/// plus what the turns add (travel_bound less |v|), so `start` lasts forward and `end`
/// backward, and together they cover the step. Then a detector whose reach is `margin` finds
/// nothing in the step: time_of_impact's own answer, without its samples.
bool apart_through(const RigidBody& a, const RigidBody& b, const BodyFacts& facts_a,
                   const BodyFacts& facts_b, const GapAlong& start, const GapAlong& end,
                   double margin, double dt);

/// The answer of a time-of-impact search.
struct TimeOfImpact {
  std::optional<double> time;  // s into the step: the first touch; none when none within dt
  bool certified = true;       // false: the search stopped at its sample limit before dt
};

/// First time in (0, dt] at which A and B, moving torque-free from their current poses with
/// their current velocities, touch by the detector; nothing when they do not within dt.
/// Samples in time, each checked by the detector, never farther apart than either of:
/// - a quarter of the thinner body's thickness of relative travel (travel_bound), so no pair of
///   samples can straddle a whole crossing;
/// - the gap along a separating axis found at the earlier sample, divided by the pair's travel
///   rate, so nothing can touch between them (conservative advancement).
/// A fixed grid of the first kind when it takes at most `max_samples` samples (the cost known in
/// advance; WorldSettings::toi_max_samples); past that, steps of the larger of the two. A grid
/// sample asks the distance first, and the detector only where the distance does not put the
/// pair beyond the detector's reach (separation_margin: the answer is the same). Then
/// bisection on the detector between the last separated and the first touching sample, until
/// the pair's travel between them is within the detector's tolerance (point_in_mesh_tolerance;
/// 1e-12 of dt at the least): the answer is a time the detector finds them touching, less than
/// the detector's tolerance of travel after one it does not. A search that reaches `max_samples`
/// before dt (bodies skimming past each other at a speed of millions of their thicknesses per step)
/// is not certified: its answer says so. Meant for pairs separated at the step's start. `facts_a`,
/// `facts_b`: the bodies' facts kept by the caller (the same numbers as BodyFacts::of, which is
/// called when they are not given); `cache`: a detection cache to reuse (the search makes its own
/// when none is given; the answer is the same); `at_end`: shape_distance of the pair moved to dt
/// (advanced()), when the caller has taken it (the search's own sample there, not taken again).
TimeOfImpact time_of_impact(const RigidBody& a, const RigidBody& b, double dt, Detector detector,
                            long max_samples, const BodyFacts* facts_a = nullptr,
                            const BodyFacts* facts_b = nullptr, DetectionCache* cache = nullptr,
                            const Separation* at_end = nullptr);

}  // namespace rbx
