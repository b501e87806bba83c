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
  // m, btBoxShape's margin (inside the box: extents unchanged); < 0: the constructor's, Bullet's
  // 0.04 lowered to a tenth of the smallest half extent for small boxes (setSafeMargin)
  double box_margin = -1.0;
  double hull_margin = 0.0;  // m, btConvexHullShape's margin (outside the hull: inflates it)
  bool fair_world = true;    // the solver settings below; false: Bullet's defaults throughout
  double split_impulse_threshold = 1e30;  // m; Bullet splits where distance < this (BT_LARGE_FLOAT)
  // The share of the push's rotation applied with its translation (Bullet's default 0.1): the
  // split impulse solves each point's push for the whole rigid motion, and applying only a tenth
  // of its turn leaves the corners of a resting face corrected unequally, which tilts a sliding
  // box and delays its rest; 1 applies the push as solved (`bullet`). < 0: Bullet's own
  // (`bullet-hull`).
  double split_turn_erp = 1.0;
  double restitution_threshold = 0.0;  // m/s; no bounce below this approach speed
  // A manifold point is solved once its distance is at most this fraction of the body's
  // inscribed radius (the smaller of the pair's). A hair above zero (`bullet`): the split
  // impulse's push, solved point by point, lifts one side of a resting face a little past zero
  // while the other side is still inside, and a point dropped there lets the box hop and creep
  // down an incline; far below the gap an approaching body leaves between two steps, so an
  // impact is still solved once the bodies overlap. 0 (`bullet-hull`, the one-point hull's
  // row): only overlapping points. Bullet's default solves every point within the breaking
  // threshold, before the bodies touch.
  double processing_fraction = 2e-7;
  // Continuous collision (Bullet's CCD): a body moving more than this fraction of its inscribed
  // radius in a step is swept, as a sphere of `ccd_sphere_fraction` of that radius, and stopped
  // at the first hit; 0: off (Bullet's default).
  double ccd_motion_fraction = 1.0;
  double ccd_sphere_fraction = 0.9;
  // The contact softness Bullet's users tune (btContactSolverInfo), at Bullet's own values unless
  // a fit sets them: the share of a penetration the split impulse's push corrects per step
  // (m_erp2) and the constraint force mixing that softens every contact (m_globalCfm, per unit
  // of time step as Bullet scales it).
  double contact_erp = 0.2;
  double contact_cfm = 0.0;
  // The share of each contact point's last-step impulses its solve starts from (Bullet's own
  // 0.85). 0: every step's solve starts from zero; started from the last step's friction, a
  // sliding box whose corner loads shift keeps friction that step no longer has, and stops off
  // Coulomb's slide.
  double warmstarting_factor = 0.0;
};

/// `bullet`: native boxes, polyhedral hulls (GJK + EPA axis, clipped manifold), zero hull
/// margin, the fair world.
BulletSettings bullet_native_settings();
/// `bullet-hull`: every body a zero-margin btConvexHullShape through GJK + EPA, the fair world.
BulletSettings bullet_hull_settings();
/// The hull world with Bullet's default settings throughout (kept to pin the known defects they
/// cause).
BulletSettings bullet_default_world_settings();

/// Bullet's backends: `bullet` (native boxes, polyhedral hulls clipped about the GJK + EPA axis),
/// `bullet-hull` (every body a zero-margin GJK + EPA hull, one point) and `bullet-sat` (every
/// body a polyhedral hull, SAT + clipping), each with its "prebuilt" variant; contact queries
/// through contactPairTest, dynamics in btDiscreteDynamicsWorld with the fair settings.
const Adapter& bullet_adapter();

/// Bullet's contact query and world at explicit settings.
const AtSettings<BulletSettings>& bullet_at_settings();

}  // namespace rbx
