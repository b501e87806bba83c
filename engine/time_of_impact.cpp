#include "engine/time_of_impact.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "engine/body_facts.h"
#include "engine/detect.h"
#include "engine/distance.h"
#include "engine/integrate.h"
#include "engine/separation.h"
#include "engine/touch_witness.h"

namespace rbx {

double shape_thickness(const ConvexPolyhedron& shape) {
  double thinnest = std::numeric_limits<double>::infinity();
  for (const Plane& p : shape.planes()) {
    double lo = std::numeric_limits<double>::infinity();
    for (const Vec3& v : shape.vertices()) lo = std::min(lo, p.normal.dot(v));
    thinnest = std::min(thinnest, p.offset - lo);
  }
  return thinnest;
}

RigidBody advanced(const RigidBody& body, double t, const PrincipalFrame* frame) {
  RigidBody moved = body;
  integrate_symplectic(moved, Vec3::Zero(), t, frame);
  return moved;
}

Pose advanced_pose(const RigidBody& body, double t, const PrincipalFrame* frame) {
  if (body.is_static) return body.pose();
  return advanced_pose(body, world_momentum(body), t, frame);
}

Pose advanced_pose(const RigidBody& body, const Vec3& momentum, double t,
                   const PrincipalFrame* frame) {
  if (body.is_static) return body.pose();
  // What advanced() computes of the pose, without copying the body: no gravity, so the centre
  // moves by v t, and the free rotation under the body's world angular momentum.
  return {body.position + body.velocity * t, free_rotation(body, momentum, t, frame)};
}

double sweep_length(const RigidBody& body, double radius, double t) {
  if (body.is_static) return 0.0;
  return (body.velocity.norm() + body.angular_velocity.norm() * radius) * t;
}

TravelRate travel_rate(const RigidBody& body, double turn_rate) {
  if (body.is_static) return {};
  // |L| = |I_body R^T w|: a rotation keeps the norm.
  const double momentum =
      (body.inertia_body * (body.orientation.conjugate() * body.angular_velocity)).norm();
  return {body.velocity.norm(), turn_rate * momentum};
}

double travel_bound(const RigidBody& body, double turn_rate, double radius, double t) {
  if (body.is_static) return 0.0;
  return travel_rate(body, turn_rate).over(radius, t);
}

namespace {

// What the turns add to a body's travel rate (m/s): travel_bound's rate less |v|.
double turn_speed(const RigidBody& body, const BodyFacts& facts) {
  return body.is_static
             ? 0.0
             : travel_bound(body, facts.turn_rate, facts.radius, 1.0) - body.velocity.norm();
}

// B's velocity seen from A (a static body does not move): B moving along a direction from B
// toward A closes the gap along it.
Vec3 b_seen_from_a(const RigidBody& a, const RigidBody& b) {
  return (b.is_static ? Vec3::Zero() : b.velocity) - (a.is_static ? Vec3::Zero() : a.velocity);
}

// How long a room (m) lasts at a closing speed (m/s).
double span(double room, double closing) {
  return closing > 0 ? room / closing : std::numeric_limits<double>::infinity();
}

}  // namespace

bool apart_through(const RigidBody& a, const RigidBody& b, const BodyFacts& facts_a,
                   const BodyFacts& facts_b, const GapAlong& start, const GapAlong& end,
                   double margin, double dt) {
  if (!(start.gap > margin) || !(end.gap > margin)) return false;
  const double turns = turn_speed(a, facts_a) + turn_speed(b, facts_b);
  const Vec3 v_rel = b_seen_from_a(a, b);
  const double forward = span(start.gap - margin, std::max(0.0, v_rel.dot(start.u)) + turns);
  const double backward = span(end.gap - margin, std::max(0.0, -v_rel.dot(end.u)) + turns);
  return forward + backward > dt;
}

namespace {

// What the distance at a time t proves (conservative advancement): how long after (forward) and
// before (backward) t the pair stays apart, and how long after t it stays beyond the detector's
// reach (`quiet`; 0 when it is not beyond it at t).
struct Room {
  double forward = 0.0, backward = 0.0, quiet = 0.0;
};

// One pair's search (time_of_impact): both bodies moved torque-free over the step, their samples
// (the detector, the distance) and the bisection between them.
class ImpactSearch {
 public:
  ImpactSearch(const RigidBody& a, const RigidBody& b, const BodyFacts& facts_a,
               const BodyFacts& facts_b, double dt, Detector detector, DetectionCache& cache,
               const Separation* at_end);
  // The pair's travel rate (m/s): no point of either body moves faster under advanced().
  double rate() const { return rate_; }
  // Samples on a grid of n intervals, certified between them from the distance.
  TimeOfImpact on_grid(long n, long max_samples);
  // Steps of at least `least` (s), longer while a separating axis shows room.
  TimeOfImpact beyond_grid(double least, long max_samples);

