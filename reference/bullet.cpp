// Bullet 3.24, double build (BT_USE_DOUBLE_PRECISION from `pkg-config bullet-float64`).
//
// Shapes (BulletSettings, each choice measured in tests/reference/fair_settings_test.cpp):
//  - `bullet`: a box body is a btBoxShape (Bullet's own margin, which sits inside the box, so
//    its extents are exact); two boxes then meet in btBoxBoxCollisionAlgorithm (the ODE-derived
//    box-box detector, up to 4 points). Any other body is a btConvexHullShape with
//    initializePolyhedralFeatures: the axis by GJK + EPA, then the hulls clipped against each
//    other (a manifold of several points). Not m_enableSatConvex: with the axis by SAT two
//    face-to-face hexagonal prisms came out spinning (velocity error 0.26 against 7e-16).
//    Margin 0: a hull's margin lies outside it and inflates it.
//  - `bullet-hull`: every body a zero-margin btConvexHullShape without polyhedral features:
//    GJK and, on overlap, EPA, one point: the input every other backend gets.
//  - `bullet-sat`: every body (boxes too) a polyhedral hull, the axis by SAT
//    (m_enableSatConvex), then clipping.
// Contact queries put one btCollisionObject per body at its pose and call
// btCollisionWorld::contactPairTest.
//
// Known wrong answer, passed on (pinned in tests/reference/bullet_test.cpp): when the hulls have
// coplanar side faces (two equal axis-aligned cubes offset along one axis), EPA
// (btGjkEpaSolver2::Penetration) returns a diagonal normal and depth 0.1/sqrt(3) for a true
// 0.1 along x. The `bullet-hull` world meets it too, since it solves contacts only after
// overlap; `bullet` does not (box-box detector).
//
// Dynamics: btDiscreteDynamicsWorld with the settings of docs/references.md that turn it into a
// fair single-impulse reference; each setting carries its reason where it is made.
//
// Bullet's convention (btManifoldPoint): m_normalWorldOnB points from the callback's object 1
// toward object 0, getDistance() < 0 when penetrating, m_positionWorldOnB lies on object 1 and
// m_positionWorldOnA = m_positionWorldOnB + m_normalWorldOnB * distance on object 0.
#include "reference/bullet.h"

#include <BulletCollision/NarrowPhaseCollision/btContinuousConvexCollision.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkConvexCast.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpaPenetrationDepthSolver.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkPairDetector.h>
#include <BulletCollision/NarrowPhaseCollision/btPointCollector.h>
#include <BulletCollision/NarrowPhaseCollision/btSubSimplexConvexCast.h>
#include <BulletCollision/NarrowPhaseCollision/btVoronoiSimplexSolver.h>
#include <btBulletCollisionCommon.h>
#include <btBulletDynamicsCommon.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <exception>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "reference/dynamics_recorder.h"
#include "reference/prebuilt_cache.h"

namespace rbx {

namespace {

// A reported point counts as a contact while its signed distance is at most this (m). GJK on
// two exactly touching hulls returns a distance of a few ulps of the coordinates either side
// of 0; 1e-9 m covers that for scenes of metre scale, while Bullet's breaking threshold
// (about 0.02 m scaled by the shape) would report clearly separated pairs.
constexpr double kTouchTolerance = 1e-9;

btVector3 to_bt(const Vec3& v) { return btVector3(v.x(), v.y(), v.z()); }
Vec3 from_bt(const btVector3& v) { return Vec3(v.x(), v.y(), v.z()); }

btMatrix3x3 to_bt_basis(const Mat3& m) {
  return btMatrix3x3(m(0, 0), m(0, 1), m(0, 2), m(1, 0), m(1, 1), m(1, 2), m(2, 0), m(2, 1),
                     m(2, 2));
}
Mat3 from_bt_basis(const btMatrix3x3& m) {
  Mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r(i, j) = m[i][j];
  return r;
}

/// Hull of `vertices` mapped by `frame` (shape frame <- body frame), with collision margin
/// `margin` (m). With `polyhedral`, Bullet also builds its face/edge structure so the SAT and
/// clipping path runs.
std::unique_ptr<btConvexHullShape> make_hull(const std::vector<Vec3>& vertices, const Mat3& frame,
                                             bool polyhedral, double margin = 0.0) {
  auto hull = std::make_unique<btConvexHullShape>();
  // Margin first: recalcLocalAabb pads the cached box by the current margin.
  hull->setMargin(margin);
  for (const Vec3& v : vertices) hull->addPoint(to_bt(Vec3(frame * v)), false);
  hull->recalcLocalAabb();
  if (polyhedral && !hull->initializePolyhedralFeatures())
    throw std::runtime_error("btConvexHullShape::initializePolyhedralFeatures failed");
  return hull;
}

/// True when `body` becomes a btBoxShape under `settings`.
bool native_box(const RigidBody& body, const BulletSettings& settings) {
  return settings.native_boxes && is_native_box(body);
}

/// The body's Bullet shape: a btBoxShape in the body axes (`frame` is then ignored: the caller
/// keeps a box in its body axes) or a hull of its vertices mapped by `frame`.
std::unique_ptr<btConvexShape> make_shape(const RigidBody& body, const Mat3& frame,
                                          const BulletSettings& settings) {
  if (!native_box(body, settings))
    return make_hull(body.shape->vertices(), frame, settings.polyhedral_hulls,
                     settings.hull_margin);
  // The constructor sets Bullet's default margin (0.04 m), lowered to a tenth of the smallest
  // half extent for small boxes (setSafeMargin); the margin is inside the box either way. A set
  // margin overrides that lowering: a margin wider than a thin box's half extent turns its
  // contacts' normals (BulletSettingsMeasured.BoxMarginAsTheConstructorSetsIt).
  auto box = std::make_unique<btBoxShape>(to_bt(0.5 * body.box_size));
  if (settings.box_margin >= 0) box->setMargin(settings.box_margin);
  // Polyhedral features let a box meet a polyhedral hull through SAT (box-box pairs use the
  // box-box algorithm whatever this says).
  if (settings.polyhedral_hulls && !box->initializePolyhedralFeatures())
    throw std::runtime_error("btBoxShape::initializePolyhedralFeatures failed");
  return box;
}

/// Label of the contact path a pair takes.
const char* pair_feature(bool box_a, bool box_b, const BulletSettings& settings) {
  if (box_a && box_b) return "box-box";
  if (!settings.polyhedral_hulls) return "gjk-epa";
  return settings.sat_convex ? "sat-clip" : "gjk-clip";
}

/// Bullet transform of a body whose shape is expressed in `frame` axes: world = R * frame^T.
btTransform body_transform(const RigidBody& body, const Mat3& frame_to_body) {
  return btTransform(to_bt_basis(Mat3(body.orientation.toRotationMatrix() * frame_to_body)),
                     to_bt(body.position));
}

// ---------------------------------------------------------------------------------------------
// Contact queries

/// Collects contactPairTest's points, converted to the contract's convention for (A, B).
class PairCallback : public btCollisionWorld::ContactResultCallback {
 public:
  PairCallback(const btCollisionObject* a, const char* feature) : a_(a), feature_(feature) {}

