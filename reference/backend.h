// The one small interface every backend implements, and the registry that names them.
//
// Every adapter receives the engine's own bodies (same hull vertices in the body frame, same
// mass, centre of mass at the body origin, same inertia tensor) and converts results to the
// contract's convention (engine/contact.h): normal from B toward A, depth >= 0, world frame, SI.
// Conventions are converted here and nowhere else; a library's wrong answers are passed on.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "engine/body.h"
#include "engine/contact.h"
#include "engine/world.h"
#include "engine/world_definition.h"
#include "reference/contact_laws.h"

namespace rbx {

/// Outcome of a backend call. Timeout: a library call past its deadline, abandoned
/// (reference/isolate.h); reported apart from Error so a slow library is not called wrong.
/// Touching: a contact query that finds the pair touching at zero depth and, by the library's
/// convention, gives no normal there (libccd, FCL's signed distance): an answer, not an error.
enum class Status { Ok, Error, Unsupported, Timeout, Touching };

/// "ok" | "error" | "unsupported" | "timeout" | "touching".
const char* to_string(Status s);

/// Contact query result at given poses. Empty `contacts` with status Ok means "not touching".
struct ContactResult {
  Status status = Status::Ok;
  std::string message;  // why, when not ok; or a note on a known library defect
  std::vector<ContactPoint> contacts;
};

/// Depth (m) up to which a contact without a normal is "touching": libccd's MPR zeroes its
/// direction below its epsilon of depth, FCL's signed distance has coincident nearest points at
/// zero distance; a nanometre is far above both and far below any depth a scene states.
constexpr double kTouchingDepth = 1e-9;

/// Tangential slip (m/s) below which a contact has no slip direction to follow (its components
/// are round-off): the adapters that point a friction pyramid's first direction along the slip
/// (ODE, DART) leave the library's own basis there, which at stick holds the body as any would.
constexpr double kStickSpeed = 1e-9;

/// A library answer of "touching" whose normal is zero or not finite defines no contact
/// normal. Returns `r` unchanged when every normal is a unit vector; status Touching when such
/// a contact has (nearly) zero depth, the libraries' convention at exact touching (the harness
/// scores it against the true depth: a miss where the pair penetrates); else status Error saying
/// which query, at what depth. This labels a library's answer; it corrects nothing.
inline ContactResult reject_undefined_normals(ContactResult r, const std::string& query) {
  for (const ContactPoint& c : r.contacts) {
    const double n = c.normal.norm();
    if (std::isfinite(n) && n > 0.5) continue;
    if (std::abs(c.depth) <= kTouchingDepth)
      return {Status::Touching,
              query + " reports the pair touching (depth " + std::to_string(c.depth) +
                  ") with no normal",
              {}};
    return {Status::Error,
            query + " reported a contact (depth " + std::to_string(c.depth) +
                ") with a zero or undefined normal",
            {}};
  }
  return r;
}

/// True when a library's native box primitive describes the body exactly: a box body (full
/// extents `box_size`, axes the body axes) whose centre is its centre of mass (true for both mass
/// models, up to round-off; checked so a shifted box falls back to its hull) and whose inertia
/// is diagonal in its body axes (so a library storing principal moments needs no rotation).
/// The one place every adapter decides "native box or hull".
inline bool is_native_box(const RigidBody& body) {
  if (body.shape_kind != ShapeKind::Box) return false;
  // Round-off of the centre of mass and of the inertia integrals: 1e-12 of the size / trace.
  const double size = body.box_size.norm();
  const Mat3& inertia = body.inertia_body;
  const double off_diagonal =
      std::abs(inertia(0, 1)) + std::abs(inertia(0, 2)) + std::abs(inertia(1, 2));
  return body.shape->bounds().center().norm() <= 1e-12 * size &&
         off_diagonal <= 1e-12 * std::abs(inertia.trace());
}

/// A distance query's answer at given poses (docs/distance.md): how far apart A and B are and a
/// closest point on each, world frame, SI. `overlapping`: the library says the pair overlaps or
/// touches, and gives no separation (the contact query answers there); `distance` and the points
/// are then unspecified.
struct DistanceResult {
  Status status = Status::Ok;
  std::string message;  // why, when not ok; or what the library's answer is (a margin contact)
  bool overlapping = false;
  double distance = 0.0;        // m
  Vec3 point_a = Vec3::Zero();  // m, world: A's point nearest B
  Vec3 point_b = Vec3::Zero();  // m, world: B's point nearest A
};

/// A time-of-impact query's answer (docs/time_of_impact.md): the first time within an interval
/// at which A and B, separated or touching at its start, touch. Each body moves by the stated
/// motion: its centre of mass at its constant velocity, its orientation at its constant angular
/// velocity (world frame) about the centre of mass, over [0, dt]. `fraction` is the time as a
/// fraction of dt; `point` and `normal` are where and how they touch then, when `located`.
struct ToiResult {
  Status status = Status::Ok;
  std::string message;          // why, when not ok; or how the library's answer was read
  bool hit = false;             // the pair touches within the interval
  double fraction = 1.0;        // first touch, in [0, 1] of the interval (1 when no hit)
  bool located = false;         // `point` and `normal` are given
  Vec3 point = Vec3::Zero();    // m, world: the contact at the touch
  Vec3 normal = Vec3::UnitZ();  // unit, world, from B toward A at the touch
};

/// Turn (rad) over the interval from which a body's two end poses no longer name its motion: the
/// libraries that take a start and an end pose (FCL's InterpMotion, Bullet's
/// btTransformUtil::calculateVelocity) turn the short way between them, by less than half a turn.
constexpr double kMaxToiTurn = 3.0;

/// The body at the end of a time-of-impact interval of `dt` (s) under the stated motion
/// (ToiResult); nothing when it turns by kMaxToiTurn or more, where its end poses name another
/// motion. The adapters that take end poses get them here.
inline std::optional<RigidBody> body_at_end(const RigidBody& body, double dt) {
  const Vec3 turn = body.angular_velocity * dt;
  const double angle = turn.norm();
  if (!(angle < kMaxToiTurn)) return std::nullopt;
  RigidBody end = body;
  end.position = body.position + body.velocity * dt;
  if (angle > 0)
    end.orientation =
        (Quat(Eigen::AngleAxisd(angle, turn / angle)) * body.orientation).normalized();
  return end;
}

/// Final state of one body after a dynamics run.
struct BodyFinal {
  std::string name;
  Vec3 position = Vec3::Zero();  // m, centre of mass, world
  Quat orientation = Quat::Identity();
  Vec3 velocity = Vec3::Zero();          // m/s
  Vec3 angular_velocity = Vec3::Zero();  // rad/s, world frame
};

/// Optional per-step sample of all bodies (for trajectory and stability checks).
struct StateSample {
  double time = 0.0;
  std::vector<BodyFinal> bodies;
};

/// What a dynamics run's first contact impulse saw, so that a backend's error can be explained
/// from measurement (one point or a manifold, the normal, how deep the contact was first seen).
/// Filled by each adapter at the first step that applied an impulse.
struct FirstImpulse {
  bool seen = false;            // false: no impulse in the run
  std::string body_a, body_b;   // the pair, in scene order
  long step = -1;               // the step whose start-of-step poses detected it
  int contact_points = 0;       // points the library solved for the pair in that step
  Vec3 normal = Vec3::Zero();   // unit, from B toward A (mean over the points)
  Vec3 point = Vec3::Zero();    // m, world: mean of the points
  double depth = 0.0;           // m, deepest point at detection
  double impulse = 0.0;         // N s, normal impulse the step's events of the pair report
  double approach_speed = 0.0;  // m/s, closing normal speed before the step (>= 0)
  double entry_phase = -1.0;    // depth / (approach_speed * dt); -1: not closing
};

/// Result of a dynamics run over a whole scene.
struct DynamicsResult {
  Status status = Status::Ok;
  std::string message;
  std::vector<CollisionEvent> events;  // as resolved by the backend (may be empty if unknown)
  std::vector<BodyFinal> finals;       // same order as scene.bodies
  std::vector<StateSample> samples;    // filled when `sample_every` > 0
  FirstImpulse first_impulse;          // what the first impulse saw
  ContactLaws laws;                    // contact-law residuals (measured: false when unknown)
};

/// The first impulse of a run from the events one step added (`step_events`: those of the
/// first event's pair count) and every body's state before that step (`before`, matched by
/// name). `points` >= 0 overrides the point count where a library's events aggregate points.
inline FirstImpulse first_impulse_of(const std::vector<CollisionEvent>& step_events,
                                     const std::vector<BodyFinal>& before, double dt,
                                     int points = -1) {
  FirstImpulse f;
  if (step_events.empty()) return f;
  const CollisionEvent& first = step_events.front();
  f.seen = true;
  f.body_a = first.body_a;
  f.body_b = first.body_b;
  f.step = first.step;
  Vec3 normal = Vec3::Zero(), point = Vec3::Zero();
  int count = 0;
  for (const CollisionEvent& ev : step_events) {
    if (ev.body_a != f.body_a || ev.body_b != f.body_b) continue;
    normal += ev.contact.normal;
    point += ev.contact.point;
    f.impulse += ev.impulse;
    f.depth = std::max(f.depth, ev.contact.depth);
    ++count;
  }
  f.contact_points = points >= 0 ? points : count;
  if (normal.norm() > 0) f.normal = normal.normalized();
  point /= count;
  f.point = point;
  // Relative velocity of the two material points at the contact point, before the step.
  auto point_velocity = [&](const std::string& name) {
    for (const BodyFinal& b : before)
      if (b.name == name) return Vec3(b.velocity + b.angular_velocity.cross(point - b.position));
    return Vec3(Vec3::Zero());
  };
  const double closing = -(point_velocity(f.body_a) - point_velocity(f.body_b)).dot(f.normal);
  f.approach_speed = std::max(0.0, closing);
  if (f.approach_speed * dt > 0) f.entry_phase = f.depth / (f.approach_speed * dt);
  return f;
}

/// Options for a dynamics run.
struct DynamicsOptions {
  double dt = 0.0;        // s; 0: the scene's sim.dt
  long sample_every = 0;  // record the state every this many steps (0: never)
  int budget = 0;         // the solver's iteration budget (Backend::budget); 0: as configured
};

/// A dynamics backend's solver iteration budget, studied by the harness at the scene's step (the
/// other axis of error against run time, beside the step). Empty `values`: no budget to turn.
struct SolverBudget {
  std::string what;         // what is counted, in the library's own terms
  std::vector<int> values;  // studied, ascending, the library's default among them
  int library_default = 0;  // the library's own default (0: it solves to convergence)
  int configured = 0;       // what the backend runs with (0: not an iteration count)
};

/// Mass properties as a library computes them by itself from the body's hull (with its own
/// default settings), in the body frame. Reported next to the exact values; every backend is
/// still given the exact ones for its runs.
struct MassResult {
  Status status = Status::Ok;
  std::string message;                 // e.g. the settings it was computed with
  double mass = 0.0;                   // kg
  double volume = -1.0;                // m^3, negative when the library does not say
  Vec3 center_of_mass = Vec3::Zero();  // m, body frame
  Mat3 inertia = Mat3::Zero();         // kg m^2, about its centre of mass, body axes
};

/// Contact query: bodies carry their poses. A and B in that order.
using ContactFn = std::function<ContactResult(const RigidBody& a, const RigidBody& b)>;
/// Dynamics run of a whole scene.
using DynamicsFn =
    std::function<DynamicsResult(const WorldDefinition& scene, const DynamicsOptions& opt)>;
/// Distance query: bodies carry their poses. A and B in that order.
using DistanceFn = std::function<DistanceResult(const RigidBody& a, const RigidBody& b)>;
/// Time-of-impact query: bodies carry their poses at the interval's start and their velocities;
/// `dt` (s) is the interval. A and B in that order.
using ToiFn = std::function<ToiResult(const RigidBody& a, const RigidBody& b, double dt)>;
/// The library's own mass properties of a body's hull for the body's mass.
using MassFn = std::function<MassResult(const RigidBody& body)>;

/// One row of the registry.
/// One contact-softness parameter a library's experts tune (MuJoCo's contact time constant,
/// ODE's and DART's error reduction and constraint force mixing): its name (as in params.json),
/// what it is, the backend's own value, its valid range and the values a fit tries.
struct SoftParameter {
  std::string name;
  std::string meaning;  // one line
  double value = 0.0;   // the backend as configured
  double lo = 0.0, hi = 0.0;
  std::vector<double> grid;
};

/// A backend's contact softness: its parameters and its dynamics with them set (`values` in the
/// order of `parameters`). Empty `parameters`: none to tune.
struct SoftContact {
  std::vector<SoftParameter> parameters;
  std::function<DynamicsResult(const WorldDefinition& scene, const DynamicsOptions& opt,
                               const std::vector<double>& values)>
      dynamics;
};

/// How a backend is drawn in every figure and page (comparisons/output/backend_style.h): a
/// library keeps one hue, its other rows darker or lighter shades of it, each with a marker of its
/// own, so that two neighbours in a legend never share both and greyscale still tells them apart.
/// The hues start from Okabe & Ito's colour-blind-safe set.
struct BackendStyle {
  std::string colour;  // "#RRGGBB"; empty: a grey the figures choose
  std::string marker;  // a matplotlib marker ("o", "s", "^", "D", "*", ...)
};

/// Where `rbx bench` times a contact query: the largest hull (vertices) in a full and in a quick
/// run (comparisons/eval/bench_cases.h); 0: not timed.
struct BenchSizes {
  int full = 0;
  int quick = 0;
};

struct Backend {
  std::string name;               // as in JSON and reports
  std::string description;        // one line: library, algorithm
  ContactFn contact;              // empty: no contact queries
  DynamicsFn dynamics;            // empty: no dynamics
  MassFn mass = nullptr;          // empty: the library computes no mass properties of a hull
  bool library = true;            // an outside library's code: isolated with a deadline per call
  bool friction = true;           // its dynamics apply Coulomb friction (false: mu is ignored)
  bool user = false;              // registered at run time (register_backend): never cached
  SolverBudget budget = {};       // the solver's iteration budget, when it has one
  SoftContact soft = {};          // its contact softness, when it has some to tune
  BackendStyle style = {};        // its colour and marker
  BenchSizes bench = {};          // the hulls `rbx bench` times its contact query on
  DistanceFn distance = nullptr;  // empty: no distance query (`unsupported`)
  ToiFn toi = nullptr;            // empty: no time-of-impact query (`unsupported`)

