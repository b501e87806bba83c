// libccd 2.1 called directly on our own support function: MPR and GJK + EPA.
//
// Build: the Debian libccd is built with CCD_DOUBLE (<ccd/config.h>), so ccd_real_t is double
// and no precision is lost crossing the boundary; a static_assert below pins that.
//
// libccd's convention (<ccd/ccd.h>, confirmed by probes in tests/reference/libccd_test.cpp):
// ccdMPRPenetration and ccdGJKPenetration compute "penetration of obj2 into obj1": translating
// obj2 (B) by depth * dir separates the pair, so dir is a unit vector pointing from A toward B,
// world frame; depth > 0; pos is a world point inside the overlap. Ours points from B toward A:
// normal = -dir. Nothing else is changed.
#include "reference/libccd.h"

#include <ccd/ccd.h>
#include <ccd/quat.h>
#include <ccd/vec3.h>

#include <cmath>
#include <string>
#include <type_traits>

namespace rbx {
namespace {

static_assert(std::is_same<ccd_real_t, double>::value,
              "libccd must be built with CCD_DOUBLE: the adapter passes doubles through");

// Iteration cap for GJK and MPR's last refinement, the only loops of libccd 2.1 that read it.
// libccd's default is unlimited ((unsigned long)-1); polytopes of a few hundred vertices
// converge in far fewer.
constexpr unsigned long kMaxIterations = 1000;

// Support-call budget of one libccd query, the cap libccd 2.1 lacks: EPA (ccd.c, __ccdGJKEPA)
// and MPR's portal refinement (mpr.c, refinePortal) loop on `while (1)`. EPA does loop forever
// where the Minkowski difference has a large flat face (boxes face on face, as in MuJoCo's
// BoxBoxLarge): libccd takes an inner diagonal of that face for the nearest feature (its
// distance ties the face's within libccd's absolute epsilon), the support along the edge's
// tilted witness is a vertex the polytope already has, yet the gap passes the tolerance test
// with the face's long lever; adding the vertex again swaps to the other diagonal, without end.
// Past the budget both bodies return the same point, so the Minkowski support is the origin
// and every libccd loop stops; the query is then reported as not converged. Converging queries
// use a few hundred calls (2 per GJK iteration and per EPA expansion). Even, so a pair's two
// calls (support1 then support2) fall on the same side of it.
constexpr long kMaxSupportCalls = 4 * static_cast<long>(kMaxIterations) + 16;

// MPR, EPA and GJK-distance tolerance (m). libccd's defaults (1e-4 MPR/EPA) are a tenth of a
// millimetre, coarse next to the 0.1-1 mm depths of our scenes; 1e-10 is tight enough not to
// limit the answer and still far above round-off of unit-scale coordinates (~1e-16 m).
constexpr ccd_real_t kTolerance = 1e-10;

/// A posed body as libccd sees it: the body-frame polyhedron, the box it is (when it is one)
/// and the body-to-world transform.
struct CcdBody {
  const ConvexPolyhedron* hull;
  bool box = false;     // a box body (is_native_box): libccd's own box support
  Vec3 half_size;       // m, the box's half extents (body axes)
  Mat3 rotation;        // body to world
  Vec3 position;        // m, world position of the body origin (the centre of mass)
  long* support_calls;  // calls so far in the current query, shared by the pair
};

/// The pose and shape of `body` for libccd, sharing the pair's support-call count.
CcdBody ccd_body(const RigidBody& body, long* calls) {
  return {body.shape.get(),       is_native_box(body), 0.5 * body.box_size,
          body.pose().rotation(), body.position,       calls};
}

/// libccd support function. A box gets the support libccd documents for boxes (its README's
/// example and its test suite's, testsuites/support.c): ccdSign(d) * half size in the box
/// frame, a component of d within libccd's epsilon of zero giving the centre of that face or
/// edge. Every other body: the vertex
/// of the posed hull furthest along `dir`, R * support_local(R^T dir) + p, support_local being
/// the hull's support_index (among tied vertices the first in the hull's order). Both are
/// support points; only where `dir` has a zero component can they differ, and libccd's MPR and
/// EPA can tell them apart there (tests/reference/libccd_test.cpp).
void support(const void* obj, const ccd_vec3_t* dir, ccd_vec3_t* vec) {
  const auto* body = static_cast<const CcdBody*>(obj);
  if (++*body->support_calls > kMaxSupportCalls) {  // over budget: see kMaxSupportCalls
    ccdVec3Set(vec, 0.0, 0.0, 0.0);
    return;
  }
  const Vec3 dir_world(ccdVec3X(dir), ccdVec3Y(dir), ccdVec3Z(dir));
  const Vec3 dir_local = body->rotation.transpose() * dir_world;
  Vec3 v_local;
  if (body->box)
    v_local = Vec3(ccdSign(dir_local.x()) * body->half_size.x(),
                   ccdSign(dir_local.y()) * body->half_size.y(),
                   ccdSign(dir_local.z()) * body->half_size.z());
  else
    v_local = body->hull->vertices()[body->hull->support_index(dir_local)];
  const Vec3 v_world = body->rotation * v_local + body->position;
  ccdVec3Set(vec, v_world.x(), v_world.y(), v_world.z());
}

/// libccd centre function (MPR's interior point): the centre of mass, the body origin, which
/// lies inside the hull for both mass models.
void center(const void* obj, ccd_vec3_t* c) {
  const auto* body = static_cast<const CcdBody*>(obj);
  ccdVec3Set(c, body->position.x(), body->position.y(), body->position.z());
}

/// The outcome of one libccd penetration call, in our convention.
struct Penetration {
  bool intersecting = false;
  bool direction_defined = false;  // false: libccd returned a zero or NaN direction
  ContactPoint contact;
};

/// Converts a libccd answer (return code, depth, dir from A toward B, pos) to ours.
Penetration convert(int code, ccd_real_t depth, const ccd_vec3_t& dir, const ccd_vec3_t& pos,
                    const char* feature) {
  Penetration p;
  p.intersecting = code == 0;
  if (!p.intersecting) return p;
  const Vec3 n(ccdVec3X(&dir), ccdVec3Y(&dir), ccdVec3Z(&dir));
  // libccd normalises dir itself; a touching contact can come back with dir = NaN (GJK + EPA)
  // or zero, which defines no normal.
  p.direction_defined = std::isfinite(n.norm()) && n.norm() > 0.5;
  p.contact.normal = -n;  // A -> B to B -> A
  p.contact.depth = depth;
  p.contact.point = Vec3(ccdVec3X(&pos), ccdVec3Y(&pos), ccdVec3Z(&pos));
  p.contact.feature = feature;
  return p;
}

/// The libccd set-up shared by both queries: default first direction (ccdFirstDirDefault,
/// +x), our support and centre functions, the cap and the tolerances above.
ccd_t make_ccd() {
  ccd_t ccd;
  CCD_INIT(&ccd);
  ccd.support1 = support;
  ccd.support2 = support;
  ccd.center1 = center;
  ccd.center2 = center;
  ccd.max_iterations = kMaxIterations;
  ccd.mpr_tolerance = kTolerance;
  ccd.epa_tolerance = kTolerance;
  ccd.dist_tolerance = kTolerance;
  return ccd;
}

/// One libccd penetration query (`run` calls ccdMPRPenetration or ccdGJKPenetration) on the
/// pair, converted to our convention.
template <class Query>
ContactResult penetration(const RigidBody& a, const RigidBody& b, const char* name,
                          const char* feature, Query&& run) {
  long support_calls = 0;
  const CcdBody body_a = ccd_body(a, &support_calls);
  const CcdBody body_b = ccd_body(b, &support_calls);
  const ccd_t ccd = make_ccd();
  ccd_real_t depth = 0.0;
  ccd_vec3_t dir, pos;
  ccdVec3Set(&dir, 0.0, 0.0, 0.0);
  ccdVec3Set(&pos, 0.0, 0.0, 0.0);
  const int code = run(&body_a, &body_b, &ccd, &depth, &dir, &pos);
  if (support_calls > kMaxSupportCalls)
    return {Status::Error,
            std::string(name) + " did not converge within " + std::to_string(kMaxSupportCalls) +
                " support calls (libccd 2.1 caps no iteration there; see reference/libccd.cpp)",
            {}};
  if (code == -2) return {Status::Error, std::string(name) + ": memory allocation failed", {}};
  const Penetration p = convert(code, depth, dir, pos, feature);
  if (!p.intersecting) return {};
  // A contact without a direction cannot be reported in our convention (libccd 2.1 at exact
  // touching: MPR zeroes its direction, GJK + EPA returns depth 0 and dir NaN).
  if (!p.direction_defined) return reject_undefined_normals({Status::Ok, "", {p.contact}}, name);
  return {Status::Ok, "", {p.contact}};
}

// `libccd-mpr`: one contact from ccdMPRPenetration (feature "mpr").
ContactResult libccd_mpr_contact(const RigidBody& a, const RigidBody& b) {
  return penetration(a, b, "ccdMPRPenetration", "mpr",
                     [](auto... args) { return ccdMPRPenetration(args...); });
}

// `libccd-epa`: one contact from ccdGJKPenetration, GJK then EPA (feature "gjk-epa").
ContactResult libccd_epa_contact(const RigidBody& a, const RigidBody& b) {
  return penetration(a, b, "ccdGJKPenetration", "gjk-epa",
                     [](auto... args) { return ccdGJKPenetration(args...); });
}

}  // namespace

const Adapter& libccd_adapter() {
  static const Adapter adapter = {
      {
          Backend{"libccd-mpr",
                  "libccd 2.1 MPR (ccdMPRPenetration); libccd's box support for boxes",
                  libccd_mpr_contact, nullptr}
              .drawn("#CC79A7", "o")
              .timed(8192, 2048),
          Backend{"libccd-epa",
                  "libccd 2.1 GJK + EPA (ccdGJKPenetration); libccd's box support for boxes",
                  libccd_epa_contact, nullptr}
              .drawn("#882255", "^"),
      },
      {}};
  return adapter;
}

}  // namespace rbx
