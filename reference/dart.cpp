// DART 6.12 adapter. Every body is a skeleton of one body node on a free joint (a static body's
// skeleton is immobile), with our mass and inertia about its centre of mass at the node's
// origin. `dart`: a box body is a BoxShape, any other a MeshShape of its hull; a world whose
// bodies are all boxes runs on DART's own detector (its box-box test, up to 4 points), any other
// on DART's FCL detector (DART's own collides no meshes). `dart-hull`: every body a MeshShape on
// the FCL detector. The world steps with DART's boxed LCP solver (Dantzig, PGS when Dantzig
// fails), one constraint per contact point with a friction pyramid of two directions, the first
// turned along each moving body's slip before every step (follow_slip).
//
// Conventions: DART's contact normal points from the second collision object to the first and
// its `force` (filled by the constraint solver) acts on the first; with A first both are ours.
// DART multiplies the two bodies' restitution coefficients and takes the smaller friction
// coefficient: each body gets sqrt(e) and mu, so a pair gets the scene's e and mu.
//
// Errors: DART reports through exceptions and dterr (printed, then it carries on); an exception
// becomes the backend's error, a non-finite state is named by the recorder. Aborts and endless
// loops are contained by the process isolation every library call runs in (reference/isolate.h).
#include "reference/dart.h"

#include <assimp/scene.h>

#include <cmath>
#include <dart/collision/CollisionGroup.hpp>
#include <dart/collision/CollisionObject.hpp>
#include <dart/collision/DistanceOption.hpp>
#include <dart/collision/DistanceResult.hpp>
#include <dart/collision/dart/DARTCollisionDetector.hpp>
#include <dart/collision/fcl/FCLCollisionDetector.hpp>
#include <dart/constraint/BoxedLcpConstraintSolver.hpp>
#include <dart/constraint/ConstraintSolver.hpp>
#include <dart/constraint/ContactConstraint.hpp>
#include <dart/constraint/DantzigBoxedLcpSolver.hpp>
#include <dart/constraint/PgsBoxedLcpSolver.hpp>
#include <dart/dynamics/BodyNode.hpp>
#include <dart/dynamics/BoxShape.hpp>
#include <dart/dynamics/FreeJoint.hpp>
#include <dart/dynamics/MeshShape.hpp>
#include <dart/dynamics/ShapeNode.hpp>
#include <dart/dynamics/SimpleFrame.hpp>
#include <dart/dynamics/Skeleton.hpp>
#include <dart/simulation/World.hpp>
#include <exception>
#include <map>
#include <memory>
#include <mutex>
#include <utility>

#include "reference/dynamics_recorder.h"
#include "reference/prebuilt_cache.h"

