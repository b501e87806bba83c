// ODE 0.16.2 adapter. `ode`: a box body becomes a dCreateBox geom (two boxes meet in dBoxBox,
// ODE's own box-box test, up to 4 points); any other body, and every body under `ode-hull`, a
// dCreateConvex geom built from its body-frame hull (coplanar triangles merged into polygons).
// Geoms are attached to a dBody with our mass and inertia; static bodies are geoms without a
// body. Debian builds ODE with libccd
// (dLIBCCD_CONVEX_CONVEX: libode links libccd), so convex-convex pairs run dCollideConvexConvexCCD,
// libccd's MPR with one contact point, not ODE's own convex SAT: its depths and points match the
// `fcl` backend's (both MPR) bit for bit on the same pair.
//
// Errors: ODE's dError and dDebug print and then exit()/abort() unless a handler is installed,
// and a handler that returns gets the same fate. Ours copy the message and longjmp back to
// guarded(), which the caller turns into Status::Error. ODE is C++ inside, so the jump may skip
// its internal clean-up: after an error the world is only destroyed, never stepped again.
// dMessage (non-fatal: ODE carries on, e.g. "LCP internal error, s <= 0" when the Dantzig
// solver meets a degenerate pivot) is counted and the first one quoted in the result's
// message; the status stays Ok, as ODE's own result does.
#include "reference/ode.h"

#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <utility>

#include "reference/c_error_trap.h"
#include "reference/dynamics_recorder.h"
#include "reference/prebuilt_cache.h"

namespace {

// ODE's error state on the calling thread (reference/c_error_trap.h).
thread_local rbx::CErrorTrap t_trap;

}  // namespace

extern "C" {

// dError / dDebug: format, then jump back to guarded(); outside it, terminate as ODE would.
static void rbx_ode_on_error(int errnum, const char* msg, va_list ap) {
  char text[400];
  std::vsnprintf(text, sizeof(text), msg ? msg : "", ap);
  rbx::trap_printf(t_trap.error, "ODE error %d: %s", errnum, text);
  rbx::trap_jump_or_abort(t_trap, "%s (outside a guarded call)\n");
}

// dMessage: count, and keep the first message; the caller reports it.
static void rbx_ode_on_message(int errnum, const char* msg, va_list ap) {
  ++t_trap.warning_count;
  if (t_trap.has_warning()) return;
  char text[400];
  std::vsnprintf(text, sizeof(text), msg ? msg : "", ap);
  rbx::trap_printf(t_trap.warning, "ODE message %d: %s", errnum, text);
}

}  // extern "C"