  /// This row drawn in `colour` with `marker`.
  Backend drawn(std::string colour, std::string marker) const {
    Backend b = *this;
    b.style = {std::move(colour), std::move(marker)};
    return b;
  }
  /// This row with the library's distance query.
  Backend measuring(DistanceFn fn) const {
    Backend b = *this;
    b.distance = std::move(fn);
    return b;
  }
  /// This row with the library's time-of-impact query.
  Backend sweeping(ToiFn fn) const {
    Backend b = *this;
    b.toi = std::move(fn);
    return b;
  }
  /// This row's contact query timed by `rbx bench` on hulls up to `full` (`quick`) vertices.
  Backend timed(int full, int quick) const {
    Backend b = *this;
    b.bench = {full, quick};
    return b;
  }
};

/// `b` with its contact softness.
inline Backend with_soft(Backend b, SoftContact soft) {
  b.soft = std::move(soft);
  return b;
}

/// `b` with its solver budget (adapters' tables name the other fields in order).
inline Backend with_budget(Backend b, SolverBudget budget) {
  b.budget = std::move(budget);
  return b;
}

/// Every backend, in report order; those added by register_backend last.
const std::vector<Backend>& backends();
/// Adds a backend to the registry for the rest of the process (a researcher's own, from Python):
/// it is marked `user` (its results are never cached: its code is not hashed). A name
/// registered before is replaced in its place (a notebook's edit and rerun). Throws
/// std::invalid_argument on an empty name, a built-in backend's name, a name with a comma or a
/// space, or a backend with neither a contact query nor dynamics. Call it before any run
/// starts: pointers to registry rows (find_backend) may move.
void register_backend(Backend b);
/// Removes a backend register_backend added. Throws std::invalid_argument on a built-in
/// backend's name or a name no backend has. Pointers to registry rows may move, as there.
void unregister_backend(const std::string& name);
/// The backend called `name`, or nullptr.
const Backend* find_backend(const std::string& name);
/// The backend called `name` in `table` (null: the registry), or nullptr.
const Backend* find_backend(const std::string& name, const std::vector<Backend>* table);

/// A contact query that is the same library path as a registry backend with a different set-up,
/// kept for timing (`rbx bench`) rather than reported as a backend of its own.
struct QueryVariant {
  std::string backend;      // the registry backend it varies, e.g. "fcl"
  std::string variant;      // e.g. "prebuilt"
  std::string description;  // one line: what differs
  ContactFn contact;
  BenchSizes bench = {};          // the hulls `rbx bench` times it on (0: not timed)
  bool boxes_only = false;        // timed on the box pair only (a path a library takes for boxes)
  DistanceFn distance = nullptr;  // the same set-up's distance query (empty: none)
  ToiFn toi = nullptr;            // a time-of-impact call of its own (empty: none)
};

/// One library adapter as a table: the backends it provides and their query variants, each row
/// with its name (as in the CLI and JSON), description and entry points. The registry is the
/// adapters' rows in order; tests reach an entry point by the backend's own name.
struct Adapter {
  std::vector<Backend> backends;
  std::vector<QueryVariant> variants;

