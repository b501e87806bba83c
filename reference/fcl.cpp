// FCL 0.7.0 adapters (double): `fcl` (fcl::Box for box bodies, so two boxes meet in
// boxBoxIntersect, up to 4 points; Convex otherwise; GST_LIBCCD), `fcl-hull` (every body a
// Convex, GST_LIBCCD: libccd MPR), signed distance (GJK + EPA), Convex with GST_INDEP (defects
// passed on). The former `fcl-box` (Box-Box only) is what `fcl` now runs on two boxes.
//
// FCL's conventions, read from the 0.7.0 headers and confirmed by probes (see
// tests/reference/fcl_test.cpp):
//   - fcl::Contact::normal points from o1 (A) toward o2 (B), world frame ("pointing from o1 to
//     o2", contact.h); penetration_depth is positive; pos is in the world frame, about the
//     midpoint of the overlap. Ours points from B toward A, so every normal is negated here.
//   - DistanceResult has no normal in 0.7. With enable_signed_distance on two OT_GEOM shapes and
//     GST_LIBCCD, min_distance = -depth when penetrating and nearest_points[0] (on A) and [1] (on
//     B) are world-frame points (gjk_libccd-inl.h, GJKDistanceImpl: "in the world frame"; a
//     rotated probe agrees). When penetrating, p0 - p1 = depth * (A -> B), so our normal is
//     (p1 - p0) / |p1 - p0|.
//   - GST_INDEP on Convex (gjk_solver_indep-inl.h, ShapeIntersectIndepImpl) returns epa.normal,
//     computed in A's local frame and never rotated to the world, and depth = -epa.depth. Both
//     are defects: passed on unpatched, labelled in ContactResult::message.
// Any FCL query may throw std::logic_error from its libccd extension on degenerate polytopes;
// that becomes status Error, never a crash.
#include "reference/fcl.h"

#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/math/motion/interp_motion.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/continuous_collision.h>
#include <fcl/narrowphase/distance.h>

#include <cmath>
#include <exception>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "reference/prebuilt_cache.h"