namespace rbx {
namespace {

// At most this many contact points per geom pair (dCollide's flags).
constexpr int kMaxContacts = 32;
// A contact point closing slower than this (m/s) is not an impact. After a perfectly inelastic
// impact or at rest the normal velocity should be zero, but CFM (1e-10) leaves the contact
// closing at ~1e-7 of the impact speed (1.5e-7 m/s after a 2 m/s impact): not a new collision.
constexpr double kClosingSpeed = 1e-6;

// Initialises ODE once per process and its per-thread data once per thread, and installs the
// handlers.
void init_ode() {
  static std::once_flag once;
  std::call_once(once, [] {
    dInitODE2(0);
    dSetErrorHandler(rbx_ode_on_error);
    dSetDebugHandler(rbx_ode_on_error);
    dSetMessageHandler(rbx_ode_on_message);
  });
  thread_local bool thread_ready = false;
  if (!thread_ready) {
    dAllocateODEDataForThread(dAllocateMaskAll);
    thread_ready = true;
  }
}

// Runs f() so that an ODE error returns false (message in t_trap.error) instead of exiting.
// f must own no object with a non-trivial destructor (the longjmp skips its frame).
template <class F>
bool guarded(F&& f) {
  return rbx::guarded(t_trap, std::forward<F>(f));
}

// The arrays dCreateConvex reads. ODE keeps pointers to them, so they must outlive the geom.
struct ConvexData {
  std::vector<dReal> planes;       // a, b, c, d per face: outward unit n, n . x = d
  std::vector<dReal> points;       // x, y, z per vertex
  std::vector<unsigned> polygons;  // per face: vertex count, then indices counter-clockwise
  unsigned face_count = 0;
};

// Builds ODE's convex description of a hull, in the hull's own frame. Coplanar triangles are
// merged into one polygon (its boundary walked from the triangles' directed edges), so ODE
// sees the true faces and edges, not the triangulation's diagonals.
ConvexData make_convex_data(const ConvexPolyhedron& hull) {
  ConvexData c;
  const auto& v = hull.vertices();
  for (const Vec3& p : v) c.points.insert(c.points.end(), {p.x(), p.y(), p.z()});
  double size = 0.0;
  for (const Vec3& p : v) size = std::max(size, p.norm());
  // Coplanar: every corner within round-off of the plane, relative to the shape's own size (an
  // absolute tolerance merges a millimetre sliver's triangles that really bend, into a
  // non-convex polygon).
  const double tol = 1e-9 * size;

  // Group triangles by plane.
  const auto& tris = hull.triangles();
  const auto& planes = hull.planes();
  std::vector<int> group(tris.size(), -1);
  std::vector<int> group_plane;
  for (size_t t = 0; t < tris.size(); ++t) {
    for (size_t g = 0; g < group_plane.size() && group[t] < 0; ++g) {
      const Plane& p = planes[group_plane[g]];
      const bool on_plane = std::all_of(tris[t].begin(), tris[t].end(), [&](int k) {
        return std::abs(p.normal.dot(v[k]) - p.offset) < tol;
      });
      if (planes[t].normal.dot(p.normal) > 1.0 - 1e-9 && on_plane) group[t] = static_cast<int>(g);
    }
    if (group[t] < 0) {
      group[t] = static_cast<int>(group_plane.size());
      group_plane.push_back(static_cast<int>(t));
    }
  }

  // Each group's boundary: directed edges whose reverse is not in the same group, chained.
  for (size_t g = 0; g < group_plane.size(); ++g) {
    std::map<std::pair<int, int>, bool> edges;
    for (size_t t = 0; t < tris.size(); ++t)
      if (group[t] == static_cast<int>(g))
        for (int k = 0; k < 3; ++k) edges[{tris[t][k], tris[t][(k + 1) % 3]}] = true;
    std::map<int, int> next;
    for (const auto& [e, unused] : edges)
      if (!edges.count({e.second, e.first})) next[e.first] = e.second;
    std::vector<unsigned> loop;
    const int start = next.begin()->first;
    int at = start;
    do {
      loop.push_back(static_cast<unsigned>(at));
      at = next.at(at);
    } while (at != start && loop.size() <= next.size());
    // ODE checks a polygon's winding on its first three corners (p0 . (p1 x p2) > 0, printing a
    // warning to stdout otherwise): the loop starts at the corner where that is largest, not at
    // one where three corners are collinear to round-off.
    const size_t count = loop.size();
    size_t first = 0;
    double most = -std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < count; ++k) {
      const double turn = v[loop[k]].dot(v[loop[(k + 1) % count]].cross(v[loop[(k + 2) % count]]));
      if (turn > most) {
        most = turn;
        first = k;
      }
    }
    std::rotate(loop.begin(), loop.begin() + static_cast<std::ptrdiff_t>(first), loop.end());
    const Plane& p = planes[group_plane[g]];
    c.planes.insert(c.planes.end(), {p.normal.x(), p.normal.y(), p.normal.z(), p.offset});
    c.polygons.push_back(static_cast<unsigned>(loop.size()));
    c.polygons.insert(c.polygons.end(), loop.begin(), loop.end());
  }
  c.face_count = static_cast<unsigned>(group_plane.size());
  return c;
}

// A convex geom and the data it points to.
struct ConvexGeom {
  std::unique_ptr<ConvexData> data;
  dGeomID geom = nullptr;
};

// Creates the geom of a body in `space` (may be 0): a box when `native` and the body is one
// (is_native_box: centred on the body origin, axes the body axes), else its convex hull.
ConvexGeom make_geom(dSpaceID space, const RigidBody& b, bool native) {
  ConvexGeom g;
  if (native && is_native_box(b)) {
    g.geom = dCreateBox(space, b.box_size.x(), b.box_size.y(), b.box_size.z());
    return g;
  }
  g.data = std::make_unique<ConvexData>(make_convex_data(*b.shape));
  const ConvexData& d = *g.data;
  g.geom = dCreateConvex(space, d.planes.data(), d.face_count, d.points.data(),
                         static_cast<unsigned>(b.shape->vertices().size()), d.polygons.data());
  return g;
}

// Places a geom (without a body) at a body's pose.
void place_geom(dGeomID g, const RigidBody& b) {
  const Quat o = b.orientation.normalized();
  dGeomSetPosition(g, b.position.x(), b.position.y(), b.position.z());
  const dQuaternion q = {o.w(), o.x(), o.y(), o.z()};
  dGeomSetQuaternion(g, q);
}

// Our contact from ODE's: the normal points into g1 (from g2 toward g1), depth positive. With
// g1 = A that is already ours.
ContactPoint convert_contact(const dContactGeom& c, const char* feature) {
  ContactPoint p;
  p.point = Vec3(c.pos[0], c.pos[1], c.pos[2]);
  p.normal = Vec3(c.normal[0], c.normal[1], c.normal[2]);
  p.depth = c.depth;
  p.feature = feature;
  return p;
}

// Owners of ODE objects.
struct WorldOwner {
  dWorldID world = nullptr;
  dSpaceID space = nullptr;
  dJointGroupID contacts = nullptr;
  std::vector<ConvexGeom> geoms;
  ~WorldOwner() {
    for (ConvexGeom& g : geoms)
      if (g.geom) dGeomDestroy(g.geom);
    if (contacts) dJointGroupDestroy(contacts);
    if (space) dSpaceDestroy(space);
    if (world) dWorldDestroy(world);
  }
};

// One contact joint created in a step, with what we need to report it.
struct StepContact {
  int a = 0, b = 0;  // scene indices, a < b
  const char* feature = "convex";
  dContactGeom geom{};    // g1 belongs to a
  double approach = 0.0;  // m/s, relative normal velocity before the step (< 0: closing)
  dJointFeedback* feedback = nullptr;
};

// Label of the collider a pair of geoms takes.
const char* pair_feature(dGeomID a, dGeomID b) {
  return dGeomGetClass(a) == dBoxClass && dGeomGetClass(b) == dBoxClass ? "box-box" : "convex";
}

// State passed through dSpaceCollide to the near callback.
struct CollideContext {
  dWorldID world = nullptr;
  dJointGroupID group = nullptr;
  double restitution = 1.0;
  double friction = 0.0;
  bool friction_along_slip = false;  // OdeSettings::friction_along_slip
  int max_contacts = kMaxContacts;   // OdeSettings::max_contacts
  std::vector<StepContact> contacts;
  std::deque<dJointFeedback> feedback;  // deque: stable addresses while growing
};

// Scene index stored in a geom's user data.
int scene_index(dGeomID g) {
  return static_cast<int>(reinterpret_cast<std::intptr_t>(dGeomGetData(g)));
}

// Velocity of a body's material point at world position p (zero for no body).
Vec3 point_velocity(dBodyID body, const dReal* p) {
  if (!body) return Vec3::Zero();
  dVector3 v;
  dBodyGetPointVel(body, p[0], p[1], p[2], v);
  return Vec3(v[0], v[1], v[2]);
}

// Near callback: contact joints with dContactBounce (and Coulomb friction) for every contact
// point of a pair. Only trivially destructible locals (an error inside dCollide longjmps over
// this frame).
void near_callback(void* data, dGeomID o1, dGeomID o2) {
  auto* ctx = static_cast<CollideContext*>(data);
  dBodyID b1 = dGeomGetBody(o1), b2 = dGeomGetBody(o2);
  if (!b1 && !b2) return;  // two static geoms
  if (scene_index(o1) > scene_index(o2)) {
    std::swap(o1, o2);
    std::swap(b1, b2);
  }
  dContact contact[kMaxContacts] = {};
  const int n = dCollide(o1, o2, ctx->max_contacts, &contact[0].geom, sizeof(dContact));
  for (int i = 0; i < n; ++i) {
    dContact& c = contact[i];
    // dContactBounce: restitution as a target separation speed (joints/contact.cpp, getInfo2:
    // the normal row's target becomes max(bounce * approach speed, ERP * depth / dt)).
    // dContactApprox1: without it ODE bounds each friction row by +-mu as a *force* in newtons
    // (lo = -mu, hi = mu in getInfo2), not by mu times the normal force; Approx1 sets each
    // friction row's findex to its normal row, and the LCP solver (lcp.cpp, dSolveLCP) then
    // uses hi = |mu * normal force|: Coulomb friction, with a friction pyramid whose two
    // directions come from dPlaneSpace. With mu = 0 ODE adds no friction rows at all
    // (getInfo1), so the flag changes nothing for frictionless scenes.
    // No dContactSoftERP / dContactSoftCFM: the world's ERP and CFM apply (see ode_dynamics).
    c.surface.mode = dContactBounce | dContactApprox1;
    const Vec3 n_ours(c.geom.normal[0], c.geom.normal[1], c.geom.normal[2]);
    const Vec3 relative = point_velocity(b1, c.geom.pos) - point_velocity(b2, c.geom.pos);
    // Each pyramid row is bounded by mu N alone, so with fixed axes a slip along neither axis
    // meets a friction force of up to sqrt(2) mu N, not against the slip: the path bends. ODE's
    // manual gives the first direction along the motion as the remedy; the second row then
    // carries no slip. At stick (no measurable slip) there is no direction to follow and
    // dPlaneSpace's axes stay.
    const Vec3 slip = relative - relative.dot(n_ours) * n_ours;
    if (ctx->friction_along_slip && ctx->friction > 0.0 && slip.norm() > kStickSpeed) {
      const Vec3 dir = slip.normalized();
      c.surface.mode |= dContactFDir1;
      for (int k = 0; k < 3; ++k) c.fdir1[k] = dir[k];
    }
    c.surface.mu = ctx->friction;         // the scene's Coulomb coefficient; 0: frictionless
    c.surface.bounce = ctx->restitution;  // the scene's coefficient of restitution e
    // Bounce at any approach speed: ODE bounces only when the approach speed exceeds
    // bounce_vel (strictly), and the seed's single-impulse law has no threshold.
    c.surface.bounce_vel = 0.0;
    dJointID j = dJointCreateContact(ctx->world, ctx->group, &c);
    dJointAttach(j, b1, b2);
    ctx->feedback.emplace_back();
    dJointSetFeedback(j, &ctx->feedback.back());
    StepContact sc;
    sc.a = scene_index(o1);
    sc.b = scene_index(o2);
    sc.geom = c.geom;
    sc.feature = pair_feature(o1, o2);
    sc.approach = relative.dot(n_ours);
    sc.feedback = &ctx->feedback.back();
    ctx->contacts.push_back(sc);
  }
}

// State of scene body i after the run.
BodyFinal read_state(const RigidBody& b, dBodyID body) {
  BodyFinal f;
  f.name = b.name;
  if (!body) {
    f.position = b.position;
    f.orientation = b.orientation;
    return f;
  }
  const dReal* p = dBodyGetPosition(body);
  const dReal* q = dBodyGetQuaternion(body);
  const dReal* v = dBodyGetLinearVel(body);
  const dReal* w = dBodyGetAngularVel(body);  // world frame
  f.position = Vec3(p[0], p[1], p[2]);
  f.orientation = Quat(q[0], q[1], q[2], q[3]).normalized();
  f.velocity = Vec3(v[0], v[1], v[2]);
  f.angular_velocity = Vec3(w[0], w[1], w[2]);
  return f;
}

}  // namespace

