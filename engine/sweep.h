// Time of impact of two convex shapes under a stated motion, the query every continuous-collision
// library answers (FCL's continuousCollide, Bullet's convex casts): the first time within an
// interval at which two shapes, apart at its start, touch.
//
// Departure from the seed, whose step finds a time of impact on its own detector with the bodies'
// torque-free motion (engine/time_of_impact.h). Here the motion is the one the libraries take
// between two poses: the centre at a constant velocity, the orientation at a constant angular
// velocity about the centre (the exponential map), so that the answers can be compared. The search
// is conservative advancement (Mirtich 1996) on the engine's GJK distance: docs/time_of_impact.md.
#pragma once

#include "engine/polyhedron.h"

namespace rbx {

/// A body's motion over an interval: from `start`, its origin (the centre of mass) at
/// `velocity`, its orientation turning at `angular_velocity` (world frame) about the origin.
struct Sweep {
  Pose start;
  Vec3 velocity = Vec3::Zero();          // m/s, world
  Vec3 angular_velocity = Vec3::Zero();  // rad/s, world
};

/// The pose of a body moving by `s`, time t (s) after the start.
Pose swept_pose(const Sweep& s, double t);

/// The first touch of two swept shapes.
struct SweepImpact {
  bool hit = false;             // they touch within the interval
  double time = 0.0;            // s: the first touch (0: touching or overlapping at the start)
  Vec3 point = Vec3::Zero();    // world: midway between the closest points at `time`
  Vec3 normal = Vec3::UnitZ();  // unit, world, from B toward A at `time`
  bool located = false;         // point and normal given (false: overlapping at the start)
  bool certified = true;        // false: the search stopped at its step limit, no touch found yet
};

/// Distance (m), as a fraction of the pair's size (the sum of their radii about their origins),
/// at which a sweep counts the shapes as touching.
constexpr double kSweepTouchRel = 1e-11;

/// The first time in [0, dt] at which shape A moving by `sa` and shape B moving by `sb` come
/// within kSweepTouchRel of their size: each step advances by the gap along a separating plane
/// over a bound on how fast it can close, so no touch is stepped over. The plane is the closest
/// points' own, or where round-off has tilted it at a tiny gap, one the touching features name (a
/// face, or the two nearest edges' cross product); the distance over the fastest any point moves
/// is always safe too. The longest safe step is taken. At most
/// `max_steps` steps (a grazing pass converges slowly); past it the answer is not certified.
SweepImpact sweep_time_of_impact(const ConvexPolyhedron& a, const Sweep& sa,
                                 const ConvexPolyhedron& b, const Sweep& sb, double dt,
                                 long max_steps = 100000);

}  // namespace rbx