namespace rbx {

namespace dd = dart::dynamics;
namespace dc = dart::collision;

const char* to_string(DartDetector detector) {
  switch (detector) {
    case DartDetector::Dart:
      return "dart";
    case DartDetector::Fcl:
      return "fcl";
  }
  return "dart";
}

namespace {

// At most this many contact points per query (as for the other libraries).
constexpr std::size_t kMaxContacts = 32;
// A contact point closing slower than this (m/s) is not an impact: after an e = 0 impact or at
// rest DART's CFM (1e-5) leaves the contact closing at a small fraction of the impact speed.
constexpr double kClosingSpeed = 1e-6;

// An assimp scene of one triangle mesh: the hull's vertices and outward triangles, as DART
// reads a mesh file. Debian's assimp is built without ASSIMP_DOUBLE_PRECISION, so its ai_real is
// float: a MeshShape's vertices are the hull's rounded to float (6e-8 relative), whatever feeds
// DART a mesh. MeshShape owns it (aiReleaseImport deletes a scene no importer made).
const aiScene* hull_scene(const ConvexPolyhedron& hull) {
  auto* mesh = new aiMesh();
  const auto& v = hull.vertices();
  mesh->mNumVertices = static_cast<unsigned>(v.size());
  mesh->mVertices = new aiVector3D[v.size()];
  for (std::size_t i = 0; i < v.size(); ++i)
    mesh->mVertices[i] = aiVector3D(static_cast<ai_real>(v[i].x()), static_cast<ai_real>(v[i].y()),
                                    static_cast<ai_real>(v[i].z()));
  const auto& tris = hull.triangles();
  mesh->mNumFaces = static_cast<unsigned>(tris.size());
  mesh->mFaces = new aiFace[tris.size()];
  for (std::size_t t = 0; t < tris.size(); ++t) {
    aiFace& f = mesh->mFaces[t];
    f.mNumIndices = 3;
    f.mIndices = new unsigned[3];
    for (int k = 0; k < 3; ++k) f.mIndices[k] = static_cast<unsigned>(tris[t][k]);
  }
  mesh->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  auto* scene = new aiScene();
  scene->mNumMeshes = 1;
  scene->mMeshes = new aiMesh* [1] { mesh };
  scene->mRootNode = new aiNode();
  scene->mRootNode->mNumMeshes = 1;
  scene->mRootNode->mMeshes = new unsigned[1]{0};
  return scene;
}

// The body's DART shape: a BoxShape when `native` and the body is one (is_native_box), else a
// MeshShape of its hull.
dd::ShapePtr make_shape(const RigidBody& b, bool native) {
  if (native && is_native_box(b)) return std::make_shared<dd::BoxShape>(b.box_size);
  return std::make_shared<dd::MeshShape>(Eigen::Vector3d::Ones(), hull_scene(*b.shape));
}

// A body's pose as DART's transform.
Eigen::Isometry3d transform_of(const RigidBody& b) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = b.orientation.normalized().toRotationMatrix();
  t.translation() = b.position;
  return t;
}

// A new detector of the given kind. FCL's: its primitives for primitive shapes (boxes) when
// `primitives`, else every shape as a triangle mesh (DART's default).
std::shared_ptr<dc::CollisionDetector> make_detector(DartDetector kind, bool primitives) {
  if (kind == DartDetector::Dart) return dc::DARTCollisionDetector::create();
  auto fcl = dc::FCLCollisionDetector::create();
  fcl->setPrimitiveShapeType(primitives ? dc::FCLCollisionDetector::PRIMITIVE
                                        : dc::FCLCollisionDetector::MESH);
  return fcl;
}

// The detector a pair of bodies (or a world of them) takes: the box detector when every body is
// a BoxShape, else the mesh detector.
DartDetector detector_for(bool all_boxes, const DartSettings& s) {
  return all_boxes ? s.box_detector : s.mesh_detector;
}

// Our contact from DART's: normal from object 2 to object 1, so flipped when A is object 2.
ContactPoint convert_contact(const dc::Contact& c, bool a_first, const char* feature) {
  ContactPoint p;
  p.point = c.point;
  p.normal = a_first ? c.normal : Vec3(-c.normal);
  p.depth = c.penetrationDepth;
  p.feature = feature;
  return p;
}

// One body's shape placed in a frame of its own, and the detector's group holding it.
struct PlacedShape {
  std::shared_ptr<dd::SimpleFrame> frame;
  dd::ShapePtr shape;
};

PlacedShape place_shape(const RigidBody& b, bool native) {
  PlacedShape p;
  p.shape = make_shape(b, native);
  p.frame = std::make_shared<dd::SimpleFrame>(dd::Frame::World(), b.name);
  p.frame->setShape(p.shape);
  return p;
}

// A query's shapes and detector, built once per pair of scene shapes in the prebuilt variants.
struct QueryPair {
  PlacedShape a, b;
  std::shared_ptr<dc::CollisionDetector> detector;
  std::unique_ptr<dc::CollisionGroup> group_a, group_b;
  const char* feature = "mesh";
};

std::shared_ptr<QueryPair> make_query_pair(const RigidBody& a, const RigidBody& b,
                                           const DartSettings& s) {
  auto q = std::make_shared<QueryPair>();
  q->a = place_shape(a, s.native_boxes);
  q->b = place_shape(b, s.native_boxes);
  const bool boxes = q->a.shape->is<dd::BoxShape>() && q->b.shape->is<dd::BoxShape>();
  const DartDetector kind = detector_for(boxes, s);
  q->detector = make_detector(kind, s.fcl_primitives);
  q->group_a = q->detector->createCollisionGroup(q->a.frame.get());
  q->group_b = q->detector->createCollisionGroup(q->b.frame.get());
  q->feature = boxes ? (kind == DartDetector::Dart ? "box-box" : "box-box (fcl)") : to_string(kind);
  return q;
}

// The detector's collide on the pair at the bodies' poses.
ContactResult query(QueryPair& q, const RigidBody& a, const RigidBody& b) {
  ContactResult r;
  try {
    q.a.frame->setRelativeTransform(transform_of(a));
    q.b.frame->setRelativeTransform(transform_of(b));
    dc::CollisionOption option(true, kMaxContacts);
    dc::CollisionResult result;
    q.detector->collide(q.group_a.get(), q.group_b.get(), option, &result);
    for (const dc::Contact& c : result.getContacts()) {
      const bool a_first = c.collisionObject1->getShapeFrame() == q.a.frame.get();
      r.contacts.push_back(convert_contact(c, a_first, q.feature));
    }
  } catch (const std::exception& e) {
    return {Status::Error, std::string("DART collide: ") + e.what(), {}};
  }
  return reject_undefined_normals(std::move(r), std::string("DART collide (") + q.feature + ")");
}

ContactResult contact_query(const RigidBody& a, const RigidBody& b, const DartSettings& s) {
  auto q = make_query_pair(a, b, s);
  return query(*q, a, b);
}
// DART's distance query: CollisionDetector::distance with nearest points, on its FCL detector
// whatever the pair (DART's own detector computes no distance: DARTCollisionDetector::distance
// warns and returns 0), with the set-up's shapes (BoxShape or MeshShape). The nearest points are
// in the world frame, nearestPoint1 on shapeFrame1, which need not be A's. DART clamps the
// distance at the option's lower bound (0): an overlapping pair reads 0, and a mesh inside
// another reads the distance between their surfaces; neither is told apart from a touch.
DistanceResult distance_query(const RigidBody& a, const RigidBody& b, const DartSettings& s) {
  DistanceResult r;
  try {
    PlacedShape pa = place_shape(a, s.native_boxes), pb = place_shape(b, s.native_boxes);
    pa.frame->setRelativeTransform(transform_of(a));
    pb.frame->setRelativeTransform(transform_of(b));
    auto detector = make_detector(DartDetector::Fcl, s.fcl_primitives);
    auto group_a = detector->createCollisionGroup(pa.frame.get());
    auto group_b = detector->createCollisionGroup(pb.frame.get());
    dc::DistanceResult result;
    detector->distance(group_a.get(), group_b.get(), dc::DistanceOption(true), &result);
    if (!result.found()) {
      r.status = Status::Error;
      r.message = "DART distance found no shape pair";
      return r;
    }
    const bool a_first = result.shapeFrame1 == pa.frame.get();
    if (pa.shape->is<dd::MeshShape>() || pb.shape->is<dd::MeshShape>())
      r.message = "MeshShape vertices rounded to float (assimp's ai_real)";
    r.distance = result.minDistance;
    r.point_a = a_first ? result.nearestPoint1 : result.nearestPoint2;
    r.point_b = a_first ? result.nearestPoint2 : result.nearestPoint1;
  } catch (const std::exception& e) {
    r.status = Status::Error;
    r.message = std::string("DART distance: ") + e.what();
  }
  return r;
}

}  // namespace