namespace {

/// A geom kept across queries (the "prebuilt" variants), destroyed with its data.
using KeptGeom = std::shared_ptr<ConvexGeom>;

KeptGeom keep_geom(const RigidBody& b, bool native) {
  return KeptGeom(new ConvexGeom(make_geom(nullptr, b, native)), [](ConvexGeom* g) {
    dGeomDestroy(g->geom);
    delete g;
  });
}

/// dCollide of the two bodies; geoms built in the query, or kept in `prebuilt` (one cache per
/// variant: the shape alone is the key).
ContactResult contact_query(const RigidBody& a, const RigidBody& b, bool native,
                            PrebuiltCache<KeptGeom>* prebuilt = nullptr,
                            int max_contacts = kMaxContacts) {
  init_ode();
  ContactResult r;
  KeptGeom ga = prebuilt ? prebuilt->get(a.shape, nullptr, [&] { return keep_geom(a, native); })
                         : keep_geom(a, native);
  KeptGeom gb = prebuilt ? prebuilt->get(b.shape, nullptr, [&] { return keep_geom(b, native); })
                         : keep_geom(b, native);
  const char* feature = pair_feature(ga->geom, gb->geom);
  place_geom(ga->geom, a);
  place_geom(gb->geom, b);
  dContactGeom contacts[kMaxContacts];
  int n = 0;
  t_trap.clear_warning();
  const dGeomID g1 = ga->geom, g2 = gb->geom;
  const int most = std::clamp(max_contacts, 1, kMaxContacts);
  const bool ok = guarded([&] { n = dCollide(g1, g2, most, contacts, sizeof(dContactGeom)); });
  if (!ok) return {Status::Error, t_trap.error, {}};
  if (t_trap.has_warning()) r.message = t_trap.warning;
  for (int i = 0; i < n; ++i) r.contacts.push_back(convert_contact(contacts[i], feature));
  // Debian's ODE routes convex-convex to libccd MPR (dCollideConvexConvexCCD): at depth below
  // CCD_EPS its direction, hence ODE's normal, is zero. Labelled, not scored as a 180 deg miss.
  return reject_undefined_normals(std::move(r), std::string("dCollide (") + feature + ")");
}

}  // namespace