  btScalar addSingleResult(btManifoldPoint& cp, const btCollisionObjectWrapper* obj0, int, int,
                           const btCollisionObjectWrapper*, int, int) override {
    // Points within the breaking threshold but separated are not contacts.
    const double distance = cp.getDistance();
    if (distance > kTouchTolerance) return 0;
    // m_normalWorldOnB points from the callback's object 1 toward object 0. If object 0 is our
    // A, that is our B -> A already; if the callback swapped them, flip it.
    const bool swapped = obj0->getCollisionObject() != a_;
    ContactPoint c;
    c.normal = from_bt(cp.m_normalWorldOnB).normalized();
    if (swapped) c.normal = -c.normal;
    c.depth = std::max(0.0, -distance);
    // Bullet's point lies on object 1's surface; report the midpoint of the two witness points,
    // the contract's "middle of the penetration" (symmetric in A and B).
    c.point = 0.5 * (from_bt(cp.getPositionWorldOnA()) + from_bt(cp.getPositionWorldOnB()));
    c.feature = feature_;
    contacts.push_back(c);
    return 0;
  }

  std::vector<ContactPoint> contacts;

 private:
  const btCollisionObject* a_;
  const char* feature_;
};

/// Collision configuration, dispatcher and world for contact queries. contactPairTest creates
/// and destroys its algorithm and manifold inside each call, so nothing carries over between
/// queries; one context per thread only avoids re-allocating the configuration's pools
/// (several MB) on every query.
struct QueryContext {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btCollisionWorld world{&dispatcher, &broadphase, &configuration};
};

/// Shapes of one settings variant kept across queries (the "prebuilt" variants); null: built in
/// each query, as the plain backends do.
using ShapeCache = PrebuiltCache<std::unique_ptr<btConvexShape>>;

ContactResult pair_query(const RigidBody& a, const RigidBody& b, const BulletSettings& settings,
                         ShapeCache* prebuilt = nullptr) {
  try {
    thread_local QueryContext ctx;
    const Mat3 identity = Mat3::Identity();
    std::unique_ptr<btConvexShape> hull_a, hull_b;
    btConvexShape *shape_a = nullptr, *shape_b = nullptr;
    if (prebuilt) {
      // A box body and a hull body never share a shape pointer: the shape alone is the key.
      shape_a =
          prebuilt->get(a.shape, nullptr, [&] { return make_shape(a, identity, settings); }).get();
      shape_b =
          prebuilt->get(b.shape, nullptr, [&] { return make_shape(b, identity, settings); }).get();
    } else {
      hull_a = make_shape(a, identity, settings);
      hull_b = make_shape(b, identity, settings);
      shape_a = hull_a.get();
      shape_b = hull_b.get();
    }
    btCollisionObject obj_a, obj_b;
    obj_a.setCollisionShape(shape_a);
    obj_b.setCollisionShape(shape_b);
    obj_a.setWorldTransform(body_transform(a, identity));
    obj_b.setWorldTransform(body_transform(b, identity));
    // With polyhedral features the algorithm takes its axis from SAT when m_enableSatConvex is
    // set, otherwise from GJK/EPA before clipping.
    ctx.world.getDispatchInfo().m_enableSatConvex =
        settings.polyhedral_hulls && settings.sat_convex;
    PairCallback callback(&obj_a,
                          pair_feature(native_box(a, settings), native_box(b, settings), settings));
    ctx.world.contactPairTest(&obj_a, &obj_b, callback);
    return {Status::Ok, "", std::move(callback.contacts)};
  } catch (const std::exception& e) {
    return {Status::Error, e.what(), {}};
  }
}

/// Bullet's closest points of two convex shapes, as its own distance demos and tests ask for
/// them: btGjkPairDetector (GJK with a Voronoi simplex solver; EPA when they overlap) on the
/// set-up's shapes, at the bodies' poses, into a btPointCollector. Its convention
/// (btGjkPairDetector::getClosestPointsNonVirtual): m_pointInWorld lies on B, m_normalOnBInWorld
/// points from B toward A, and A's point is m_pointInWorld + m_normalOnBInWorld * m_distance; a
/// negative distance is an overlap. Margins are the set-up's: a btBoxShape's lies inside the box
/// and GJK adds it back as a rounding of radius margin at its edges and corners (measured in
/// BulletSettingsMeasured.BoxMarginRoundsTheDistanceAtCorners), a hull's is zero.
DistanceResult pair_distance(const RigidBody& a, const RigidBody& b,
                             const BulletSettings& settings) {
  DistanceResult r;
  try {
    const Mat3 identity = Mat3::Identity();
    const std::unique_ptr<btConvexShape> shape_a = make_shape(a, identity, settings);
    const std::unique_ptr<btConvexShape> shape_b = make_shape(b, identity, settings);
    btVoronoiSimplexSolver simplex;
    btGjkEpaPenetrationDepthSolver epa;
    btGjkPairDetector gjk(shape_a.get(), shape_b.get(), &simplex, &epa);
    btGjkPairDetector::ClosestPointInput input;
    input.m_transformA = body_transform(a, identity);
    input.m_transformB = body_transform(b, identity);
    btPointCollector collector;
    gjk.getClosestPoints(input, collector, nullptr);
    if (!collector.m_hasResult) {
      r.status = Status::Error;
      r.message = "btGjkPairDetector::getClosestPoints returned no result";
      return r;
    }
    if (collector.m_distance < 0) {
      r.overlapping = true;
      return r;
    }
    r.distance = collector.m_distance;
    for (const auto* shape : {shape_a.get(), shape_b.get()})
      if (shape->getShapeType() == BOX_SHAPE_PROXYTYPE && shape->getMargin() > 0)
        r.message = "btBoxShape with Bullet's margin (" + std::to_string(shape->getMargin()) +
                    " m) inside it: GJK sees the box rounded by the margin at its edges and "
                    "corners";
    r.point_b = from_bt(collector.m_pointInWorld);
    r.point_a = r.point_b + from_bt(collector.m_normalOnBInWorld) * collector.m_distance;
  } catch (const std::exception& e) {
    r.status = Status::Error;
    r.message = e.what();
  }
  return r;
}

/// Bullet's casts (btConvexCast::calcTimeOfImpact), as its convex sweep tests call them, on the
/// set-up's shapes between the bodies' start and end poses. Read from the 3.24 sources:
/// - btContinuousConvexCollision takes each body's linear and angular velocity from its two poses
///   (btTransformUtil::calculateVelocity: the short way round) and advances conservatively on
///   btGjkPairDetector's distance, as the stated motion does; btGjkConvexCast and
///   btSubsimplexConvexCast move the origins only, keeping the start orientations.
/// - all three stop once the pair is within 1 mm (a fixed radius in each) and report that time as
///   m_fraction, with m_normal from B toward A and m_hitPoint on B (btGjkPairDetector's
///   m_pointInWorld), world frame; m_allowedPenetration stays at its 0.
enum class BulletCast { Continuous, Gjk, Subsimplex };

ToiResult pair_toi(const RigidBody& a, const RigidBody& b, double dt,
                   const BulletSettings& settings, BulletCast cast,
                   ShapeCache* prebuilt = nullptr) {
  ToiResult r;
  try {
    const std::optional<RigidBody> end_a = body_at_end(a, dt), end_b = body_at_end(b, dt);
    const bool rotating = !a.angular_velocity.isZero(0) || !b.angular_velocity.isZero(0);
    if (!end_a || !end_b || (cast != BulletCast::Continuous && rotating)) {
      r.status = Status::Unsupported;
      r.message = !end_a || !end_b ? "a body turns too far for its end poses to name its motion"
                                   : "this cast moves the bodies without turning them";
      return r;
    }
    const Mat3 identity = Mat3::Identity();
    std::unique_ptr<btConvexShape> own_a, own_b;
    auto shape = [&](const RigidBody& body, std::unique_ptr<btConvexShape>& own) {
      if (prebuilt)
        return prebuilt
            ->get(body.shape, nullptr, [&] { return make_shape(body, identity, settings); })
            .get();
      own = make_shape(body, identity, settings);
      return own.get();
    };
    btConvexShape* const shape_a = shape(a, own_a);
    btConvexShape* const shape_b = shape(b, own_b);
    btVoronoiSimplexSolver simplex;
    btGjkEpaPenetrationDepthSolver epa;
    btConvexCast::CastResult result;
    const btTransform from_a = body_transform(a, identity), to_a = body_transform(*end_a, identity);
    const btTransform from_b = body_transform(b, identity), to_b = body_transform(*end_b, identity);
    bool hit = false;
    if (cast == BulletCast::Continuous) {
      btContinuousConvexCollision caster(shape_a, shape_b, &simplex, &epa);
      hit = caster.calcTimeOfImpact(from_a, to_a, from_b, to_b, result);
    } else if (cast == BulletCast::Gjk) {
      btGjkConvexCast caster(shape_a, shape_b, &simplex);
      hit = caster.calcTimeOfImpact(from_a, to_a, from_b, to_b, result);
    } else {
      btSubsimplexConvexCast caster(shape_a, shape_b, &simplex);
      hit = caster.calcTimeOfImpact(from_a, to_a, from_b, to_b, result);
    }
    if (!hit) return r;
    r.hit = true;
    r.fraction = result.m_fraction;
    const Vec3 normal = from_bt(result.m_normal);
    if (normal.norm() > 0.5) {
      r.located = true;
      r.point = from_bt(result.m_hitPoint);
      r.normal = normal.normalized();
    }
  } catch (const std::exception& e) {
    r.status = Status::Error;
    r.message = e.what();
  }
  return r;
}

// ---------------------------------------------------------------------------------------------
// Dynamics

/// One scene body in Bullet: its shape in the principal frame of its inertia.
struct BulletBody {
  Mat3 principal = Mat3::Identity();  // Q: principal axes (columns) in body axes, det +1
  bool box = false;                   // a btBoxShape
  std::unique_ptr<btConvexShape> shape;
  std::unique_ptr<btRigidBody> body;
};

/// Principal axes Q (I_body = Q diag(lambda) Q^T, det Q = +1) and the principal moments.
void principal_axes(const Mat3& inertia, Mat3* q, Vec3* moments) {
  Eigen::SelfAdjointEigenSolver<Mat3> eig(inertia);
  if (eig.info() != Eigen::Success) throw std::runtime_error("inertia eigen-decomposition failed");
  *q = eig.eigenvectors();
  *moments = eig.eigenvalues();
  // A reflection would mirror the hull: make Q a proper rotation.
  if (q->determinant() < 0) q->col(0) = -q->col(0);
}

/// The engine's state of one body from Bullet's: undo the principal-frame rotation.
BodyFinal final_state(const std::string& name, const BulletBody& bb) {
  BodyFinal f;
  f.name = name;
  const btTransform& t = bb.body->getWorldTransform();
  f.position = from_bt(t.getOrigin());
  // Bullet's rotation is R_body * Q, so R_body = R_bt * Q^T.
  Quat q(Mat3(from_bt_basis(t.getBasis()) * bb.principal.transpose()));
  q.normalize();
  // One sign of the double cover, for reproducible output.
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  f.orientation = q;
  f.velocity = from_bt(bb.body->getLinearVelocity());
  f.angular_velocity = from_bt(bb.body->getAngularVelocity());  // world frame in both
  return f;
}

/// The radius of the largest sphere about the centre of mass inside the body's hull (m).
double inscribed_radius(const RigidBody& rb) {
  double inscribed = INFINITY;
  for (const Plane& p : rb.shape->planes())
    inscribed = std::min(inscribed, -p.distance(Vec3::Zero()));
  return inscribed;
}

/// The single-impulse settings of docs/references.md on the world's solver (`fair_world`).
void make_solver_fair(btDiscreteDynamicsWorld& world, const BulletSettings& settings) {
  btContactSolverInfo& info = world.getSolverInfo();
  // Restitution applies at any approach speed (default: none below 0.2 m/s).
  info.m_restitutionVelocityThreshold = settings.restitution_threshold;
  // Split impulse for every penetration depth (default: only below -0.04 m; shallower
  // penetration is fixed by Baumgarte, m_erp2 * depth / dt added to the velocity target):
  // position error is then removed by a separate push that adds no velocity.
  info.m_splitImpulse = 1;
  info.m_splitImpulsePenetrationThreshold = settings.split_impulse_threshold;
  if (settings.split_turn_erp >= 0) info.m_splitImpulseTurnErp = settings.split_turn_erp;
  // Warm starting set by the factor, never by clearing SOLVER_USE_WARMSTARTING: without that
  // flag solveGroupCacheFriendlyFinish skips writeBackContacts, so the manifold points would
  // never carry the applied impulses the events below are read from.
  info.m_warmstartingFactor = settings.warmstarting_factor;
  // Enough Gauss-Seidel iterations for multi-point manifolds to converge (default 10); a
  // single-point impact is exact after the first.
  info.m_numIterations = 100;
  info.m_erp2 = settings.contact_erp;
  info.m_globalCfm = settings.contact_cfm;
}

/// Scene body `i` as a Bullet body, in the principal frame of its inertia. Not yet in a world.
BulletBody make_bullet_body(const RigidBody& rb, int i, const WorldDefinition& scene,
                            const BulletSettings& settings) {
  const bool fair = settings.fair_world;
  BulletBody bb;
  // Bullet stores a diagonal local inertia only, so the hull is placed in the principal
  // frame of I_body (vertices Q^T v) and the body's rotation becomes R * Q. Bullet's own
  // calculateLocalInertia is the hull's bounding box's, hence supplied here.
  // A native box keeps the body axes: is_native_box guarantees a diagonal inertia there.
  Vec3 moments = Vec3::Zero();
  bb.box = native_box(rb, settings);
  if (bb.box) {
    if (!rb.is_static) moments = rb.inertia_body.diagonal();
  } else if (!rb.is_static) {
    principal_axes(rb.inertia_body, &bb.principal, &moments);
  }
  bb.shape = make_shape(rb, bb.principal.transpose(), settings);
  // Static bodies: mass 0 and zero inertia make Bullet's static object.
  const double mass = rb.is_static ? 0.0 : rb.mass;
  btRigidBody::btRigidBodyConstructionInfo ci(mass, nullptr, bb.shape.get(), to_bt(moments));
  ci.m_startWorldTransform = body_transform(rb, bb.principal);
  // Bullet combines restitution (and friction) as the product of the two bodies' values;
  // sqrt(e) on every body gives e for every pair (to 1 ulp), where "e on one body, 1 on the
  // rest" would give 1 between two of the rest.
  ci.m_restitution = std::sqrt(scene.sim.restitution);
  if (fair) {
    // Coulomb friction from the scene by the same product rule (the fair default is 0;
    // Bullet's body default is 0.5). Damping 0: Bullet's default, made explicit.
    ci.m_friction = std::sqrt(scene.sim.friction);
    ci.m_rollingFriction = 0;
    ci.m_spinningFriction = 0;
    ci.m_linearDamping = 0;
    ci.m_angularDamping = 0;
    ci.m_additionalDamping = false;
  }
  bb.body = std::make_unique<btRigidBody>(ci);
  bb.body->setUserIndex(i);
  if (!rb.is_static) {
    bb.body->setLinearVelocity(to_bt(rb.velocity));
    bb.body->setAngularVelocity(to_bt(rb.angular_velocity));
  }
  // Gyroscopic term: Bullet's default flag BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY is
  // kept. It advances Euler's equations I w' + w x I w = 0 in body axes by one Newton step
  // of implicit Euler, so a torque-free asymmetric body precesses (without it w stays
  // fixed in the world and angular momentum is not conserved). It is first order and
  // slightly dissipative (|L| drifts by ~1.2 dt per second here, see the test). The
  // explicit variant is explicit Euler clamped by m_maxGyroscopicForce; the implicit
  // world-frame one linearises about the world inertia. This one uses the diagonal local
  // inertia, which the principal frame above makes exact.
  if (fair) {
    // Never sleep: a slow body must keep integrating.
    bb.body->setActivationState(DISABLE_DEACTIVATION);
    // Contacts are solved once the hulls touch (default: any point within the breaking
    // threshold, i.e. before touching), so the impulse acts at contact (BulletSettings).
    bb.body->setContactProcessingThreshold(settings.processing_fraction * inscribed_radius(rb));
  }
  // Continuous collision as Bullet's own CCD demo sets it for its cubes (a motion threshold of
  // the half extent, a swept sphere of 0.9 of it), here from the hull's inscribed radius about
  // the centre of mass, so that the sphere stays inside any hull. A body moving further in a
  // step is swept from its centre; at a hit it is moved to the hit and keeps its velocity, and
  // the next step's contact responds.
  if (!rb.is_static && settings.ccd_motion_fraction > 0) {
    const double inscribed = inscribed_radius(rb);
    if (inscribed > 0 && std::isfinite(inscribed)) {
      bb.body->setCcdMotionThreshold(settings.ccd_motion_fraction * inscribed);
      bb.body->setCcdSweptSphereRadius(settings.ccd_sphere_fraction * inscribed);
    }
  }
  return bb;
}

/// Step `k` (time step dt) as the solver left it: every manifold point it used (within the
/// processing threshold; points beyond it were not solved and may keep an old impulse), given
/// to `recorder` with the impulse it applied to body A (the normal impulse and the friction
/// impulses along Bullet's lateral directions, the second only when the solver runs two); those
/// with a positive normal impulse are also the step's events, appended to `events`.
void read_step(const btCollisionDispatcher& dispatcher, const btContactSolverInfo& info, long k,
               double dt, const std::vector<std::string>& names,
               const std::vector<BulletBody>& bodies, const BulletSettings& settings,
               std::vector<CollisionEvent>& events, DynamicsRecorder& recorder) {
  const bool two_directions = (info.m_solverMode & SOLVER_USE_2_FRICTION_DIRECTIONS) != 0;
  for (int m = 0; m < dispatcher.getNumManifolds(); ++m) {
    const btPersistentManifold* manifold = dispatcher.getManifoldByIndexInternal(m);
    const int i0 = manifold->getBody0()->getUserIndex();
    const int i1 = manifold->getBody1()->getUserIndex();
    for (int p = 0; p < manifold->getNumContacts(); ++p) {
      const btManifoldPoint& cp = manifold->getContactPoint(p);
      if (cp.getDistance() > manifold->getContactProcessingThreshold()) continue;
      // On body 0: the normal (from body 1 toward body 0) and friction impulses; the pair is
      // ordered by scene index.
      Vec3 n = from_bt(cp.m_normalWorldOnB).normalized();
      Vec3 impulse = cp.getAppliedImpulse() * n +
                     cp.m_appliedImpulseLateral1 * from_bt(cp.m_lateralFrictionDir1);
      if (two_directions)
        impulse += cp.m_appliedImpulseLateral2 * from_bt(cp.m_lateralFrictionDir2);
      SolvedContact c;
      c.a = std::min(i0, i1);
      c.b = std::max(i0, i1);
      if (i0 > i1) {
        n = -n;
        impulse = -impulse;
      }
      c.point = 0.5 * (from_bt(cp.getPositionWorldOnA()) + from_bt(cp.getPositionWorldOnB()));
      c.normal = n;
      c.depth = std::max(0.0, -static_cast<double>(cp.getDistance()));
      c.impulse = impulse;
      recorder.contact_at_start(c);
      if (cp.getAppliedImpulse() <= 0) continue;
      CollisionEvent ev;
      ev.time = k * dt;  // detection runs at the start-of-step poses
      ev.step = k;
      ev.body_a = names[c.a];
      ev.body_b = names[c.b];
      ev.contact.normal = c.normal;
      ev.contact.depth = c.depth;
      ev.contact.point = c.point;
      ev.contact.feature = pair_feature(bodies[i0].box, bodies[i1].box, settings);
      ev.impulse = cp.getAppliedImpulse();  // N s, along the normal
      events.push_back(ev);
    }
  }
}

/// Throws when a body's state is not finite after step `k`: an error, not a result.
void check_finite(const std::vector<BulletBody>& bodies, const std::vector<std::string>& names,
                  long k) {
  for (size_t i = 0; i < bodies.size(); ++i) {
    const btRigidBody& b = *bodies[i].body;
    if (!std::isfinite(b.getWorldTransform().getOrigin().length2()) ||
        !std::isfinite(b.getLinearVelocity().length2()) ||
        !std::isfinite(b.getAngularVelocity().length2()))
      throw std::runtime_error("non-finite state of body " + names[i] + " at step " +
                               std::to_string(k + 1));
  }
}

/// Runs the scene in a btDiscreteDynamicsWorld. `settings.fair_world`: the single-impulse
/// settings of docs/references.md; otherwise Bullet's defaults for the world, solver and bodies
/// (the scene's shapes, masses, inertia, restitution and gravity are used either way).
DynamicsResult run_bullet_world(const WorldDefinition& scene, const DynamicsOptions& opt,
                                const BulletSettings& settings) {
  DynamicsResult result;
  try {
    const double dt = opt.dt > 0 ? opt.dt : scene.sim.dt;  // s
    if (!(dt > 0)) throw std::invalid_argument("time step must be > 0");
    const long steps = step_count(scene.sim.duration, dt);  // throws when uncountable

    btDefaultCollisionConfiguration configuration;
    btCollisionDispatcher dispatcher(&configuration);
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &configuration);
    // Polyhedral hulls take their axis from SAT (see make_shape).
    world.getDispatchInfo().m_enableSatConvex = settings.polyhedral_hulls && settings.sat_convex;
    // Bullet's default gravity is (0, -10, 0); the scene's is the input in both modes.
    world.setGravity(to_bt(scene.sim.gravity));
    if (settings.fair_world) make_solver_fair(world, settings);
    if (opt.budget > 0) world.getSolverInfo().m_numIterations = opt.budget;

    // Bodies: the engine's own (make_body), so hull, mass, centre of mass and inertia are
    // exactly the custom engine's.
    std::vector<BulletBody> bodies;
    bodies.reserve(scene.bodies.size());
    struct Remover {  // bodies leave the world before they are destroyed
      btDiscreteDynamicsWorld* world;
      std::vector<BulletBody>* bodies;
      ~Remover() {
        for (BulletBody& bb : *bodies)
          if (bb.body) world->removeRigidBody(bb.body.get());
      }
    } remover{&world, &bodies};
    std::vector<std::string> names;
    for (size_t i = 0; i < scene.bodies.size(); ++i) {
      const RigidBody rb = make_body(scene.bodies[i]);
      names.push_back(rb.name);
      bodies.push_back(make_bullet_body(rb, static_cast<int>(i), scene, settings));
      world.addRigidBody(bodies.back().body.get());
    }

    DynamicsRecorder recorder(result, opt, [&] {
      std::vector<BodyFinal> states;
      for (size_t i = 0; i < bodies.size(); ++i) states.push_back(final_state(names[i], bodies[i]));
      return states;
    });
    recorder.measure_contact_laws(scene);
    recorder.start();
    for (long k = 0; k < steps; ++k) {
      recorder.before_step(result.events);
      // One internal step of exactly dt (maxSubSteps = 0: no fixed 1/60 s sub-stepping and no
      // interpolated motion states).
      world.stepSimulation(dt, 0, dt);
      read_step(dispatcher, world.getSolverInfo(), k, dt, names, bodies, settings, result.events,
                recorder);
      // The first impulse: one event per manifold point, so the count is the events'.
      recorder.first_impulse_from_step(result.events, dt);
      check_finite(bodies, names, k);
      recorder.after_step(k + 1, (k + 1) * dt);
    }
    recorder.finish_laws();

    for (size_t i = 0; i < bodies.size(); ++i)
      result.finals.push_back(final_state(names[i], bodies[i]));
    result.status = Status::Ok;
  } catch (const std::exception& ex) {
    result = DynamicsResult();
    result.status = Status::Error;
    result.message = ex.what();
  }
  return result;
}

}  // namespace