DartSettings dart_hull_settings() {
  DartSettings s;
  s.native_boxes = false;
  return s;
}

namespace {

// One scene body in the DART world: its skeleton's node and the shape node that collides.
struct DartBody {
  dd::SkeletonPtr skeleton;
  dd::BodyNode* node = nullptr;
  dd::FreeJoint* joint = nullptr;
};

// Adds scene body `b` to `world` as a skeleton with a free joint; restitution sqrt(e) and
// friction mu on its shape (DART combines a pair's by product and by minimum).
DartBody add_body(dart::simulation::World& world, const RigidBody& b, bool native, double e,
                  double mu) {
  DartBody d;
  d.skeleton = dd::Skeleton::create(b.name);
  auto pair = d.skeleton->createJointAndBodyNodePair<dd::FreeJoint>();
  d.joint = pair.first;
  d.node = pair.second;
  d.node->setInertia(dd::Inertia(b.mass, Eigen::Vector3d::Zero(), b.inertia_body));
  auto* shape_node =
      d.node->createShapeNodeWith<dd::CollisionAspect, dd::DynamicsAspect>(make_shape(b, native));
  shape_node->getDynamicsAspect()->setRestitutionCoeff(std::sqrt(std::max(e, 0.0)));
  shape_node->getDynamicsAspect()->setFrictionCoeff(mu);
  d.joint->setTransform(transform_of(b));
  d.joint->setLinearVelocity(b.velocity);
  d.joint->setAngularVelocity(b.angular_velocity);
  if (b.is_static) d.skeleton->setMobile(false);
  world.addSkeleton(d.skeleton);
  return d;
}

// State of scene body `b` from its node (a static body keeps its scene state).
BodyFinal read_state(const RigidBody& b, const DartBody& d) {
  BodyFinal f;
  f.name = b.name;
  if (b.is_static) {
    f.position = b.position;
    f.orientation = b.orientation;
    return f;
  }
  const Eigen::Isometry3d& t = d.node->getWorldTransform();
  f.position = t.translation();
  f.orientation = Quat(t.linear()).normalized();
  f.velocity = d.node->getLinearVelocity();
  f.angular_velocity = d.node->getAngularVelocity();
  return f;
}

// One contact point of a step: scene indices (a < b), our contact, its impulse on a, and the
// normal speed of a relative to b before the step (< 0: closing).
struct StepContact {
  int a = 0, b = 0;
  ContactPoint contact;
  Vec3 impulse = Vec3::Zero();
  double approach = 0.0;
};

// The step's contacts from the world's last collision result, in scene order.
std::vector<StepContact> step_contacts(const dart::simulation::World& world,
                                       const std::map<const dd::ShapeFrame*, int>& index,
                                       const std::vector<BodyFinal>& before, double dt,
                                       const char* feature) {
  std::vector<StepContact> out;
  for (const dc::Contact& c : world.getLastCollisionResult().getContacts()) {
    const int i1 = index.at(c.collisionObject1->getShapeFrame());
    const int i2 = index.at(c.collisionObject2->getShapeFrame());
    StepContact s;
    s.a = std::min(i1, i2);
    s.b = std::max(i1, i2);
    const bool a_first = i1 < i2;
    s.contact = convert_contact(c, a_first, feature);
    // `force` acts on object 1 over the step.
    s.impulse = (a_first ? c.force : Vec3(-c.force)) * dt;
    const Vec3& p = s.contact.point;
    auto velocity = [&](int i) {
      return Vec3(before[i].velocity + before[i].angular_velocity.cross(p - before[i].position));
    };
    s.approach = (velocity(s.a) - velocity(s.b)).dot(s.contact.normal);
    out.push_back(s);
  }
  return out;
}

// Events of a step (append_pair_events).
void pair_events(const std::vector<StepContact>& contacts, const std::vector<RigidBody>& bodies,
                 long step, double dt, std::vector<CollisionEvent>& events) {
  std::vector<PairPoint> points;
  for (const StepContact& s : contacts)
    points.push_back(
        {s.a, s.b, s.contact, s.impulse.dot(s.contact.normal), s.approach < -kClosingSpeed});
  append_pair_events(points, bodies, step, dt, events);
}

// DART's friction is a pyramid of two rows per contact, each bounded by mu times the normal
// impulse; with its basis fixed, a slip along neither row meets a friction force of up to
// sqrt(2) mu N that is not against the slip. Its first direction is a per-shape setting,
// read when a step builds its contact constraints, so before each step every moving body's
// shape gets the slip at its contacts at this step's positions (the sum over them of its
// tangential velocity relative to the other body): a sliding body's first row then runs against
// its slip. Below kStickSpeed the setting is cleared (DART's own basis). One direction per
// shape: a body that slips different ways at different contacts (spinning on its patch, pressed
// between two others) gets their sum, and the pyramid's error stays there. The world is collided
// here, once more than the step does, rather than reusing the last step's contacts: a landing's
// first contact step would otherwise run on DART's own basis.
void follow_slip(dart::simulation::World& world, const std::vector<DartBody>& dbodies,
                 const std::map<const dd::ShapeFrame*, int>& index,
                 const std::vector<BodyFinal>& now) {
  dc::CollisionResult result;
  auto* solver = world.getConstraintSolver();
  solver->getCollisionGroup()->collide(solver->getCollisionOption(), &result);
  std::vector<Vec3> slip(dbodies.size(), Vec3::Zero());
  for (const dc::Contact& c : result.getContacts()) {
    const int i1 = index.at(c.collisionObject1->getShapeFrame());
    const int i2 = index.at(c.collisionObject2->getShapeFrame());
    auto velocity = [&](int i) {
      return Vec3(now[i].velocity + now[i].angular_velocity.cross(c.point - now[i].position));
    };
    const Vec3 n = c.normal.normalized();
    const Vec3 relative = velocity(i1) - velocity(i2);
    const Vec3 tangential = relative - relative.dot(n) * n;
    slip[i1] += tangential;
    slip[i2] -= tangential;
  }
  for (std::size_t i = 0; i < dbodies.size(); ++i) {
    if (!dbodies[i].skeleton->isMobile()) continue;
    auto* aspect = dbodies[i].node->getShapeNode(0)->getDynamicsAspect();
    aspect->setFirstFrictionDirectionFrame(dd::Frame::World());
    aspect->setFirstFrictionDirection(slip[i].norm() > kStickSpeed ? Vec3(slip[i].normalized())
                                                                   : Vec3::Zero());
  }
}

DynamicsResult dart_dynamics_with(const WorldDefinition& scene, const DynamicsOptions& opt,
                                  const DartSettings& settings) {
  // ContactConstraint's parameters are process-wide statics: one DART world at a time.
  static std::mutex world_lock;
  const std::lock_guard<std::mutex> lock(world_lock);
  DynamicsResult r;
  const double dt = opt.dt > 0.0 ? opt.dt : scene.sim.dt;
  if (!(dt > 0.0)) return {Status::Error, "DART: time step must be > 0", {}, {}, {}, {}, {}};
  const long steps = step_count(scene.sim.duration, dt);  // throws when uncountable
  const std::vector<RigidBody> bodies = make_bodies(scene);
  try {
    dart::constraint::ContactConstraint::setConstraintForceMixing(settings.cfm);
    dart::constraint::ContactConstraint::setErrorReductionParameter(settings.erp);
    auto world = dart::simulation::World::create();
    world->setGravity(scene.sim.gravity);
    world->setTimeStep(dt);
    // A studied budget (dart_budget) runs PGS with that many iterations.
    namespace cs = dart::constraint;
    if (opt.budget > 0 || !settings.dantzig) {
      auto pgs = std::make_shared<cs::PgsBoxedLcpSolver>();
      cs::PgsBoxedLcpSolver::Option o;
      if (opt.budget > 0) o.mMaxIteration = opt.budget;
      pgs->setOption(o);
      world->setConstraintSolver(std::make_unique<cs::BoxedLcpConstraintSolver>(pgs));
    }
    bool all_boxes = true;
    for (const RigidBody& b : bodies)
      all_boxes = all_boxes && settings.native_boxes && is_native_box(b);
    const DartDetector kind = detector_for(all_boxes, settings);
    world->getConstraintSolver()->setCollisionDetector(
        make_detector(kind, settings.fcl_primitives));
    const char* feature = all_boxes && kind == DartDetector::Dart ? "box-box" : to_string(kind);

    std::vector<DartBody> dbodies;
    std::map<const dd::ShapeFrame*, int> index;
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      dbodies.push_back(add_body(*world, bodies[i], settings.native_boxes, scene.sim.restitution,
                                 scene.sim.friction));
      index[dbodies.back().node->getShapeNode(0)] = static_cast<int>(i);
    }
    auto read_states = [&] {
      std::vector<BodyFinal> states;
      for (std::size_t i = 0; i < bodies.size(); ++i)
        states.push_back(read_state(bodies[i], dbodies[i]));
      return states;
    };
    DynamicsRecorder recorder(r, opt, read_states);
    recorder.measure_contact_laws(scene);
    recorder.start();
    for (long step = 0; step < steps; ++step) {
      recorder.before_step(r.events);
      const std::vector<BodyFinal> before = read_states();
      if (settings.friction_along_slip && scene.sim.friction > 0.0)
        follow_slip(*world, dbodies, index, before);
      world->step();
      const std::vector<StepContact> contacts = step_contacts(*world, index, before, dt, feature);
      pair_events(contacts, bodies, step, dt, r.events);
      if (const CollisionEvent* first = recorder.first_new_event(r.events)) {
        int points = 0;
        for (const StepContact& s : contacts)
          if (bodies[s.a].name == first->body_a && bodies[s.b].name == first->body_b) ++points;
        recorder.first_impulse_from_event(*first, dt, points);
      }
      for (const StepContact& s : contacts) {
        SolvedContact c;
        c.a = s.a;
        c.b = s.b;
        c.point = s.contact.point;
        c.normal = s.contact.normal;
        c.depth = s.contact.depth;
        c.impulse = s.impulse;
        recorder.contact_at_start(c);
      }
      recorder.after_step(step + 1, (step + 1) * dt);
    }
    recorder.finish("DART");
  } catch (const std::exception& e) {
    r.status = Status::Error;
    r.message = std::string("DART: ") + e.what();
  }
  return r;
}