OdeSettings ode_hull_settings() {
  OdeSettings s;
  s.native_boxes = false;
  // ODE's default world: on its one-point convex manifold a resting box tips about its single
  // contact, and only an uncapped correction lifts it back before it sinks into the floor.
  s.max_correcting_vel = INFINITY;
  return s;
}

namespace {

// The scene's ODE world, space and contact group in `w`: gravity from the scene; ERP and CFM
// from the settings, ODE's defaults (0.2, 1e-10).
//  - CFM softens each contact by a relative CFM / (dt * inverse effective mass), ~1e-7 here.
//  - Position correction: a contact's target separation speed is
//    max(e * approach speed, min(ERP * depth / dt, max_correcting_vel)). Uncapped (ODE's
//    default), a contact first seen d deep leaves at ERP d / dt whatever e is: an e = 0
//    impact bounces, and a landing box pops off the floor, flies and loses its slide. Capped at
//    0, nothing lifts a resting stack out of the floor and it sinks. A cap between keeps the
//    stack where the default does (its steady correction is far below any cap) and bounds the
//    pop; a lower cap also starves the fitted soft contact of the real tosses, which then sinks
//    and rolls off the measured path (tests/reference/fair_settings_test.cpp and
//    tests/comparisons/explore_slide_test.cpp measure each). A contact surface layer instead
//    makes the stacks blow up. ODE's e = 0 impacts seen inside a step keep a bounce of at most
//    the cap, a measured limitation (the report's contact-phase table).
void create_world(WorldOwner& w, const WorldDefinition& scene, const OdeSettings& settings) {
  w.world = dWorldCreate();
  w.space = dSimpleSpaceCreate(nullptr);
  w.contacts = dJointGroupCreate(0);
  const Vec3& g = scene.sim.gravity;
  dWorldSetGravity(w.world, g.x(), g.y(), g.z());
  dWorldSetERP(w.world, settings.erp);
  dWorldSetCFM(w.world, settings.cfm);
  if (std::isfinite(settings.max_correcting_vel))
    dWorldSetContactMaxCorrectingVel(w.world, settings.max_correcting_vel);
}

// Bodies: our mass and inertia about the centre of mass at the body origin; a static body is a
// geom without a body (null in `ode_bodies`). Returns "" or why ODE refused a body.
std::string add_bodies(WorldOwner& w, const std::vector<RigidBody>& bodies,
                       const OdeSettings& settings, std::vector<dBodyID>& ode_bodies) {
  ode_bodies.assign(bodies.size(), nullptr);
  for (size_t i = 0; i < bodies.size(); ++i) {
    const RigidBody& b = bodies[i];
    w.geoms.push_back(make_geom(w.space, b, settings.native_boxes));
    dGeomID geom = w.geoms.back().geom;
    dGeomSetData(geom, reinterpret_cast<void*>(static_cast<std::intptr_t>(i)));
    if (b.is_static) {
      place_geom(geom, b);
      continue;
    }
    dBodyID body = dBodyCreate(w.world);
    dMass mass;
    const Mat3& I = b.inertia_body;
    dMassSetParameters(&mass, b.mass, 0, 0, 0, I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2),
                       I(1, 2));
    // dBodySetMass checks the mass (dMassCheck) and calls dDebug on failure.
    if (!guarded([&] { dBodySetMass(body, &mass); }))
      return std::string("ODE dBodySetMass (") + b.name + "): " + t_trap.error;
    const Quat o = b.orientation.normalized();
    const dQuaternion q = {o.w(), o.x(), o.y(), o.z()};
    dBodySetPosition(body, b.position.x(), b.position.y(), b.position.z());
    dBodySetQuaternion(body, q);
    dBodySetLinearVel(body, b.velocity.x(), b.velocity.y(), b.velocity.z());
    dBodySetAngularVel(body, b.angular_velocity.x(), b.angular_velocity.y(),
                       b.angular_velocity.z());
    // Exact rotation by w dt each step instead of the linearised quaternion update (a setting
    // for a fair reference; ODE's default is the infinitesimal update).
    dBodySetFiniteRotationMode(body, 1);
    dGeomSetBody(geom, body);
    ode_bodies[i] = body;
  }
  return "";
}