BulletSettings bullet_native_settings() { return {}; }

BulletSettings bullet_hull_settings() {
  BulletSettings s;
  s.native_boxes = false;
  s.polyhedral_hulls = false;
  // The one-point hull keeps Bullet's push turn and solves overlapping points only: with one
  // point per pair there is no other side of a face to lift, and the full turn measured worse
  // on its incline slide (docs/references.md).
  s.processing_fraction = 0;
  s.split_turn_erp = -1;
  return s;
}

BulletSettings bullet_default_world_settings() {
  BulletSettings s = bullet_hull_settings();
  s.fair_world = false;
  s.ccd_motion_fraction = 0;
  return s;
}

const AtSettings<BulletSettings>& bullet_at_settings() {
  static const AtSettings<BulletSettings> entries = {
      [](const RigidBody& a, const RigidBody& b, const BulletSettings& settings) {
        return pair_query(a, b, settings);
      },
      run_bullet_world, pair_distance};
  return entries;
}

namespace {

BulletSettings bullet_sat_settings() {
  BulletSettings s;
  s.native_boxes = false;
  s.sat_convex = true;
  return s;
}

// The contact query, dynamics run and prebuilt query of one set-up. Prebuilt: each shape built
// once and kept (reference/prebuilt_cache.h; polyhedral features included), the query without
// the cost of building the shape, which the report shows apart; one cache per set-up and thread.
template <BulletSettings (*Settings)()>
ContactResult query(const RigidBody& a, const RigidBody& b) {
  return pair_query(a, b, Settings());
}
template <BulletSettings (*Settings)()>
DistanceResult distance_query(const RigidBody& a, const RigidBody& b) {
  return pair_distance(a, b, Settings());
}
template <BulletSettings (*Settings)(), BulletCast Cast>
ToiResult toi_query(const RigidBody& a, const RigidBody& b, double dt) {
  return pair_toi(a, b, dt, Settings(), Cast);
}
template <BulletSettings (*Settings)()>
ContactResult prebuilt_query(const RigidBody& a, const RigidBody& b) {
  thread_local ShapeCache cache;
  return pair_query(a, b, Settings(), &cache);
}
template <BulletSettings (*Settings)()>
ToiResult prebuilt_toi(const RigidBody& a, const RigidBody& b, double dt) {
  thread_local ShapeCache cache;
  return pair_toi(a, b, dt, Settings(), BulletCast::Continuous, &cache);
}
template <BulletSettings (*Settings)()>
DynamicsResult dynamics_run(const WorldDefinition& scene, const DynamicsOptions& opt) {
  return run_bullet_world(scene, opt, Settings());
}

MassResult bullet_hull_mass(const RigidBody& body);

// The budget studied: Bullet's sequential-impulse iterations (library default 10; the fair
// world's 100, make_solver_fair).
SolverBudget bullet_budget() {
  return {"m_numIterations (sequential-impulse iterations)", {1, 3, 10, 30, 100}, 10, 100};
}

// `bullet` mass: btBoxShape::calculateLocalInertia for boxes (the solid box's, exact), the hull
// routine below otherwise.
MassResult bullet_mass(const RigidBody& body) {
  if (!is_native_box(body)) return bullet_hull_mass(body);
  MassResult r;
  // Bullet's default margin is inside the box, so the routine sees the full extents.
  btBoxShape box(to_bt(0.5 * body.box_size));
  btVector3 inertia(0, 0, 0);
  box.calculateLocalInertia(body.mass, inertia);
  r.mass = body.mass;
  r.center_of_mass = Vec3::Zero();  // the box centre, which is_native_box puts at the origin
  r.inertia = from_bt(inertia).asDiagonal();
  r.message = "btBoxShape::calculateLocalInertia (solid box)";
  return r;
}

// `bullet-hull` mass: btConvexHullShape::calculateLocalInertia with its default margin (0.04 m):
// the inertia of the bounding box about the shape origin, each extent grown by 6 margins (the
// cached AABB, getAabb and the routine each add one on both sides); no centre of mass.
MassResult bullet_hull_mass(const RigidBody& body) {
  MassResult r;
  btConvexHullShape hull;
  for (const Vec3& v : body.shape->vertices()) hull.addPoint(to_bt(v), false);
  hull.recalcLocalAabb();
  // Left at Bullet's default collision margin, as a user of the library would have it.
  btVector3 inertia(0, 0, 0);
  hull.calculateLocalInertia(body.mass, inertia);
  r.mass = body.mass;
  r.center_of_mass = Vec3::Zero();  // Bullet takes the shape origin as the centre of mass
  r.inertia = from_bt(inertia).asDiagonal();
  r.message = "calculateLocalInertia, default margin " + std::to_string(hull.getMargin()) +
              " m: bounding-box inertia about the shape origin";
  return r;
}

// The contact softness Bullet's users tune, from `base`'s settings: the contact error reduction
// and constraint force mixing of btContactSolverInfo.
SoftContact bullet_soft(const BulletSettings& base) {
  return {{{"erp",
            "m_erp2: the share of a penetration the split impulse's push corrects per step",
            base.contact_erp,
            0.0,
            1.0,
            {0.05, 0.1, 0.4, 0.8, 1.0}},
           {"cfm",
            "m_globalCfm: constraint force mixing, softening every contact",
            base.contact_cfm,
            0.0,
            1.0,
            {1e-6, 1e-5, 1e-4, 1e-3, 3e-3, 1e-2, 3e-2, 1e-1}}},
          [base](const WorldDefinition& scene, const DynamicsOptions& opt,
                 const std::vector<double>& v) {
            BulletSettings s = base;
            s.contact_erp = v.at(0);
            s.contact_cfm = v.at(1);
            return run_bullet_world(scene, opt, s);
          }};
}

}  // namespace