// DART's own mass properties of the body's shape for the body's mass: Shape::computeInertia and
// getVolume (a MeshShape's are its bounding box's). DART computes no centre of mass: a shape's
// is its frame's origin, here the body's centre of mass.
MassResult mass_of(const RigidBody& b, bool native) {
  MassResult m;
  try {
    const dd::ShapePtr shape = make_shape(b, native);
    m.mass = b.mass;
    m.volume = shape->getVolume();
    m.inertia = shape->computeInertia(b.mass);
    m.message = shape->is<dd::BoxShape>() ? "BoxShape::computeInertia"
                                          : "MeshShape::computeInertia (its bounding box)";
  } catch (const std::exception& e) {
    return {Status::Error, std::string("DART: ") + e.what()};
  }
  return m;
}

// `dart` and `dart-hull`: a new detector and shapes per query, as the other adapters do.
ContactResult dart_contact(const RigidBody& a, const RigidBody& b) {
  return contact_query(a, b, DartSettings{});
}

ContactResult dart_hull_contact(const RigidBody& a, const RigidBody& b) {
  return contact_query(a, b, dart_hull_settings());
}

// Variant "prebuilt": the pair's shapes, frames, detector and groups built once and kept.
ContactResult prebuilt_query(const RigidBody& a, const RigidBody& b, const DartSettings& s,
                             PrebuiltCache<std::shared_ptr<QueryPair>>& cache) {
  std::shared_ptr<QueryPair>& q =
      cache.get(a.shape, b.shape, [&] { return make_query_pair(a, b, s); });
  return query(*q, a, b);
}

