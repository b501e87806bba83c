// Bullet 3.24 (double precision): native boxes (btBoxShape) and polyhedral hulls as its experts
// use them (`bullet`), the same-hull input of every backend (`bullet-hull`), polyhedral SAT on
// every hull (`bullet-sat`), and btDiscreteDynamicsWorld as a fair single-impulse reference.
#pragma once

#include "reference/backend.h"

namespace rbx {

/// How bodies become Bullet shapes and how the world is set up. Every field's choice is
/// measured against its alternatives in tests/reference/fair_settings_test.cpp.
struct BulletSettings {
  bool native_boxes = true;      // btBoxShape for is_native_box bodies; false: every body a hull
  bool polyhedral_hulls = true;  // initializePolyhedralFeatures: hulls clipped (manifolds)
  bool sat_convex = false;       // polyhedral hulls: the axis by SAT (false: by GJK + EPA)
  double box_margin = 0.04;      // m, btBoxShape's margin (inside the box: extents unchanged)
  double hull_margin = 0.0;      // m, btConvexHullShape's margin (outside the hull: inflates it)
  bool fair_world = true;        // the solver settings below; false: Bullet's defaults throughout
  double split_impulse_threshold = 1e30;  // m; Bullet splits where distance < this (BT_LARGE_FLOAT)
  double restitution_threshold = 0.0;     // m/s; no bounce below this approach speed
  double processing_threshold = 0.0;      // m; contacts solved once closer than this
};

/// `bullet`: native boxes, polyhedral hulls (GJK + EPA axis, clipped manifold), zero hull
/// margin, the fair world.
BulletSettings bullet_native_settings();
/// `bullet-hull`: every body a zero-margin btConvexHullShape through GJK + EPA, the fair world.
BulletSettings bullet_hull_settings();

/// `bullet`: contactPairTest on the native shapes (box-box: btBoxBoxDetector; otherwise the
/// polyhedral hulls clipped against each other about the GJK + EPA axis).
ContactResult bullet_contact(const RigidBody& a, const RigidBody& b);
/// `bullet-hull`: btConvexHullShape (margin 0) pair through GJK + EPA, one point.
ContactResult bullet_hull_contact(const RigidBody& a, const RigidBody& b);
/// `bullet-sat`: every body a polyhedral hull (boxes too), SAT + clipping.
ContactResult bullet_sat_contact(const RigidBody& a, const RigidBody& b);
/// `bullet`, `bullet-hull` and `bullet-sat` with each shape built once and kept (reference/
/// prebuilt_cache.h; polyhedral features included): variant "prebuilt", the same query without
/// the cost of building the shape (the report shows that cost apart).
ContactResult bullet_contact_prebuilt(const RigidBody& a, const RigidBody& b);
ContactResult bullet_hull_contact_prebuilt(const RigidBody& a, const RigidBody& b);
ContactResult bullet_sat_contact_prebuilt(const RigidBody& a, const RigidBody& b);
/// The contact query with explicit settings.
ContactResult bullet_contact_with(const RigidBody& a, const RigidBody& b,
                                  const BulletSettings& settings);
/// `bullet` mass: btBoxShape::calculateLocalInertia for boxes (the solid box's, exact), the
/// hull routine below otherwise.
MassResult bullet_mass(const RigidBody& body);
/// `bullet-hull` mass: btConvexHullShape::calculateLocalInertia with its default margin (0.04 m):
/// the inertia of the bounding box about the shape origin, each extent grown by 6 margins (the
/// cached AABB, getAabb and the routine each add one on both sides); no centre of mass.
MassResult bullet_hull_mass(const RigidBody& body);
/// `bullet` dynamics: btDiscreteDynamicsWorld on the native shapes, fair settings.
DynamicsResult bullet_dynamics(const Scene& scene, const DynamicsOptions& opt);
/// `bullet-hull` dynamics: the same world, every body a zero-margin GJK + EPA hull.
DynamicsResult bullet_hull_dynamics(const Scene& scene, const DynamicsOptions& opt);
/// The world with explicit settings.
DynamicsResult bullet_dynamics_with(const Scene& scene, const DynamicsOptions& opt,
                                    const BulletSettings& settings);
/// The hull world with Bullet's default settings (kept to pin the known defects they cause).
DynamicsResult bullet_dynamics_default_world(const Scene& scene, const DynamicsOptions& opt);

}  // namespace rbx