const Adapter& bullet_adapter() {
  static const Adapter adapter = {
      {
          // Native boxes (btBoxShape, btBoxBoxDetector on two boxes), polyhedral hulls clipped
          // about the GJK + EPA axis otherwise, zero hull margin, the fair world.
          with_soft(with_budget(
                        {"bullet",
                         "Bullet 3.24 double: btBoxShape or polyhedral hull (clipped); fair world",
                         query<bullet_native_settings>, dynamics_run<bullet_native_settings>,
                         bullet_mass},
                        bullet_budget()),
                    bullet_soft(bullet_native_settings()))
              .measuring(distance_query<bullet_native_settings>)
              .sweeping(toi_query<bullet_native_settings, BulletCast::Continuous>)
              .drawn("#009E73", "o")
              .timed(2048, 2048),
          // Every body a zero-margin btConvexHullShape through GJK + EPA (one point).
          with_soft(with_budget({"bullet-hull",
                                 "Bullet 3.24 double: zero-margin hull GJK + EPA; fair world",
                                 query<bullet_hull_settings>, dynamics_run<bullet_hull_settings>,
                                 bullet_hull_mass},
                                bullet_budget()),
                    bullet_soft(bullet_hull_settings()))
              .measuring(distance_query<bullet_hull_settings>)
              .sweeping(toi_query<bullet_hull_settings, BulletCast::Continuous>)
              .drawn("#00543D", "s"),
          // Every body a polyhedral hull (boxes too), SAT + clipping; contact queries only.
          Backend{"bullet-sat", "Bullet 3.24 double: polyhedral hull SAT + clipping, boxes too",
                  query<bullet_sat_settings>, nullptr}
              .drawn("#7FD4B6", "D")
              .timed(512, 128),
      },
      {
          {"bullet",
           "prebuilt",
           "each btBoxShape or polyhedral hull built once and kept",
           prebuilt_query<bullet_native_settings>,
           {},
           false,
           nullptr,
           prebuilt_toi<bullet_native_settings>},
          {"bullet-hull",
           "prebuilt",
           "each btConvexHullShape built once and kept",
           prebuilt_query<bullet_hull_settings>,
           {},
           false,
           nullptr,
           prebuilt_toi<bullet_hull_settings>},
          {"bullet-hull",
           "gjk-cast",
           "btGjkConvexCast on the zero-margin hulls: translation only",
           nullptr,
           {},
           false,
           nullptr,
           toi_query<bullet_hull_settings, BulletCast::Gjk>},
          {"bullet-hull",
           "subsimplex-cast",
           "btSubsimplexConvexCast on the zero-margin hulls: translation only",
           nullptr,
           {},
           false,
           nullptr,
           toi_query<bullet_hull_settings, BulletCast::Subsimplex>},
          {"bullet-sat", "prebuilt", "each polyhedral hull built once and kept",
           prebuilt_query<bullet_sat_settings>},
      }};
  return adapter;
}

}  // namespace rbx