// Events of step `step` (append_pair_events): each point's normal impulse is its normal force
// f . n times dt.
void pair_events(const CollideContext& ctx, const std::vector<RigidBody>& bodies,
                 const std::vector<dBodyID>& ode_bodies, long step, double dt,
                 std::vector<CollisionEvent>& events) {
  std::vector<PairPoint> points;
  for (const StepContact& sc : ctx.contacts) {
    PairPoint p;
    p.a = sc.a;
    p.b = sc.b;
    p.contact = convert_contact(sc.geom, sc.feature);
    // Force along the normal (N). With two bodies f1 acts on a; with one, ODE moves the
    // body into the first slot, so take whichever slot is filled (the push is >= 0).
    const dJointFeedback& fb = *sc.feedback;
    const Vec3 f1(fb.f1[0], fb.f1[1], fb.f1[2]), f2(fb.f2[0], fb.f2[1], fb.f2[2]);
    const Vec3& n = p.contact.normal;
    const double push = (ode_bodies[sc.a] && ode_bodies[sc.b])
                            ? f1.dot(n)
                            : std::max(std::abs(f1.dot(n)), std::abs(f2.dot(n)));
    p.normal_impulse = push * dt;  // N s
    p.closing = sc.approach < -kClosingSpeed;
    points.push_back(p);
  }
  append_pair_events(points, bodies, step, dt, events);
}

