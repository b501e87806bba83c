// ODE 0.16.2: dCreateBox for boxes and dCreateConvex otherwise (`ode`), or dCreateConvex for
// every body (`ode-hull`); dCollide, and dWorldStep with bounce = e.
#pragma once

#include "reference/backend.h"

namespace rbx {

/// How bodies become ODE geoms and how the world is set up. Every field's choice is measured
/// against its alternatives in tests/reference/fair_settings_test.cpp.
struct OdeSettings {
  bool native_boxes = true;  // dCreateBox for is_native_box bodies; false: every body convex
  double cfm = 1e-10;        // world constraint force mixing (ODE's default)
  double erp = 0.2;          // world error reduction parameter (ODE's default)
  // First friction direction along the contact's tangential slip (dContactFDir1), where there
  // is slip; false: both directions from dPlaneSpace (ODE's default), fixed whatever the slip.
  bool friction_along_slip = true;
  // The most contacts dCollide returns for a pair (1 to 32): dBoxBox's face manifold has up to
  // 8 points, culled by ODE to this many; the convex path returns what it finds.
  int max_contacts = 32;
  // m/s: the most a contact's position correction (ERP depth / dt) may push its bodies apart
  // (dWorldSetContactMaxCorrectingVel, ODE's remedy for "popping"); infinite: ODE's default.
  double max_correcting_vel = 0.1;
};

/// `ode-hull`: every body a dCreateConvex geom, ODE's default world.
OdeSettings ode_hull_settings();

/// ODE's backends: `ode` (dCreateBox for boxes, dBoxBox; dCreateConvex otherwise) and
/// `ode-hull` (dCreateConvex for every body, libccd MPR in Debian's build, one point); dCollide,
/// and dWorldStep with bounce = e; each with its "prebuilt" variant.
const Adapter& ode_adapter();
/// ODE's contact query (settings.native_boxes) and dynamics run at explicit settings.
const AtSettings<OdeSettings>& ode_at_settings();

}  // namespace rbx