ContactResult dart_contact_prebuilt(const RigidBody& a, const RigidBody& b) {
  thread_local PrebuiltCache<std::shared_ptr<QueryPair>> cache;
  return prebuilt_query(a, b, DartSettings{}, cache);
}

ContactResult dart_hull_contact_prebuilt(const RigidBody& a, const RigidBody& b) {
  thread_local PrebuiltCache<std::shared_ptr<QueryPair>> cache;
  return prebuilt_query(a, b, dart_hull_settings(), cache);
}

DynamicsResult dart_dynamics(const WorldDefinition& scene, const DynamicsOptions& opt) {
  return dart_dynamics_with(scene, opt, DartSettings{});
}

DynamicsResult dart_hull_dynamics(const WorldDefinition& scene, const DynamicsOptions& opt) {
  return dart_dynamics_with(scene, opt, dart_hull_settings());
}

// The budget studied: PGS iterations of the boxed LCP (DART's PGS default: 30). rbx runs
// Dantzig (a pivoting solve: no iteration count), so the study shows what PGS gives up.
SolverBudget dart_budget() {
  return {"PgsBoxedLcpSolver iterations (configured: Dantzig, exact)", {5, 10, 30, 100}, 30, 0};
}

}  // namespace

const AtSettings<DartSettings>& dart_at_settings() {
  static const AtSettings<DartSettings> entries = {contact_query, dart_dynamics_with};
  return entries;
}