// Every contact joint of the step with the impulse it applied to body a over the step (its
// feedback force times dt), given to `recorder`. With two bodies f1 acts on a; with one, ODE
// moves the body into the first slot, so f1 acts on whichever of a and b is the body.
void record_contacts(const CollideContext& ctx, const std::vector<dBodyID>& ode_bodies, double dt,
                     DynamicsRecorder& recorder) {
  for (const StepContact& sc : ctx.contacts) {
    const ContactPoint cp = convert_contact(sc.geom, sc.feature);
    const dJointFeedback& fb = *sc.feedback;
    const Vec3 f1(fb.f1[0], fb.f1[1], fb.f1[2]);
    SolvedContact c;
    c.a = sc.a;
    c.b = sc.b;
    c.point = cp.point;
    c.normal = cp.normal;
    c.depth = cp.depth;
    c.impulse = (ode_bodies[sc.a] ? f1 : Vec3(-f1)) * dt;
    recorder.contact_at_start(c);
  }
}

// How many of the step's contact points belong to the pair of `event`.
int points_of(const CollideContext& ctx, const std::vector<RigidBody>& bodies,
              const CollisionEvent& event) {
  int points = 0;
  for (const StepContact& sc : ctx.contacts)
    if (bodies[sc.a].name == event.body_a && bodies[sc.b].name == event.body_b) ++points;
  return points;
}

}  // namespace

