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

// Iteration cap for MPR refinement, GJK and EPA. libccd's default is unlimited
// ((unsigned long)-1), so a case that does not converge would hang the report; polytopes of a
// few hundred vertices converge in far fewer.
constexpr unsigned long kMaxIterations = 1000;

// MPR, EPA and GJK-distance tolerance (m). libccd's defaults (1e-4 MPR/EPA) are a tenth of a
// millimetre, coarse next to the 0.1-1 mm depths of our scenes; 1e-10 is tight enough not to
// limit the answer and still far above round-off of unit-scale coordinates (~1e-16 m).
constexpr ccd_real_t kTolerance = 1e-10;

/// A posed hull as libccd sees it: the body-frame polyhedron and the body-to-world transform.
struct CcdBody {
  const ConvexPolyhedron* hull;
  Mat3 rotation;  // body to world
  Vec3 position;  // m, world position of the body origin (the centre of mass)
};

/// libccd support function: the world-frame vertex of the posed hull furthest along `dir`,
/// R * support_local(R^T dir) + p.
void support(const void* obj, const ccd_vec3_t* dir, ccd_vec3_t* vec) {
  const auto* body = static_cast<const CcdBody*>(obj);
  const Vec3 dir_world(ccdVec3X(dir), ccdVec3Y(dir), ccdVec3Z(dir));
  const Vec3 dir_local = body->rotation.transpose() * dir_world;
  const Vec3& v_local = body->hull->vertices()[body->hull->support_index(dir_local)];
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

}  // namespace

ContactResult libccd_contact(const RigidBody& a, const RigidBody& b) {
  const CcdBody body_a{a.shape.get(), a.pose().rotation(), a.position};
  const CcdBody body_b{b.shape.get(), b.pose().rotation(), b.position};

  // Default first direction (ccdFirstDirDefault, +x); our support and centre functions; the
  // cap and tolerances above.
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

  // Both algorithms on the same pair.
  ccd_real_t depth = 0.0;
  ccd_vec3_t dir, pos;
  ccdVec3Set(&dir, 0.0, 0.0, 0.0);
  ccdVec3Set(&pos, 0.0, 0.0, 0.0);
  const int mpr_code = ccdMPRPenetration(&body_a, &body_b, &ccd, &depth, &dir, &pos);
  const Penetration mpr = convert(mpr_code, depth, dir, pos, "mpr");
  depth = 0.0;
  ccdVec3Set(&dir, 0.0, 0.0, 0.0);
  ccdVec3Set(&pos, 0.0, 0.0, 0.0);
  const int gjk_code = ccdGJKPenetration(&body_a, &body_b, &ccd, &depth, &dir, &pos);
  if (gjk_code == -2) return {Status::Error, "ccdGJKPenetration: memory allocation failed", {}};
  const Penetration epa = convert(gjk_code, depth, dir, pos, "gjk-epa");

  // A contact without a direction cannot be reported in our convention: say so instead of
  // dropping it silently (libccd 2.1 GJK + EPA at exactly touching returns depth 0, dir NaN).
  for (const Penetration* p : {&mpr, &epa}) {
    if (p->intersecting && !p->direction_defined) {
      return {Status::Error,
              std::string(p == &mpr ? "ccdMPRPenetration" : "ccdGJKPenetration") +
                  " reported contact (depth " + std::to_string(p->contact.depth) +
                  ") with an undefined direction",
              {}};
    }
  }

  // contacts[0] = MPR, contacts[1] = GJK + EPA when both see contact; if only one does, its
  // contact alone (told apart by `feature`) and a note of the disagreement.
  ContactResult out;
  if (mpr.intersecting) out.contacts.push_back(mpr.contact);
  if (epa.intersecting) out.contacts.push_back(epa.contact);
  if (mpr.intersecting != epa.intersecting) {
    out.message = mpr.intersecting ? "MPR reports contact, GJK reports none"
                                   : "GJK + EPA reports contact, MPR reports none";
  }
  return out;
}

}  // namespace rbx