  /// The backend called `name`; throws std::invalid_argument when this adapter has none.
  const Backend& backend(const std::string& name) const {
    for (const Backend& b : backends)
      if (b.name == name) return b;
    throw std::invalid_argument("no backend '" + name + "' in this adapter");
  }
  /// The variant `variant` of backend `name`; throws std::invalid_argument when there is none.
  const QueryVariant& variant(const std::string& name, const std::string& variant) const {
    for (const QueryVariant& v : variants)
      if (v.backend == name && v.variant == variant) return v;
    throw std::invalid_argument("no variant '" + variant + "' of '" + name + "' in this adapter");
  }
};

/// A library's contact query and dynamics run at explicit settings of type `Settings`, so that a
/// test can measure each setting against its alternatives (tests/reference/fair_settings_test.cpp).
/// An empty member: the library has no such entry.
template <class Settings>
struct AtSettings {
  std::function<ContactResult(const RigidBody& a, const RigidBody& b, const Settings& settings)>
      contact;
  std::function<DynamicsResult(const WorldDefinition& scene, const DynamicsOptions& opt,
                               const Settings& settings)>
      dynamics;
  /// Empty where the library has no distance query.
  std::function<DistanceResult(const RigidBody& a, const RigidBody& b, const Settings& settings)>
      distance = nullptr;
  /// Empty where the library has no time-of-impact query.
  std::function<ToiResult(const RigidBody& a, const RigidBody& b, double dt,
                          const Settings& settings)>
      toi = nullptr;
};

/// Every query variant, one line each (reference/registry.cpp).
const std::vector<QueryVariant>& query_variants();
/// The variant `variant` of `backend`, or nullptr.
const QueryVariant* find_query_variant(const std::string& backend, const std::string& variant);

/// Builds the engine bodies of a scene (shared by adapters so all use the same inputs).
std::vector<RigidBody> make_bodies(const WorldDefinition& scene);

}  // namespace rbx