namespace {

DynamicsResult ode_dynamics_with(const WorldDefinition& scene, const DynamicsOptions& opt,
                                 const OdeSettings& settings) {
  // One ODE world steps at a time in the process: ODE 0.16's worlds share its default
  // self-threaded stepping implementation, and two dWorldStep calls on two threads (rbx report
  // runs scenes on every core) fail its assertion in WaitWakeup (threading_fake_sync.h:83),
  // measured on analytic/headon_e0. Contact queries (dCollide) need no lock.
  static std::mutex world_step_lock;
  const std::lock_guard<std::mutex> lock(world_step_lock);
  init_ode();
  DynamicsResult r;
  const double dt = opt.dt > 0.0 ? opt.dt : scene.sim.dt;
  if (!(dt > 0.0)) return {Status::Error, "ODE: time step must be > 0", {}, {}, {}, {}, {}};
  const long steps = step_count(scene.sim.duration, dt);  // throws when uncountable
  const std::vector<RigidBody> bodies = make_bodies(scene);

  WorldOwner w;
  create_world(w, scene, settings);
  // A studied budget (ode_budget) steps with the iterative quick step; otherwise the exact step.
  const int budget = opt.budget;
  if (budget > 0) dWorldSetQuickStepNumIterations(w.world, budget);
  // The quick step shuffles its constraints with ODE's one random generator, shared by the whole
  // process: seeded here (ODE's own start value), a run gives the same answer whatever ran
  // before it in this process.
  dRandSetSeed(0);
  std::vector<dBodyID> ode_bodies;
  if (std::string error = add_bodies(w, bodies, settings, ode_bodies); !error.empty()) {
    r.status = Status::Error;
    r.message = std::move(error);
    return r;
  }

  DynamicsRecorder recorder(r, opt, [&] {
    std::vector<BodyFinal> states;
    for (size_t i = 0; i < bodies.size(); ++i)
      states.push_back(read_state(bodies[i], ode_bodies[i]));
    return states;
  });
  CollideContext ctx;
  ctx.world = w.world;
  ctx.group = w.contacts;
  ctx.restitution = scene.sim.restitution;
  ctx.friction = scene.sim.friction;
  ctx.friction_along_slip = settings.friction_along_slip;
  ctx.max_contacts = std::clamp(settings.max_contacts, 1, kMaxContacts);
  t_trap.clear_warning();
  t_trap.warning_count = 0;
  long first_message_step = -1;
  recorder.measure_contact_laws(scene);
  recorder.start();
  for (long step = 0; step < steps; ++step) {
    recorder.before_step(r.events);
    ctx.contacts.clear();
    ctx.feedback.clear();
    CollideContext* c = &ctx;
    const dSpaceID space = w.space;
    const dWorldID world = w.world;
    if (!guarded([&] {
          dSpaceCollide(space, c, near_callback);
          if (budget > 0)
            dWorldQuickStep(world, dt);
          else
            dWorldStep(world, dt);
        })) {
      r.status = Status::Error;
      r.message = "ODE at step " + std::to_string(step) + ": " + t_trap.error;
      return r;
    }
    if (t_trap.has_warning() && first_message_step < 0) first_message_step = step;
    pair_events(ctx, bodies, ode_bodies, step, dt, r.events);
    // The first impulse: ODE's events merge a pair's points, so the count is ODE's own (the
    // event keeps the deepest of the pair's points already).
    if (const CollisionEvent* first = recorder.first_new_event(r.events))
      recorder.first_impulse_from_event(*first, dt, points_of(ctx, bodies, *first));
    record_contacts(ctx, ode_bodies, dt, recorder);
    dJointGroupEmpty(w.contacts);
    recorder.after_step(step + 1, (step + 1) * dt);
  }
  if (t_trap.warning_count > 0)
    r.message = std::to_string(t_trap.warning_count) + " ODE message(s), the first at step " +
                std::to_string(first_message_step) + ": " + t_trap.warning;

  recorder.finish("ODE");
  return r;
}

}  // namespace

