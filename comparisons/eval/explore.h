// `rbx explore`: random contact pairs checked against the exact oracle, disagreements grouped by
// signature and each group shrunk to a simple scene.
//
// Sample k of seed s is a pure function of (s, k): its generator is seeded from a hash of the
// two (a counter-based stream, as in Salmon et al. 2011), so any sample can be regenerated
// alone, on any rank or thread. A sample is written as scene text (TOML, every number with 17
// significant digits) and is built from that text exactly as `rbx compare` builds it, so what
// explore measured is what the harness measures on the written scene.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "comparisons/eval/json_io.h"
#include "comparisons/eval/result_cache.h"
#include "comparisons/scene/scene.h"
#include "engine/math.h"
#include "reference/backend.h"

namespace rbx {

/// Counter-based random numbers: splitmix64 seeded from a hash of (seed, index).
class SampleRng {
 public:
  SampleRng(uint64_t seed, uint64_t index);
  /// 64 uniform random bits.
  uint64_t next();
  /// Uniform in [0, 1).
  double uniform();
  /// Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Uniform integer in [lo, hi].
  int integer(int lo, int hi);
  /// A point with each coordinate uniform in [lo, hi), drawn z first, then y, then x (the order
  /// GCC gave the samples drawn before this existed; C++ leaves the order of a call's arguments
  /// unspecified, so `Vec3(uniform(), uniform(), uniform())` differs between compilers).
  Vec3 uniform3(double lo, double hi);
  /// Uniform direction on the unit sphere.
  Vec3 direction();
  /// Uniform random rotation (Shoemake's method).
  Quat rotation();