namespace rbx {
namespace {

// Room for every contact a shape pair can produce: Convex-Convex gives 1 (MPR or EPA),
// boxBoxIntersect at most 4. Larger than both so that FCL never culls a contact by depth.
constexpr std::size_t kMaxContacts = 8;

// Nearest points closer than this (m) define no direction: FCL's signed distance at exactly
// touching returns p0 == p1. Far below any depth a scene resolves, far above round-off of
// unit-scale coordinates (~1e-16 m).
constexpr double kCoincidentPoints = 1e-12;

// Note attached to every fcl-indep result (docs/references.md, "Known wrong answers").
constexpr const char* kIndepDefect =
    "FCL 0.7 GST_INDEP on Convex: normal left in A's local frame (not rotated to world) and "
    "depth negative; passed on unpatched (known defects)";

/// World pose of the body frame as an FCL transform.
fcl::Transform3d to_fcl(const Pose& pose) {
  fcl::Transform3d tf = fcl::Transform3d::Identity();
  tf.linear() = pose.rotation();
  tf.translation() = pose.position;
  return tf;
}

/// The body's hull as an fcl::Convex in the body frame: one face per triangle, encoded as FCL's
/// polygon array [3, i, j, k, 3, ...] with counter-clockwise (outward) vertex order.
std::shared_ptr<fcl::Convex<double>> make_convex(const ConvexPolyhedron& hull) {
  auto vertices =
      std::make_shared<std::vector<fcl::Vector3d>>(hull.vertices().begin(), hull.vertices().end());
  auto faces = std::make_shared<std::vector<int>>();
  faces->reserve(4 * hull.triangles().size());
  for (const auto& t : hull.triangles()) {
    faces->push_back(3);
    faces->insert(faces->end(), t.begin(), t.end());
  }
  // throw_if_invalid = true: FCL's own (partial) check that the mesh is watertight. Our
  // polyhedron is already validated, so a throw here would mean a conversion bug, reported as
  // status Error by the caller rather than a silently wrong support function.
  return std::make_shared<fcl::Convex<double>>(vertices, static_cast<int>(hull.triangles().size()),
                                               faces, true);
}

/// Converts one fcl::Contact to ours: normal negated (A -> B to B -> A), depth and point as FCL
/// gives them. No other change: a wrong value from FCL stays wrong.
ContactPoint from_fcl(const fcl::Contactd& c, const std::string& feature) {
  ContactPoint p;
  p.point = c.pos;
  p.normal = -c.normal;
  p.depth = c.penetration_depth;
  p.feature = feature;
  return p;
}

/// fcl::collide between two geometries at the bodies' poses with the given GJK solver; every
/// contact FCL returns, converted.
ContactResult collide(const std::shared_ptr<fcl::CollisionGeometryd>& geom_a,
                      const fcl::Transform3d& tf_a,
                      const std::shared_ptr<fcl::CollisionGeometryd>& geom_b,
                      const fcl::Transform3d& tf_b, fcl::GJKSolverType solver,
                      const std::string& feature) {
  fcl::CollisionObjectd object_a(geom_a, tf_a);
  fcl::CollisionObjectd object_b(geom_b, tf_b);
  // enable_contact = true: normal, depth and position are wanted, not just a yes/no.
  fcl::CollisionRequestd request(kMaxContacts, true);
  // The solver is the point of each backend: GST_LIBCCD runs libccd MPR on Convex (boxBox2 on
  // two boxes), GST_INDEP FCL's own GJK + EPA. gjk_tolerance stays at FCL's default 1e-6 m (it
  // becomes MPR's portal tolerance under GST_LIBCCD, the GJK and EPA tolerance under
  // GST_INDEP; collision-inl.h): the backends show FCL as its users run it, and the `libccd`
  // backend runs the same MPR at 1e-10 m to show whether the tolerance matters.
  request.gjk_solver_type = solver;
  fcl::CollisionResultd result;
  fcl::collide(&object_a, &object_b, request, result);

  ContactResult out;
  std::vector<fcl::Contactd> contacts;
  result.getContacts(contacts);
  for (const fcl::Contactd& c : contacts) out.contacts.push_back(from_fcl(c, feature));
  return out;
}

/// Runs an FCL query, turning any exception (FCL throws std::logic_error on degenerate
/// polytopes) into status Error.
template <typename Query>
ContactResult guarded(const char* what, Query&& query) {
  try {
    return query();
  } catch (const std::exception& e) {
    return {Status::Error, std::string(what) + ": " + e.what(), {}};
  }
}

/// Body-frame hull of `body` as an FCL geometry.
std::shared_ptr<fcl::CollisionGeometryd> convex_geometry(const RigidBody& body) {
  return make_convex(*body.shape);
}

/// The body as FCL's users would give it: an fcl::Box for a box body (axes the body axes), its
/// Convex hull otherwise. `tf` receives the geometry's world pose.
std::shared_ptr<fcl::CollisionGeometryd> native_geometry(const RigidBody& body,
                                                         fcl::Transform3d& tf);

/// The world pose of native_geometry's geometry for `body`.
void native_placement(const RigidBody& body, fcl::Transform3d& tf) {
  tf = to_fcl(body.pose());
  // The box centre is taken from the hull's bounds (zero up to round-off for both mass models),
  // so that round-off in the centre-of-mass shift cannot move it.
  if (is_native_box(body))
    tf.translation() += body.pose().rotation() * body.shape->bounds().center();
}

std::shared_ptr<fcl::CollisionGeometryd> native_geometry(const RigidBody& body,
                                                         fcl::Transform3d& tf) {
  native_placement(body, tf);
  if (!is_native_box(body)) return convex_geometry(body);
  return std::make_shared<fcl::Boxd>(body.box_size);
}

// `fcl`: fcl::collide, GST_LIBCCD, on fcl::Box for box bodies and Convex otherwise (two boxes:
// boxBoxIntersect, up to 4 points; otherwise libccd MPR).
ContactResult fcl_contact(const RigidBody& a, const RigidBody& b) {
  // GST_LIBCCD: with two Box shapes both solvers dispatch to boxBoxIntersect (the table in
  // gjk_solver_libccd-inl.h); with a Convex in the pair it runs libccd MPR.
  const bool boxes = is_native_box(a) && is_native_box(b);
  return reject_undefined_normals(
      guarded(boxes ? "fcl::collide (Box-Box)" : "fcl::collide (GST_LIBCCD)",
              [&] {
                fcl::Transform3d tf_a, tf_b;
                auto geom_a = native_geometry(a, tf_a);
                auto geom_b = native_geometry(b, tf_b);
                return collide(geom_a, tf_a, geom_b, tf_b, fcl::GST_LIBCCD,
                               boxes ? "box-box" : "mpr");
              }),
      "fcl::collide (GST_LIBCCD)");
}

// `fcl-hull`: fcl::collide on Convex shapes with GST_LIBCCD (libccd MPR), boxes included.
ContactResult fcl_hull_contact(const RigidBody& a, const RigidBody& b) {
  // At depth below CCD_EPS libccd's MPR sets its direction to zero ("can be anything",
  // mpr.c findPenetr) and FCL copies it as the normal: labelled as no normal, not a 180 deg miss.
  return reject_undefined_normals(guarded("fcl::collide (GST_LIBCCD)",
                                          [&] {
                                            return collide(convex_geometry(a), to_fcl(a.pose()),
                                                           convex_geometry(b), to_fcl(b.pose()),
                                                           fcl::GST_LIBCCD, "mpr");
                                          }),
                                  "fcl::collide (GST_LIBCCD, libccd MPR)");
}

// `fcl` with each shape's geometry (Box or Convex) built once per thread and kept (reference/
// prebuilt_cache.h), as a user holding FCL objects across steps runs it: FCL without its set-up.
ContactResult fcl_contact_prebuilt(const RigidBody& a, const RigidBody& b) {
  // One cache for fcl::Box bodies, one for Convex ones: the key is the shape alone.
  thread_local PrebuiltCache<std::shared_ptr<fcl::CollisionGeometryd>> box_cache, convex_cache;
  auto cache_of = [&](const RigidBody& body) -> auto& {
    return is_native_box(body) ? box_cache : convex_cache;
  };
  const bool boxes = is_native_box(a) && is_native_box(b);
  return reject_undefined_normals(
      guarded(boxes ? "fcl::collide (Box-Box)" : "fcl::collide (GST_LIBCCD)",
              [&] {
                fcl::Transform3d tf_a, tf_b;
                auto geom_a =
                    cache_of(a).get(a.shape, nullptr, [&] { return native_geometry(a, tf_a); });
                auto geom_b =
                    cache_of(b).get(b.shape, nullptr, [&] { return native_geometry(b, tf_b); });
                // The placement, as native_geometry gives it (the cached geometry skips it).
                native_placement(a, tf_a);
                native_placement(b, tf_b);
                return collide(geom_a, tf_a, geom_b, tf_b, fcl::GST_LIBCCD,
                               boxes ? "box-box" : "mpr");
              }),
      "fcl::collide (GST_LIBCCD)");
}

ContactResult fcl_hull_contact_prebuilt(const RigidBody& a, const RigidBody& b) {
  // fcl_hull_contact with each shape's fcl::Convex built once per thread.
  thread_local PrebuiltCache<std::shared_ptr<fcl::CollisionGeometryd>> cache;
  return reject_undefined_normals(
      guarded("fcl::collide (GST_LIBCCD)",
              [&] {
                auto geom_a = cache.get(a.shape, nullptr, [&] { return convex_geometry(a); });
                auto geom_b = cache.get(b.shape, nullptr, [&] { return convex_geometry(b); });
                return collide(geom_a, to_fcl(a.pose()), geom_b, to_fcl(b.pose()), fcl::GST_LIBCCD,
                               "mpr");
              }),
      "fcl::collide (GST_LIBCCD, libccd MPR)");
}

// `fcl-epa`: fcl::distance with signed distance (GJK + EPA).
ContactResult fcl_epa_contact(const RigidBody& a, const RigidBody& b) {
  return guarded("fcl::distance (signed, GST_LIBCCD)", [&]() -> ContactResult {
    fcl::CollisionObjectd object_a(convex_geometry(a), to_fcl(a.pose()));
    fcl::CollisionObjectd object_b(convex_geometry(b), to_fcl(b.pose()));
    // Nearest points give the normal and the point; signed distance gives -depth when
    // penetrating. GST_LIBCCD is the solver that computes it by GJK + EPA on Convex shapes
    // (DistanceRequest docs: SD_1 for primitive shapes); GST_INDEP instead falls back on a
    // collide() workaround and can hit an assertion. distance_tolerance stays at FCL's default
    // 1e-6 m, the documented bound on the EPA depth; on polytopes EPA ends on a hull face anyway.
    fcl::DistanceRequestd request(true, true);
    request.gjk_solver_type = fcl::GST_LIBCCD;
    fcl::DistanceResultd result;
    fcl::distance(&object_a, &object_b, request, result);

    // Separated: no contact.
    if (result.min_distance > 0.0) return ContactResult{};

    // Touching or penetrating: normal from A's nearest point toward B's, reversed by the order
    // (p0 - p1 = depth * (A -> B), ours is B -> A).
    const Vec3 p0 = result.nearest_points[0];
    const Vec3 p1 = result.nearest_points[1];
    const Vec3 d = p1 - p0;
    if (!(d.norm() > kCoincidentPoints)) {
      // At zero distance FCL 0.7 gives coincident nearest points: touching, with no normal.
      const bool touching = std::abs(result.min_distance) <= kTouchingDepth;
      return {touching ? Status::Touching : Status::Error,
              "signed distance " + std::to_string(result.min_distance) +
                  " with coincident nearest points: FCL 0.7 returns no normal at zero depth",
              {}};
    }
    ContactPoint c;
    c.normal = d / d.norm();
    c.depth = -result.min_distance;
    c.point = 0.5 * (p0 + p1);
    c.feature = "gjk-epa";
    return ContactResult{Status::Ok, "", {c}};
  });
}

// `fcl-indep`: fcl::collide on Convex shapes with GST_INDEP, defects shown as they are.
ContactResult fcl_indep_contact(const RigidBody& a, const RigidBody& b) {
  // Only collide() is called, in this process, without run_isolated: it cannot abort. INDEP's
  // *distance* can: fcl::distance's signed-distance workaround (narrowphase/distance-inl.h,
  // `assert(index != ...)`, line 177) trips on INDEP's negative depths, and libfcl.so.0.7 is
  // built without NDEBUG, so it aborts (pinned in tests/reference/fcl_isolated_test.cpp); it is
  // never called here. collide() on two Convex goes collision_func_matrix -> ShapeShapeCollide
  // -> GJKSolver_indep::shapeIntersect -> ShapeIntersectIndepImpl (gjk_solver_indep-inl.h),
  // which runs detail::GJK and detail::EPA (gjk-inl.h, epa-inl.h) with bounded iterations and
  // fixed-size stores, and reports trouble through its status (EPA::Failed -> no contact),
  // never by assert: the only assertions in FCL 0.7's narrow phase are in
  // gjk_libccd-inl.h (GST_LIBCCD only), distance-inl.h (above) and the primitive-shape
  // algorithms, none on this path; Convex's constructor asserts non-null arrays, which
  // make_convex always passes. (Eigen's own bounds assertions are live in the library too;
  // they guard indexing, not the input geometry.) So no input can make this path abort, and a
  // fork per query would buy nothing.
  ContactResult r = guarded("fcl::collide (GST_INDEP)", [&] {
    return collide(convex_geometry(a), to_fcl(a.pose()), convex_geometry(b), to_fcl(b.pose()),
                   fcl::GST_INDEP, "gjk-epa-indep");
  });
  if (r.status == Status::Ok) r.message = kIndepDefect;
  return r;
}

// -- distance ------------------------------------------------------------------------------
// fcl::distance with enable_nearest_points, as FCL's users ask for closest points. FCL 0.7 gives
// min_distance and nearest_points[0] (on o1 = A) and [1] (on o2 = B) in the world frame (both
// solvers: gjk_libccd-inl.h GJKDistanceImpl, gjk_solver_indep-inl.h ShapeDistanceIndepImpl map
// the simplex's points by tf1), and -1 for a pair in collision (no points): our `overlapping`.
// distance_tolerance and the GJK tolerances stay at FCL's defaults, as for the contact rows.
DistanceResult fcl_distance(const std::shared_ptr<fcl::CollisionGeometryd>& geom_a,
                            const fcl::Transform3d& tf_a,
                            const std::shared_ptr<fcl::CollisionGeometryd>& geom_b,
                            const fcl::Transform3d& tf_b, fcl::GJKSolverType solver,
                            bool signed_distance, const std::string& what) {
  try {
    fcl::CollisionObjectd object_a(geom_a, tf_a);
    fcl::CollisionObjectd object_b(geom_b, tf_b);
    fcl::DistanceRequestd request(true, signed_distance);
    request.gjk_solver_type = solver;
    fcl::DistanceResultd result;
    fcl::distance(&object_a, &object_b, request, result);
    DistanceResult r;
    if (result.min_distance < 0.0) {
      r.overlapping = true;
      return r;
    }
    r.distance = result.min_distance;
    r.point_a = result.nearest_points[0];
    r.point_b = result.nearest_points[1];
    return r;
  } catch (const std::exception& e) {
    DistanceResult r;
    r.status = Status::Error;
    r.message = what + ": " + e.what();
    return r;
  }
}

// `fcl`: fcl::Box for box bodies, Convex otherwise; GST_LIBCCD (libccd's GJK).
DistanceResult fcl_distance_native(const RigidBody& a, const RigidBody& b) {
  fcl::Transform3d tf_a, tf_b;
  auto geom_a = native_geometry(a, tf_a);
  auto geom_b = native_geometry(b, tf_b);
  return fcl_distance(geom_a, tf_a, geom_b, tf_b, fcl::GST_LIBCCD, false,
                      "fcl::distance (GST_LIBCCD)");
}

// `fcl-hull`: every body a Convex; GST_LIBCCD.
DistanceResult fcl_distance_hull(const RigidBody& a, const RigidBody& b) {
  return fcl_distance(convex_geometry(a), to_fcl(a.pose()), convex_geometry(b), to_fcl(b.pose()),
                      fcl::GST_LIBCCD, false, "fcl::distance (GST_LIBCCD)");
}

// `fcl-epa`: the signed distance the contact row reads (GJK, EPA when overlapping).
DistanceResult fcl_distance_signed(const RigidBody& a, const RigidBody& b) {
  return fcl_distance(convex_geometry(a), to_fcl(a.pose()), convex_geometry(b), to_fcl(b.pose()),
                      fcl::GST_LIBCCD, true, "fcl::distance (signed, GST_LIBCCD)");
}

// `fcl-indep`: every body a Convex; GST_INDEP (FCL's own GJK). Unsigned, so the signed-distance
// workaround that can abort (see fcl_indep_contact) is never reached.
DistanceResult fcl_distance_indep(const RigidBody& a, const RigidBody& b) {
  return fcl_distance(convex_geometry(a), to_fcl(a.pose()), convex_geometry(b), to_fcl(b.pose()),
                      fcl::GST_INDEP, false, "fcl::distance (GST_INDEP)");
}

// `fcl`'s distance with each shape's geometry built once per thread (fcl_contact_prebuilt).
DistanceResult fcl_distance_prebuilt(const RigidBody& a, const RigidBody& b) {
  thread_local PrebuiltCache<std::shared_ptr<fcl::CollisionGeometryd>> box_cache, convex_cache;
  auto cache_of = [&](const RigidBody& body) -> auto& {
    return is_native_box(body) ? box_cache : convex_cache;
  };
  fcl::Transform3d tf_a, tf_b;
  auto geom_a = cache_of(a).get(a.shape, nullptr, [&] { return native_geometry(a, tf_a); });
  auto geom_b = cache_of(b).get(b.shape, nullptr, [&] { return native_geometry(b, tf_b); });
  native_placement(a, tf_a);
  native_placement(b, tf_b);
  return fcl_distance(geom_a, tf_a, geom_b, tf_b, fcl::GST_LIBCCD, false,
                      "fcl::distance (GST_LIBCCD)");
}

// -- time of impact --------------------------------------------------------------------------
// fcl::continuousCollide between the bodies' start and end poses, with InterpMotion
// (CCDM_LINEAR: the geometry's origin, here the centre of mass, at a constant velocity, the
// orientation turning at a constant rate about a fixed axis the short way: the stated motion)
// and conservative advancement (CCDC_CONSERVATIVE_ADVANCEMENT), the solver FCL's users pick for
// primitives and convex shapes (its default CCDC_NAIVE tests num_max_iterations = 10 evenly
// spaced poses: FclSettingsMeasured.NaiveSamplingMissesAThinCrossing). Read from the 0.7
// headers: the shape-shape advancement ignores the request (FCL_UNUSED) and stops once its next
// safe step is under a fixed 1e-4 of the interval (ShapeConservativeAdvancementTraversalNode's
// t_err), reporting that time and the poses then, and no contact (its maintainers advise a
// discrete query at those poses for one: a second library call, not part of this query).
// The motion is built here rather than by the overload taking two transforms per body, whose
// InterpMotion(tf1, tf2) never sets its reference point (an Eigen vector left uninitialised) and
// derives the velocities from it: its answers changed with whatever the process had run before
// (0.089, 0.252, 0.276 of the interval or no touch, on one pair, measured).
ToiResult fcl_toi(const std::shared_ptr<fcl::CollisionGeometryd>& geom_a, const RigidBody& a,
                  const std::shared_ptr<fcl::CollisionGeometryd>& geom_b, const RigidBody& b,
                  double dt, fcl::GJKSolverType solver, bool native, const std::string& what) {
  ToiResult r;
  try {
    const std::optional<RigidBody> end_a = body_at_end(a, dt), end_b = body_at_end(b, dt);
    if (!end_a || !end_b) {
      r.status = Status::Unsupported;
      r.message = "a body turns too far for its end poses to name its motion";
      return r;
    }
    auto placed = [native](const RigidBody& body) {
      fcl::Transform3d tf = to_fcl(body.pose());
      if (native) native_placement(body, tf);
      return tf;
    };
    fcl::ContinuousCollisionRequestd request;
    request.ccd_motion_type = fcl::CCDM_LINEAR;
    request.ccd_solver_type = fcl::CCDC_CONSERVATIVE_ADVANCEMENT;
    request.gjk_solver_type = solver;
    fcl::ContinuousCollisionResultd result;
    // The five-argument InterpMotion: the one constructor that sets the reference point (here
    // the geometry's origin) before deriving the velocities from it (file comment).
    auto motion = [](const fcl::Transform3d& from, const fcl::Transform3d& to) {
      return fcl::InterpMotion<double>(from.linear(), from.translation(), to.linear(),
                                       to.translation(), fcl::Vector3d::Zero());
    };
    const fcl::InterpMotion<double> motion_a = motion(placed(a), placed(*end_a));
    const fcl::InterpMotion<double> motion_b = motion(placed(b), placed(*end_b));
    const double toc =
        fcl::continuousCollide(geom_a.get(), &motion_a, geom_b.get(), &motion_b, request, result);
    if (toc < 0) {
      r.status = Status::Error;
      r.message = what + " has no conservative advancement for this shape pair";
      return r;
    }
    if (!result.is_collide) return r;
    r.hit = true;
    r.fraction = result.time_of_contact;
    r.message = "continuousCollide gives the time and the poses then, no contact";
  } catch (const std::exception& e) {
    r.status = Status::Error;
    r.message = what + ": " + e.what();
  }
  return r;
}

// `fcl`: fcl::Box for box bodies, Convex otherwise; GST_LIBCCD.
ToiResult fcl_toi_native(const RigidBody& a, const RigidBody& b, double dt) {
  fcl::Transform3d tf_a, tf_b;
  return fcl_toi(native_geometry(a, tf_a), a, native_geometry(b, tf_b), b, dt, fcl::GST_LIBCCD,
                 true, "fcl::continuousCollide (GST_LIBCCD)");
}

// `fcl`'s time of impact with each shape's geometry built once per thread (the "prebuilt"
// variant: the same answers, timed as a user holding FCL objects calls it).
ToiResult fcl_toi_prebuilt(const RigidBody& a, const RigidBody& b, double dt) {
  thread_local PrebuiltCache<std::shared_ptr<fcl::CollisionGeometryd>> box_cache, convex_cache;
  auto geometry = [&](const RigidBody& body) {
    fcl::Transform3d unused;
    return (is_native_box(body) ? box_cache : convex_cache).get(body.shape, nullptr, [&] {
      return native_geometry(body, unused);
    });
  };
  return fcl_toi(geometry(a), a, geometry(b), b, dt, fcl::GST_LIBCCD, true,
                 "fcl::continuousCollide (GST_LIBCCD)");
}

// `fcl-hull`'s, each fcl::Convex built once per thread.
ToiResult fcl_hull_toi_prebuilt(const RigidBody& a, const RigidBody& b, double dt) {
  thread_local PrebuiltCache<std::shared_ptr<fcl::CollisionGeometryd>> cache;
  auto geometry = [&](const RigidBody& body) {
    return cache.get(body.shape, nullptr, [&] { return convex_geometry(body); });
  };
  return fcl_toi(geometry(a), a, geometry(b), b, dt, fcl::GST_LIBCCD, false,
                 "fcl::continuousCollide (GST_LIBCCD)");
}

// `fcl-hull`: every body a Convex; GST_LIBCCD.
ToiResult fcl_toi_hull(const RigidBody& a, const RigidBody& b, double dt) {
  return fcl_toi(convex_geometry(a), a, convex_geometry(b), b, dt, fcl::GST_LIBCCD, false,
                 "fcl::continuousCollide (GST_LIBCCD)");
}

// `fcl-indep`: every body a Convex; GST_INDEP.
ToiResult fcl_toi_indep(const RigidBody& a, const RigidBody& b, double dt) {
  return fcl_toi(convex_geometry(a), a, convex_geometry(b), b, dt, fcl::GST_INDEP, false,
                 "fcl::continuousCollide (GST_INDEP)");
}

MassResult fcl_hull_mass(const RigidBody& body);

// `fcl` mass: fcl::Box's volume and inertia for box bodies (unit density, scaled by mass /
// volume), fcl_hull_mass otherwise.
MassResult fcl_mass(const RigidBody& body) {
  if (!is_native_box(body)) return fcl_hull_mass(body);
  MassResult r;
  const fcl::Boxd box(body.box_size);
  r.volume = box.computeVolume();
  r.mass = body.mass;
  r.center_of_mass = Vec3::Zero();  // the box centre, which is_native_box puts at the origin
  // Box's inertia is at unit density: scaled by the density mass / volume.
  r.inertia = box.computeMomentofInertia() * (body.mass / r.volume);
  r.message = "fcl::Box, unit-density inertia scaled to the mass";
  return r;
}

// `fcl-hull` mass: FCL's own Convex volume, centre of mass and inertia (computeVolume, computeCOM,
// computeMomentofInertiaRelatedToCOM at uniform density mass / volume).
MassResult fcl_hull_mass(const RigidBody& body) {
  MassResult r;
  try {
    const auto convex = make_convex(*body.shape);
    r.volume = convex->computeVolume();
    r.mass = body.mass;
    r.center_of_mass = convex->computeCOM();
    // FCL integrates at unit density: scale to the body's mass.
    r.inertia = convex->computeMomentofInertiaRelatedToCOM() * (body.mass / r.volume);
    // Convention: FCL's Box/Sphere return the inertia at unit density, and the base class's
    // parallel-axis shift assumes it, so we scale by the density mass / volume. FCL 0.7's
    // Convex returns it per unit MASS instead (convex-inl.h divides by the volume): the result
    // is off by 1/V, shown as it is.
    r.message =
        "fcl::Convex, unit-density convention scaled to the mass (0.7's Convex is per unit mass)";
  } catch (const std::exception& e) {
    r.status = Status::Error;
    r.message = e.what();
  }
  return r;
}

}  // namespace

const Adapter& fcl_adapter() {
  static const Adapter adapter = {
      {
          Backend{"fcl", "FCL 0.7: Box (boxBoxIntersect) or Convex (libccd MPR)", fcl_contact,
                  nullptr, fcl_mass}
              .measuring(fcl_distance_native)
              .sweeping(fcl_toi_native)
              .drawn("#E69F00", "o")
              .timed(8192, 2048),
          Backend{"fcl-hull", "FCL 0.7 Convex, GST_LIBCCD (libccd MPR)", fcl_hull_contact, nullptr,
                  fcl_hull_mass}
              .measuring(fcl_distance_hull)
              .sweeping(fcl_toi_hull)
              .drawn("#A35F00", "s"),
          Backend{"fcl-epa", "FCL 0.7 signed distance (GJK + EPA)", fcl_epa_contact, nullptr}
              .measuring(fcl_distance_signed)
              .drawn("#F3C363", "^")
              .timed(8192, 2048),
          Backend{"fcl-indep", "FCL 0.7 Convex, GST_INDEP (known defects shown)", fcl_indep_contact,
                  nullptr}
              .measuring(fcl_distance_indep)
              .sweeping(fcl_toi_indep)
              .drawn("#6B4E16", "D"),
      },
      {
          {"fcl",
           "prebuilt",
           "each fcl::Box or Convex built once and kept, as a user holding FCL objects",
           fcl_contact_prebuilt,
           {8192, 2048},
           false,
           fcl_distance_prebuilt,
           fcl_toi_prebuilt},
          // `fcl` on two box bodies runs fcl::Box (boxBoxIntersect): timed apart on the boxes.
          {"fcl",
           "boxes",
           "fcl on two box bodies: fcl::Box, boxBoxIntersect",
           fcl_contact,
           {8, 8},
           true},
          {"fcl-hull",
           "prebuilt",
           "each fcl::Convex built once and kept",
           fcl_hull_contact_prebuilt,
           {},
           false,
           nullptr,
           fcl_hull_toi_prebuilt},
      }};
  return adapter;
}

}  // namespace rbx