// The contact softness DART's ContactConstraint exposes, from `base`'s settings: its error
// reduction (ERP) and constraint force mixing (CFM, floored by DART at 1e-9).
SoftContact dart_soft(const DartSettings& base) {
  return {{{"erp",
            "ContactConstraint's error reduction parameter",
            base.erp,
            0.0,
            1.0,
            {0.0, 0.01, 0.1, 0.2, 0.4}},
           {"cfm",
            "ContactConstraint's constraint force mixing (its floor 1e-9)",
            base.cfm,
            1e-9,
            1.0,
            {1e-9, 1e-7, 1e-5, 1e-3, 1e-2, 3e-2, 1e-1}}},
          [base](const WorldDefinition& scene, const DynamicsOptions& opt,
                 const std::vector<double>& v) {
            DartSettings s = base;
            s.erp = v.at(0);
            s.cfm = v.at(1);
            return dart_dynamics_with(scene, opt, s);
          }};
}

const Adapter& dart_adapter() {
  static const Adapter adapter = {
      {
          with_soft(
              with_budget({"dart",
                           "DART 6.12 BoxShape on DART's detector (all boxes) or MeshShape on FCL; "
                           "boxed LCP (Dantzig)",
                           dart_contact, dart_dynamics,
                           [](const RigidBody& b) { return mass_of(b, true); }},
                          dart_budget()),
              dart_soft(DartSettings{}))
              .measuring([](const RigidBody& a, const RigidBody& b) {
                return distance_query(a, b, DartSettings{});
              })
              .drawn("#999933", "o")
              .timed(2048, 512),
          with_soft(with_budget(
                        {"dart-hull", "DART 6.12 MeshShape of the hull on FCL; boxed LCP (Dantzig)",
                         dart_hull_contact, dart_hull_dynamics,
                         [](const RigidBody& b) { return mass_of(b, false); }},
                        dart_budget()),
                    dart_soft(dart_hull_settings()))
              .measuring([](const RigidBody& a, const RigidBody& b) {
                return distance_query(a, b, dart_hull_settings());
              })
              .drawn("#5C5C1F", "s"),
      },
      {
          // DART: BoxShapes on its own detector for the box pair, meshes on FCL for the hulls.
          {"dart",
           "prebuilt",
           "each pair's shapes, detector and groups built once and kept",
           dart_contact_prebuilt,
           {2048, 512}},
          {"dart-hull", "prebuilt", "each pair's meshes, detector and groups built once and kept",
           dart_hull_contact_prebuilt},
      }};
  return adapter;
}

}  // namespace rbx