 private:
  uint64_t state_;
};

/// A body of a sample, as it is written to a scene.
struct ExploreBody {
  std::string shape_class;       // "box" | "hull" | "sliver"
  Vec3 box_size = Vec3::Ones();  // m, full extents (box)
  std::vector<Vec3> points;      // m, local points whose convex hull is the shape (hull, sliver)
  Vec3 position = Vec3::Zero();  // m, world position of the local origin
  Quat orientation = Quat::Identity();
  Vec3 rotation_deg = Vec3::Zero();  // used instead of `orientation` when `use_degrees`
  bool use_degrees = false;
};

/// One random contact pair: body A, body B, and how the pose was chosen.
struct ContactSample {
  uint64_t seed = 0;
  uint64_t index = 0;
  std::string pose_class;  // touching | separated | deep | diagonal | parallel | edge_edge | random
  ExploreBody a, b;
};

/// Sample `index` of `seed`: shapes and a pose biased toward hard cases.
ContactSample make_contact_sample(uint64_t seed, uint64_t index);

/// The sample as a scene file (checks = ["contact"], duration 0); `expect` is inserted verbatim
/// (an [expect] block or ""), `header` as leading comment lines.
std::string sample_scene_text(const ContactSample& s, const std::string& header = "",
                              const std::string& expect = "");

/// What went wrong for one backend on one sample ("" : agrees with the truth).
/// error | misses | false_contact | normal | depth | point (the other kinds name theirs)
struct BackendOutcome {
  std::string backend;
  std::string error;            // "" when it agrees, else the kind above
  bool measured = false;        // both touch: the three errors below are set
  double normal_err_deg = 0.0;  // against exact, ties counted as right (as the harness does)
  double depth_err_rel = 0.0;   // |depth - exact depth| / smaller body size
  double point_err_rel = 0.0;   // the worst point's distance from the true region / size
  std::string message;          // the backend's message when status is error
  // Impact and landing kinds (measured = the run finished):
  double velocity_err_ke = 0.0;  // final velocities against the closed form, KE norm (harness)
  double momentum_err_ke = 0.0;  // final momenta (p, L about the COM) against it, same norm
  // Landing kind:
  double position_err_m = 0.0;   // horizontal distance of the final centre from the closed form
  double turn_rad = 0.0;         // rotation angle of the final orientation from the initial one
  double rest_time_err_s = 0.0;  // |measured - closed-form time to rest| (the run's samples)
  // Landing and slide kinds: the deepest contact the library reported in the run (m).
  double reported_depth_m = 0.0;
  // Landing and slide kinds: the highest the box's centre rose off its surface, along the
  // normal, once on it (m; largest_rise).
  double rise_m = 0.0;
  // Contact kind (measured): how far the points fall short of the exact patch / size
  // (patch_cover.h); counted, not yet a disagreement (docs/explore.md).
  double coverage_err_rel = 0.0;
  // Distance kind (measured): the errors of rbx distance's verdict (distance_query.h), relative
  // to the true distance.
  double distance_err_rel = 0.0;
  double witness_err_rel = 0.0;
  // Toi kind (measured: both touch): |first touch - exact's|, of the interval; where that is
  // a disagreement (early, late), the pair's separation at the row's time (ToiVerdict).
  double time_err = 0.0;
  double separation_m = 0.0;
};

/// Everything measured on one sample.
struct SampleOutcome {
  uint64_t index = 0;
  std::string pose_class;
  std::string shapes;   // "box-hull": the classes of A and B
  std::string feature;  // exact's axis: face_a | face_b | edge_edge, or "separated"
  bool touching = false;
  double depth_rel = 0.0;                // exact depth / smaller body size (negative: separated)
  std::vector<BackendOutcome> backends;  // in the order asked for; unsupported ones left out
  double phase = -1.0;  // impact, landing: where in its step the first contact falls, [0, 1)
};

/// Runs the sample through `exact` and each named backend and classifies each answer.
/// Thresholds: the harness's marks of a clear disagreement (kMarkAngleDeg, kMarkDepthRel).
/// Backends are looked up in `table` (default: the registry).
SampleOutcome evaluate_contact_sample(const ContactSample& s, const std::vector<std::string>& names,
                                      const std::vector<Backend>* table = nullptr,
                                      const ResultCache* cache = nullptr);

/// The same on a scene's text (as `rbx compare` would read it); `shapes` names the classes of
/// A and B ("box-hull"), which the text does not record.
SampleOutcome evaluate_scene_text(const std::string& text, const std::vector<std::string>& names,
                                  const std::string& pose_class, const std::string& shapes);

/// Group key of a disagreement: "backend shapes feature error".
std::string signature(const SampleOutcome& s, const BackendOutcome& b);

/// Compact text form of an outcome (for the ranks' exchange) and back.
std::string encode(const SampleOutcome& s);
SampleOutcome decode(const std::string& text);

/// The simplest member found of a disagreement group.
struct ShrinkResult {
  ContactSample sample;     // shrunk
  SampleOutcome outcome;    // of the shrunk sample, for its backend
  int vertices_before = 0;  // total points of both bodies
  int vertices_after = 0;
  int steps_accepted = 0;  // simplifications kept
  int evaluations = 0;     // predicate calls
};

/// Shrinks sample `s` while `backend` keeps the same signature `sig`: fewer hull points, A at
/// the origin, rotations rounded toward axis-aligned (whole degrees, then coarser), rounder
/// positions, sizes and points. Every candidate is judged on its scene text. At most
/// `max_evaluations` predicate calls.
ShrinkResult shrink(const ContactSample& s, const std::string& backend, const std::string& sig,
                    int max_evaluations = 400);

/// Whether a candidate of shrink_with still shows the disagreement; its outcome into `out`
/// (when given) where it does.
using ShowsDisagreement = std::function<bool(const ContactSample&, SampleOutcome* out)>;

/// shrink's simplifications, each kept while `shows` says the candidate still shows the
/// disagreement: the distance and toi kinds judge a candidate by their own query.
ShrinkResult shrink_with(const ContactSample& s, const ShowsDisagreement& shows,
                         int max_evaluations);

/// True when the harness (evaluate_scene, as `rbx compare` runs it) shows on the scene text
/// the disagreement of `b`'s kind: status error, a touching mismatch, a normal off by more
/// than kMarkAngleDeg, a depth off by more than kMarkDepthRel of the smaller body, a point
/// off by more than the same fraction; impact kind: a velocity error above kMarkVelocityErr;
/// landing kind: a final centre or turn beyond the landing marks. `detail` says what it saw.
bool harness_reproduces(const std::string& scene_text, const std::string& path,
                        const BackendOutcome& b, std::string* detail = nullptr);

// ---------------------------------------------------------------------------------------------
// Impact kind: one body hits another (free or static) at one vertex on a face; the closed form
// is the single-point impulse with restitution e (seed corrections: world-frame inverse inertia,
// relative velocity at the point), computed here from the masses, the inertia tensors and the
// exact oracle's contact point and normal, not by the custom engine.

/// One random single-point impact, as it is written to a scene.
struct ImpactSample {
  uint64_t seed = 0;
  uint64_t index = 0;
  bool b_static = false;              // B static (a slab) or free
  ExploreBody a, b;                   // B is a box; positions are those at t = 0
  double mass_a = 1.0, mass_b = 1.0;  // kg
  Vec3 velocity_a = Vec3::Zero(), velocity_b = Vec3::Zero();  // m/s, no spin before the impact
  double restitution = 1.0;
  double dt = 1e-3;                   // s
  double contact_time = 0.0;          // s, first contact (exact, translation only before it)
  double phase = 0.0;                 // contact_time / dt - floor(contact_time / dt)
  double duration = 0.0;              // s
  int face = 0;                       // B's face hit: axis 0..2, + 3 for the negative side
  double face_u = 0.0, face_v = 0.0;  // the point hit on it, fractions of the face in (-0.5, 0.5)
  // The closed form (index 0: A, 1: B), at t = duration:
  Vec3 expect_velocity[2], expect_angular_velocity[2];  // m/s, rad/s (world)
  Vec3 expect_angular_momentum[2];                      // kg m^2/s about the COM (world)
  std::string text;        // the scene with its [expect] block (empty: no valid sample)
  std::string derivation;  // comment lines: point, normal, impulse
};

/// Sample `index` of `seed` (impact kind). Poses are drawn until one gives a single contact
/// point (a unique lowest vertex over the inside of a face) and no second contact afterwards;
/// throws std::runtime_error when none of the attempts does.
ImpactSample make_impact_sample(uint64_t seed, uint64_t index);

/// Builds the sample's scene and closed form from its design (shapes, orientations, masses,
/// velocities, e, dt, contact time): false when it has no single-point contact or a second one.
bool realize_impact(ImpactSample& s);

/// Runs the sample's scene through each named dynamics backend against its closed form (backends
/// looked up in `table`, default: the registry).
SampleOutcome evaluate_impact_sample(const ImpactSample& s, const std::vector<std::string>& names,
                                     const std::vector<Backend>* table = nullptr,
                                     const ResultCache* cache = nullptr);

/// Impact groups shrunk like the contact ones: fewer hull points, rotations toward whole
/// degrees, rounder speeds, masses and e, as long as `backend` keeps signature `sig`.
struct ImpactShrinkResult {
  ImpactSample sample;
  SampleOutcome outcome;
  int vertices_before = 0, vertices_after = 0, steps_accepted = 0, evaluations = 0;
};
ImpactShrinkResult shrink_impact(const ImpactSample& s, const std::string& backend,
                                 const std::string& sig, int max_evaluations = 120);

// ---------------------------------------------------------------------------------------------
// Landing kind: a box lands flat on a static floor with a horizontal velocity, e = 0, friction
// mu; the closed form is the landing impulse J = m vn, the friction impulse min(mu J, m |v_h|)
// against the slip, then a slide decelerating at mu g to rest, without turning (the box is drawn
// so that it cannot tip: mu sz < min(sx, sy)). The derivation is written in each scene.

/// A landing's disagreement marks, for every backend alike. Position: 1 mm, above a
/// time-stepped slide's own discretisation (a right Riemann sum of the falling speed falls short
/// by at most v dt / 2 = 0.75 mm at the largest slide speed drawn, 1.5 m/s, and dt = 1 ms) and
/// below what a wrong law does (a deceleration 1 % off moves the rest by 1 % of the slide,
/// centimetres on most samples). Turn: 1e-3 rad: a box that stays flat turns by round-off only,
/// one that tips or spins on its contact patch by far more.
constexpr double kLandingPositionMark = 1e-3;  // m
constexpr double kLandingTurnMark = 1e-3;      // rad

/// One random landing: its design (drawn) and the closed form (derived by realize_landing).
struct LandingSample {
  uint64_t seed = 0;
  uint64_t index = 0;
  // Design.
  Vec3 size = Vec3::Ones();  // m, full extents of the box
  double mass = 1.0;         // kg
  double yaw_deg = 0.0;      // the box's turn about the vertical (it still lands flat)
  double slide_speed = 1.0;  // m/s, horizontal speed |v_h| before the landing
  double heading_deg = 0.0;  // direction of v_h, degrees from +x toward +y
  double fall_speed = 1.0;   // m/s, downward speed vz at t = 0 (> 0)
  double friction = 0.5;     // Coulomb mu
  double dt = 1e-3;          // s
  int steps_before = 2;      // k: first touch in step k (counting from 0)
  double phase = 0.5;        // where in that step: t_c = (k + phase) dt
  // The closed form (realize_landing).
  double contact_time = 0.0;      // s, t_c
  double drop = 0.0;              // m, h0: height of the base above the floor at t = 0
  double normal_impulse = 0.0;    // N s, J = m vn
  double friction_impulse = 0.0;  // N s, min(mu J, m |v_h|)
  double speed_after = 0.0;       // m/s, |v_h'| just after the landing
  double rest_time = 0.0;         // s, t_c + |v_h'| / (mu g)
  double duration = 0.0;          // s, a whole number of steps past the rest
  bool slides = false;            // the base slides on after the landing (|v_h| > mu vn)
  Vec3 start_position = Vec3::Zero(), velocity = Vec3::Zero();  // t = 0, m and m/s
  Vec3 expect_position = Vec3::Zero();                          // m, centre at t = duration
  std::string text;  // the scene with its derivation and [expect] block (empty: invalid design)
};

/// Sample `index` of `seed` (landing kind): a pure function of the two.
LandingSample make_landing_sample(uint64_t seed, uint64_t index);

/// The closed form and the scene of a landing design: false when the design is not a flat
/// landing of the closed form (a box that could tip, a touch outside its step, no fall).
bool realize_landing(LandingSample& s);

/// Runs the sample's scene through each named dynamics backend against its closed form:
/// status error, then a turn above kLandingTurnMark, then a position above
/// kLandingPositionMark (late_landing where a landing resolved a step late explains it); a turn
/// or position named deep_contact (name_deep_contact), else lift_off where the box rose off the
/// floor by more than kSlideLiftMark after its first touch, else cone_excess (name_cone_excess).
SampleOutcome evaluate_landing_sample(const LandingSample& s, const std::vector<std::string>& names,
                                      const std::vector<Backend>* table = nullptr,
                                      const ResultCache* cache = nullptr);

/// Landing groups shrunk toward round designs (unit mass, no yaw, a slide along x, rounder mu,
/// sizes, speeds and phase) while `backend` keeps signature `sig`.
struct LandingShrinkResult {
  LandingSample sample;
  SampleOutcome outcome;
  int steps_accepted = 0, evaluations = 0;
};
LandingShrinkResult shrink_landing(const LandingSample& s, const std::string& backend,
                                   const std::string& sig, int max_evaluations = 120);

// ---------------------------------------------------------------------------------------------
// Slide kind: a box already resting on a floor or an incline (a static slab), in contact at
// t = 0, with a speed along the surface; friction mu, e = 0. On a floor it slides along its
// launch direction decelerating at mu g; on an incline it slides down or up the fall line
// decelerating at g (mu cos(theta) -/+ sin(theta)), or starts at rest and sticks (mu is drawn
// above tan(theta)); then static friction holds it. Closed form: the stop distance v^2 / (2 a)
// along the launch, the time to rest v / a, no turn (the box is drawn so that it cannot tip:
// mu sz < min(sx, sy)). The derivation is written in each scene.

/// A slide's time-to-rest mark: the rest is read as the first sampled time the speed along the
/// surface is below 1e-3 m/s, the box then staying put (measured_rest_time), which at the least
/// deceleration drawn (0.98 m/s^2) is up to 1 ms early, and sampling every step adds up to one
/// step (1 ms); 3 ms is
/// above both and below what a wrong law does (a deceleration 1 % off moves the rest by 1 % of
/// the slide's time, 5 to 1,500 ms here). Position and turn: the landing's marks.
constexpr double kSlideRestTimeMark = 3e-3;  // s

/// A slide's lift mark: a box whose centre rose more than this off its surface along the normal
/// left it (lift_off), which the closed form's box never does. A tenth of the position mark, as
/// the rest drift is: above any rise from round-off or a stiff contact's give (the boxes of
/// Bullet, ODE and DART rise at most 3.4e-6 m on seed 8086 x 1,000), below the few tenths of a
/// millimetre a short flight takes. A lower flight can still move a short slide's rest past its
/// mark; hop_accounts_for_rest names that one from the box's own normal momentum.
constexpr double kSlideLiftMark = 1e-4;  // m

/// One random slide: its design (drawn) and the closed form (derived by realize_slide).
struct SlideSample {
  uint64_t seed = 0;
  uint64_t index = 0;
  // Design.
  Vec3 size = Vec3::Ones();  // m, full extents of the box
  double mass = 1.0;         // kg
  double yaw_deg = 0.0;      // the box's turn about the surface normal
  double incline_deg = 0.0;  // theta: 0 is a floor
  double azimuth_deg = 0.0;  // heading of the incline's fall line, degrees from +x toward +y
  double heading_deg = 0.0;  // floor: the launch direction, degrees from +x toward +y
  int along_fall_line = 1;   // incline: +1 launched down the slope, -1 up it, 0 at rest
  double speed = 1.0;        // m/s, launch speed along the surface (0 on an incline at rest)
  double friction = 0.5;     // Coulomb mu
  double dt = 1e-3;          // s
  // The closed form (realize_slide).
  double deceleration = 0.0;    // m/s^2, a
  double stop_distance = 0.0;   // m, v^2 / (2 a)
  double rest_time = 0.0;       // s, v / a
  double duration = 0.0;        // s, a whole number of steps past the rest
  Vec3 normal = Vec3::UnitZ();  // the surface's, up
  Vec3 start_position = Vec3::Zero(), velocity = Vec3::Zero();  // t = 0
  Vec3 expect_position = Vec3::Zero();                          // m, centre at t = duration
  std::string text;  // the scene with its derivation and [expect] block (empty: invalid design)
};

/// "floor", "down", "up" or "sticks": the slide's case (its samples' feature).
std::string slide_case(const SlideSample& s);

/// Sample `index` of `seed` (slide kind): a pure function of the two.
SlideSample make_slide_sample(uint64_t seed, uint64_t index);

/// The closed form and the scene of a slide design: false when it is not a slide of the closed
/// form (a box that could tip, an incline it would not stick on, a speed out of range).
bool realize_slide(SlideSample& s);

/// The closed-form time to rest (s) of a slide scene as written: its first body launched along
/// the top of its second (a static slab), under the scene's gravity and friction.
double slide_rest_time(const Scene& scene);

/// Time (s) at which the first body stopped in a run's samples: the earliest sample whose speed
/// along `normal`'s plane is below 1e-3 m/s and from which it never moves more than 0.1 mm
/// along that plane; `end` when there is none.
double measured_rest_time(const std::vector<StateSample>& samples, const Vec3& normal, double end);

/// The highest the first body's centre rose above its resting height (`rest`, along `normal`) in
/// a run's samples, once it had come within a tenth of kSlideLiftMark of that height (m; 0 when
/// it never rose): from `start` for a box that starts on its surface, from its first touch for
/// one that lands. A box of the closed form never leaves its surface.
double largest_rise(const std::vector<StateSample>& samples, const Vec3& start, const Vec3& rest,
                    const Vec3& normal);

/// Whether a slide's time to rest (`rest`, measured) is off the closed form's (`closed_form`)
/// by what the box's normal momentum just before it stopped accounts for, to within
/// kSlideRestTimeMark, in a run whose box rose off its surface (`rise` above a tenth of
/// kSlideLiftMark, where largest_rise stops reading it as on the surface). Up to a time t the
/// normal impulse is m g_n t + m v_n(t), so with Coulomb's friction at mu N while it slides the
/// box's speed along the surface is v - a t - mu v_n(t): a box still coming down from a hop at
/// its last sliding sample stops later than v / a by mu |v_n| / a, one moving off its surface
/// earlier.
bool hop_accounts_for_rest(const std::vector<StateSample>& samples, const Vec3& normal, double rest,
                           double closed_form, double friction, double deceleration, double rise);

/// Runs the sample's scene through each named dynamics backend against its closed form:
/// status error, then a turn above kLandingTurnMark, then a position along the surface above
/// kLandingPositionMark, then a time to rest above kSlideRestTimeMark; any of these named
/// deep_contact (name_deep_contact), else lift_off where the box rose off its surface by more
/// than kSlideLiftMark on the way, or where hop_accounts_for_rest explains a rest_time miss.
SampleOutcome evaluate_slide_sample(const SlideSample& s, const std::vector<std::string>& names,
                                    const std::vector<Backend>* table = nullptr,
                                    const ResultCache* cache = nullptr);

/// Slide groups shrunk toward round designs (unit mass, no yaw, axis directions, rounder mu,
/// sizes, speed and angle) while `backend` keeps signature `sig`.
struct SlideShrinkResult {
  SlideSample sample;
  SampleOutcome outcome;
  int steps_accepted = 0, evaluations = 0;
};
SlideShrinkResult shrink_slide(const SlideSample& s, const std::string& backend,
                               const std::string& sig, int max_evaluations = 120);

// ---------------------------------------------------------------------------------------------
// Tunnel kind: a box projectile flies face-on at a thin static wall (any direction, no gravity,
// no friction, restitution e), so fast that in one step it may travel from 0.2 to 20 times the
// wall's thickness plus its own depth, first touch 2 to 5 steps ahead at a random phase. Closed
// form: the face-on impact through the centre reverses the normal velocity times e and keeps
// the tangential one (no spin); the box stays on the near side. A backend without continuous
// collision can let it through.

/// One random fast projectile: its design (drawn) and the closed form (realize_tunnel).
struct TunnelSample {
  uint64_t seed = 0;
  uint64_t index = 0;
  // Design.
  Vec3 size = Vec3::Constant(0.1);  // m, the projectile box's full extents (z along the normal)
  double mass = 1.0;                // kg
  double yaw_deg = 0.0;             // the box's turn about the wall's normal
  double wall_thickness = 0.05;     // m
  Vec3 normal = Vec3::UnitZ();      // the wall's near face's, toward the projectile
  double travel_ratio = 1.0;        // normal travel per step / (wall thickness + box depth)
  double tangential = 0.0;          // tangential speed / normal speed, along the wall's x axis
  double restitution = 0.5;
  double dt = 1e-3;
  int steps_before = 2;  // k: first touch in step k (counting from 0)
  double phase = 0.5;    // where in that step: t_c = (k + phase) dt
  // The closed form (realize_tunnel).
  double speed = 0.0;                                                  // m/s, normal approach speed
  double contact_time = 0.0;                                           // s
  double duration = 0.0;                                               // s
  Vec3 velocity = Vec3::Zero(), velocity_after = Vec3::Zero();         // m/s
  Vec3 start_position = Vec3::Zero(), expect_position = Vec3::Zero();  // m, t = 0 and the end
  std::string text;  // the scene with its derivation and [expect] block (empty: invalid design)
};

/// Sample `index` of `seed` (tunnel kind): a pure function of the two.
TunnelSample make_tunnel_sample(uint64_t seed, uint64_t index);

/// The closed form and the scene of a projectile design: false when it is not one (sizes,
/// speeds or phase out of range).
bool realize_tunnel(TunnelSample& s);

/// Runs the sample's scene through each named dynamics backend against its closed form: status
/// error, then a centre past the wall's near face at the end (tunnel), then a velocity error
/// above kMarkVelocityErr in the energy norm (velocity).
SampleOutcome evaluate_tunnel_sample(const TunnelSample& s, const std::vector<std::string>& names,
                                     const std::vector<Backend>* table = nullptr,
                                     const ResultCache* cache = nullptr);

/// Tunnel groups shrunk toward round designs while `backend` keeps signature `sig`.
struct TunnelShrinkResult {
  TunnelSample sample;
  SampleOutcome outcome;
  int steps_accepted = 0, evaluations = 0;
};
TunnelShrinkResult shrink_tunnel(const TunnelSample& s, const std::string& backend,
                                 const std::string& sig, int max_evaluations = 120);

// ---------------------------------------------------------------------------------------------
// Distance kind: the contact kind's shapes (boxes, hulls of 4 to 2,000 points, slivers; sizes
// up to 1e3 apart) in its poses (touching, parallel faces, around a corner, crossed edges, ...)
// moved apart along the exact closest pair's direction until the gap is g, drawn log-uniformly
// from 1e-9 to 10 times the smaller body's size. Moving B along that direction by t changes the
// distance by exactly t (the pair stays closest, and the plane between them still separates), so
// the gap is g to round-off; the truth is the oracle's distance on the written scene.

/// "hair" (g below 1e-4 of the smaller size), "near" (below 0.1) or "far": a sample's gap class.
std::string gap_class(double gap_rel);

/// Sample `index` of `seed` (distance kind): a pure function of the two; its pose_class is its
/// gap class.
ContactSample make_distance_sample(uint64_t seed, uint64_t index);

/// `s` with B moved apart from A to a gap drawn from (seed, index) as make_distance_sample does.
ContactSample moved_apart(ContactSample s, uint64_t seed, uint64_t index);

/// Runs the sample's scene (sample_scene_text) through the exact oracle and each named backend's
/// distance query (those without one left out) and classifies each answer by rbx distance's
/// verdict (judge_distance): status error, then overlap (says the pair overlaps), then distance
/// (off by more than kDistanceDisagreeRel), then witness (the points are not a closest pair).
/// A library's answer comes from `cache` when it holds one, and is kept there when not.
SampleOutcome evaluate_distance_sample(const ContactSample& s,
                                       const std::vector<std::string>& names,
                                       const std::vector<Backend>* table = nullptr,
                                       const ResultCache* cache = nullptr);

// ---------------------------------------------------------------------------------------------
// Toi kind: the distance kind's separated pairs (gaps 1e-9 to 10 sizes), hulls cut to their
// first kToiMaxPoints points (the oracle's closed form weighs every edge pair against every
// vertex: a 2,000-point pair costs minutes), set moving over an interval of 1 s, in one of five
// motions: head-on (along the closest pair's direction, the touch
// at a drawn fraction f of the interval, exact: the gap closes at the approach speed), oblique
// (head-on plus a sideways drift), spinning (plus a turn of up to 2 rad for each body), hair-miss
// (head-on, ending short of the touch by 1e-9 to 1e-4 of the smaller size) and graze (sideways
// only). The truth is the oracle's time (exact_toi) on the written scene.

constexpr size_t kToiMaxPoints = 64;

/// A toi sample: the pair and each body's velocity and angular velocity over `interval`.
struct ToiSample {
  ContactSample pair;  // pose_class: the motion
  Vec3 velocity_a = Vec3::Zero(), angular_velocity_a = Vec3::Zero();
  Vec3 velocity_b = Vec3::Zero(), angular_velocity_b = Vec3::Zero();
  double interval = 1.0;  // s
};

/// Sample `index` of `seed` (toi kind): a pure function of the two.
ToiSample make_toi_sample(uint64_t seed, uint64_t index);

/// The sample as a scene file: the pair's scene with the velocities and `dt` = the interval, so
/// that `rbx toi` on it asks the same question.
std::string toi_scene_text(const ToiSample& s, const std::string& header = "");

/// Runs the sample through the oracle (exact_toi) and each named backend's time-of-impact query
/// and its variants' (rows without one left out); classifies each answer by rbx toi's verdict
/// (judge_toi): status error, then misses (no touch where the oracle has one), then
/// false_contact (a touch where it has none), then time (over kToiDisagree of the interval).
/// A library's answer comes from `cache` when it holds one, and is kept there when not.
SampleOutcome evaluate_toi_sample(const ToiSample& s, const std::vector<std::string>& names,
                                  const ResultCache* cache = nullptr);

}  // namespace rbx