 private:
  static double rate_of(const RigidBody& body, const BodyFacts& facts) {
    return travel_bound(body, facts.turn_rate, facts.radius, 1.0);
  }
  Pose pose_a(double t) const { return advanced_pose(a_, momentum_a_, t, &facts_a_.principal); }
  Pose pose_b(double t) const { return advanced_pose(b_, momentum_b_, t, &facts_b_.principal); }
  // The detector's answer at t; where the last touch it found settles it, without it.
  bool touching(double t);
  // The time the pair takes to travel the detector's tolerance (s).
  double tolerance_time() const { return tol_ / rate_; }
  Room room(double t) const;
  TimeOfImpact first_touch(double before, double after, double quiet);

  const RigidBody &a_, &b_;
  const BodyFacts &facts_a_, &facts_b_;
  const double dt_;
  const Detector detector_;
  DetectionCache& cache_;
  // The world angular momenta, fixed along the torque-free motion: taken once for every sample.
  const Vec3 momentum_a_, momentum_b_;
  const double rate_;
  // Farther apart than this, the detector finds nothing (the margin ExtendedStep::separated
  // skips the detector by): a sample there needs no detection.
  const double reach_;
  const double tol_;                     // m, the detector's tolerance (point_in_mesh_tolerance)
  double spin_ = 0.0;                    // m/s: what the turns add to the travel rate
  Vec3 v_rel_ = Vec3::Zero();            // B's velocity seen from A (a static body does not move)
  std::optional<TouchWitness> witness_;  // of the last touch the detector found
  const Separation* at_end_;             // the distance at dt, when the caller took it
};

ImpactSearch::ImpactSearch(const RigidBody& a, const RigidBody& b, const BodyFacts& facts_a,
                           const BodyFacts& facts_b, double dt, Detector detector,
                           DetectionCache& cache, const Separation* at_end)
    : a_(a),
      b_(b),
      facts_a_(facts_a),
      facts_b_(facts_b),
      dt_(dt),
      detector_(detector),
      cache_(cache),
      momentum_a_(world_momentum(a)),
      momentum_b_(world_momentum(b)),
      rate_(rate_of(a, facts_a) + rate_of(b, facts_b)),
      reach_(separation_margin(std::max(facts_a.own_tol, facts_b.own_tol), facts_a.reach,
                               facts_b.reach)),
      tol_(point_in_mesh_tolerance(*a.shape, *b.shape)),
      at_end_(at_end) {
  spin_ = turn_speed(a, facts_a) + turn_speed(b, facts_b);
  v_rel_ = b_seen_from_a(a, b);
}

bool ImpactSearch::touching(double t) {
  const Pose pa = pose_a(t), pb = pose_b(t);
  if (witness_) {
    const std::optional<bool> settled = witness_->settle(pa, pb, reach_, tol_);
    if (settled) return *settled;
  }
  const std::optional<ContactPoint> hit = detect(*a_.shape, pa, *b_.shape, pb, detector_, cache_);
  if (hit) witness_ = TouchWitness::of(*a_.shape, pa, *b_.shape, pb, *hit);
  return hit.has_value();
}

Room ImpactSearch::room(double t) const {
  const Pose pa = pose_a(t), pb = pose_b(t);
  const Separation sep =
      t == dt_ && at_end_ ? *at_end_ : shape_distance(*a_.shape, pa, *b_.shape, pb);
  if (sep.overlapping || !(sep.distance > 0)) return Room{};
  const Vec3 n = (sep.point_b - sep.point_a) / sep.distance;
  const double approach = -v_rel_.dot(n);
  const double closing = std::max(0.0, approach) + spin_;
  Room r{span(sep.distance, closing), span(sep.distance, std::max(0.0, -approach) + spin_)};
  // The gap along n from the vertices, not the distance's own figure, proves it beyond reach
  // (the same proof ExtendedStep::separated takes).
  if (sep.distance > reach_) {
    const double gap = gap_along(*a_.shape, pa, *b_.shape, pb, -n);
    if (gap > reach_) r.quiet = span(gap - reach_, closing);
  }
  return r;
}

// Bisection on the detector between `before` (apart) and `after` (touching), until the pair
// travels no more than the detector's tolerance between them (1e-12 of the step at the least):
// the detector calls a pair touching within that tolerance, so a finer time only places its own
// rounding of the touch. Until `quiet` the pair is beyond the detector's reach: those midpoints
// are apart without asking it, and the answer is the same bisection's. So are most of the others
// (touching(): the touch's witness), all but the last few near the touch.
TimeOfImpact ImpactSearch::first_touch(double before, double after, double quiet) {
  const double resolution = std::max(1e-12 * dt_, tolerance_time());
  while (after - before > resolution) {
    const double mid = 0.5 * (before + after);
    (!(mid < quiet) && touching(mid) ? after : before) = mid;
  }
  return TimeOfImpact{after, true};
}

// Two samples apart do not prove the time between them apart: bodies skimming past each other
// can overlap briefly between them (a corner clipping another's). Certified from the distance
// (engine/distance.h): along the direction n from A's closest point to B's, the gap d between
// the shapes shrinks no faster than the approach along n, -(v_b - v_a) . n, plus what the turns
// can bring (the spin part of the travel rate), so nothing touches for d over that rate after a
// time the pair is apart, nor that long before (the rate of opening, backward). A touch between
// samples at t0 and t1 needs both spans to fit in between; where they do not, nothing touched.
// Else the interval is walked by those steps (conservative advancement), each at least the
// detector's tolerance of travel (an overlap shallower than that is touching to the detector
// anyway).
TimeOfImpact ImpactSearch::on_grid(long n, long max_samples) {
  const double least_step = tolerance_time();
  long walked = 0;
  double before = 0.0;
  Room at_before = room(0.0);
  for (long k = 1; k <= n; ++k) {
    const double t = dt_ * static_cast<double>(k) / static_cast<double>(n);
    // The distance first: beyond the detector's reach, no detection.
    const Room at_t = room(t);
    if (!(at_t.quiet > 0) && touching(t)) return first_touch(before, t, before + at_before.quiet);
    if (!(at_before.forward + at_t.backward > t - before)) {
      // The walk asks the distance at each step, and the detector only where the distance
      // finds the pair touching (the cheaper query first).
      double clear = before;
      Room at_clear = at_before;
      // It ends where the span the last distance proves meets the one t's proves backward.
      while (!(at_clear.forward + at_t.backward > t - clear)) {
        const double next = clear + std::max(at_clear.forward, least_step);
        if (next >= t) break;
        const Room at_next = room(next);
        if (!(at_next.forward > 0) && touching(next))
          return first_touch(clear, next, clear + at_clear.quiet);
        clear = next;
        at_clear = at_next;
        if (++walked >= max_samples) return {std::nullopt, false};
      }
    }
    before = t;
    at_before = at_t;
  }
  return {};
}

TimeOfImpact ImpactSearch::beyond_grid(double least, long max_samples) {
  // A fall from afar takes one step to the touch.
  double t = 0.0;
  for (long k = 0; k < max_samples; ++k) {
    const Pose pa = pose_a(t), pb = pose_b(t);
    const Vec3 axis = find_separating_axis(*a_.shape, pa, *b_.shape, pb, 0.0);
    const double gap = axis == Vec3::Zero() ? 0.0 : gap_along(*a_.shape, pa, *b_.shape, pb, axis);
    const double next = std::min(dt_, t + std::max(least, gap / rate_));
    if (touching(next)) return first_touch(t, next, t);
    if (next >= dt_) return {};
    t = next;
  }
  return {std::nullopt, false};
}

}  // namespace

TimeOfImpact time_of_impact(const RigidBody& a, const RigidBody& b, double dt, Detector detector,
                            long max_samples, const BodyFacts* facts_a, const BodyFacts* facts_b,
                            DetectionCache* cache, const Separation* at_end) {
  std::optional<BodyFacts> own_a, own_b;
  if (!facts_a) facts_a = &own_a.emplace(BodyFacts::of(a));
  if (!facts_b) facts_b = &own_b.emplace(BodyFacts::of(b));
  // One detection cache for every sample (its scratch lists allocated once), the caller's when
  // given.
  std::optional<DetectionCache> own_cache;
  if (!cache) cache = &own_cache.emplace();
  ImpactSearch search(a, b, *facts_a, *facts_b, dt, detector, *cache, at_end);
  if (!(search.rate() > 0.0)) return {};  // apart at the start and neither moves
  const double thin = std::min(facts_a->thickness, facts_b->thickness);
  const double grid = std::ceil(search.rate() * dt / (0.25 * thin));
  if (grid <= static_cast<double>(max_samples))
    return search.on_grid(std::max(1L, static_cast<long>(grid)), max_samples);
  // Too many samples for a grid: each step at least the grid's, longer while a separating axis
  // shows room.
  return search.beyond_grid(0.25 * thin / search.rate(), max_samples);
}

}  // namespace rbx