namespace {

// `ode`: dCollide on dCreateBox geoms for boxes (dBoxBox), dCreateConvex otherwise.
ContactResult ode_contact(const RigidBody& a, const RigidBody& b) {
  return contact_query(a, b, true);
}

// `ode-hull`: dCollide on dCreateConvex geoms (libccd MPR in Debian's build, one point).
ContactResult ode_hull_contact(const RigidBody& a, const RigidBody& b) {
  return contact_query(a, b, false);
}

// `ode` and `ode-hull` with each shape's geom built once and kept (reference/prebuilt_cache.h),
// placed at each query: variant "prebuilt".
ContactResult ode_contact_prebuilt(const RigidBody& a, const RigidBody& b) {
  thread_local PrebuiltCache<KeptGeom> cache;
  return contact_query(a, b, true, &cache);
}

ContactResult ode_hull_contact_prebuilt(const RigidBody& a, const RigidBody& b) {
  thread_local PrebuiltCache<KeptGeom> cache;
  return contact_query(a, b, false, &cache);
}

// `ode`: dWorldStep with dContactBounce on the native geoms.
DynamicsResult ode_dynamics(const WorldDefinition& scene, const DynamicsOptions& opt) {
  return ode_dynamics_with(scene, opt, OdeSettings{});
}

// `ode-hull`: the same world on convex geoms.
DynamicsResult ode_hull_dynamics(const WorldDefinition& scene, const DynamicsOptions& opt) {
  return ode_dynamics_with(scene, opt, ode_hull_settings());
}

}  // namespace

const AtSettings<OdeSettings>& ode_at_settings() {
  static const AtSettings<OdeSettings> entries = {
      [](const RigidBody& a, const RigidBody& b, const OdeSettings& settings) {
        return contact_query(a, b, settings.native_boxes, nullptr, settings.max_contacts);
      },
      ode_dynamics_with};
  return entries;
}

// The budget studied: the iterations of ODE's quick step (dWorldQuickStep, successive
// over-relaxation; library default 20). rbx runs the exact step (dWorldStep, a pivoting LCP
// solve: no iteration count), so the study shows what the quick step costs and gives up.
SolverBudget ode_budget() {
  return {
      "dWorldQuickStep iterations (configured: dWorldStep, exact)", {5, 10, 20, 50, 100}, 20, 0};
}

// The contact softness ODE's manual has its users tune, from `base`'s settings: the world's
// error reduction (ERP) and constraint force mixing (CFM).
SoftContact ode_soft(const OdeSettings& base) {
  return {{{"erp",
            "error reduction parameter (the share of a penetration corrected per step)",
            base.erp,
            0.0,
            1.0,
            {0.05, 0.1, 0.2, 0.4, 0.8}},
           {"cfm",
            "constraint force mixing (contact compliance)",
            base.cfm,
            0.0,
            1.0,
            {1e-10, 1e-7, 1e-5, 1e-3, 1e-2, 3e-2, 1e-1}}},
          [base](const WorldDefinition& scene, const DynamicsOptions& opt,
                 const std::vector<double>& v) {
            OdeSettings s = base;
            s.erp = v.at(0);
            s.cfm = v.at(1);
            return ode_dynamics_with(scene, opt, s);
          }};
}

const Adapter& ode_adapter() {
  static const Adapter adapter = {
      {
          with_soft(with_budget({"ode",
                                 "ODE 0.16.2 dCreateBox (dBoxBox) or dCreateConvex; dWorldStep, "
                                 "bounce = e",
                                 ode_contact, ode_dynamics},
                                ode_budget()),
                    ode_soft(OdeSettings{}))
              .drawn("#6A3D9A", "o")
              .timed(2048, 512),
          with_soft(with_budget({"ode-hull",
                                 "ODE 0.16.2 dCreateConvex (libccd MPR); dWorldStep, bounce = e",
                                 ode_hull_contact, ode_hull_dynamics},
                                ode_budget()),
                    ode_soft(ode_hull_settings()))
              .drawn("#B39DDB", "s"),
      },
      {
          {"ode", "prebuilt", "each dBox or dConvex geom built once and kept",
           ode_contact_prebuilt},
          {"ode-hull", "prebuilt", "each dConvex geom built once and kept",
           ode_hull_contact_prebuilt},
      }};
  return adapter;
}

}  // namespace rbx
