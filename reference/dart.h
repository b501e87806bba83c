// DART 6.12: a skeleton with a free joint per body, DART's boxed LCP constraint solver (Dantzig)
// over a collision detector of DART's (`dart`), or every body the same hull (`dart-hull`).
#pragma once

#include "reference/backend.h"

namespace rbx {

/// DART's collision detectors that can share a process with rbx: its own (primitives only, no
/// meshes) and FCL (meshes as triangle BVHs). Debian's DART Bullet detector links the
/// single-precision Bullet, whose symbols are those of the double-precision Bullet rbx links.
enum class DartDetector { Dart, Fcl };

/// "dart" | "fcl".
const char* to_string(DartDetector detector);

/// How bodies become DART shapes and how the world is set up. Every field's choice is measured
/// against its alternatives in tests/reference/fair_settings_test.cpp.
struct DartSettings {
  bool native_boxes = true;                        // BoxShape for is_native_box bodies; else a mesh
  DartDetector box_detector = DartDetector::Dart;  // when every body of the pair/world is a box
  DartDetector mesh_detector = DartDetector::Fcl;  // when some body is a mesh
  bool fcl_primitives = false;  // FCL's box for a BoxShape; false: a triangle mesh (DART's default)
  bool dantzig = true;          // the boxed LCP's Dantzig solver (DART's default); false: PGS
  double cfm =
      1e-9;          // ContactConstraint's constraint force mixing (DART's default 1e-5; its floor)
  double erp = 0.0;  // ContactConstraint's error reduction parameter (DART's default 0.01)
  // Each moving shape's first friction direction set, before every step, to the slip at its
  // contacts; false: DART's own basis (fixed whatever the slip).
  bool friction_along_slip = true;
};

/// `dart-hull`: every body a MeshShape of its hull, on the mesh detector.
DartSettings dart_hull_settings();

/// DART's backends: `dart` (BoxShape on DART's own detector when every body is a box, a
/// MeshShape of the hull on FCL otherwise) and `dart-hull` (every body a MeshShape on FCL), each
/// with its "prebuilt" variant; contact queries through the detector's collide, dynamics in a
/// simulation::World with the boxed LCP solver.
const Adapter& dart_adapter();

/// DART's contact query and dynamics run at explicit settings.
const AtSettings<DartSettings>& dart_at_settings();

}  // namespace rbx
