// The two searches behind choose_contact_plane (engine/contact_plane.h) and what they share:
// the candidate axes they keep and the test of two Gauss-map arcs. Internal to the engine.
//
// Two searches, one answer: both keep every candidate axis (a face normal of the Minkowski
// difference D = A - B) whose overlap lies within the tie margin of the least, and
// choose_contact_plane picks among those by keys of the geometry alone. The scan measures every
// face and filters edges linearly and is the faster on small shapes; the search is a branch and
// bound over the shapes' Gauss maps and is the faster from a few hundred faces
// (docs/contact_plane.md has the timings).
#pragma once

#include <limits>
#include <vector>

#include "engine/contact_plane.h"

namespace rbx::plane_detail {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// One candidate axis: its overlap, the kind (faces before edge pairs on a tie: a face contact
/// is the stable one), its sign-free form and the normal from B toward A.
struct Candidate {
  double overlap = kInf;  // m
  int kind = 0;           // 0 face, 1 edge pair
  Vec3 axis = Vec3::Zero();
  Vec3 normal = Vec3::Zero();
  PlaneAxis source = PlaneAxis::FaceOfB;
};

/// What a search leaves: its candidates (every one within `tie` of the least overlap among
/// them), the tie margin, and a fallback direction should none be kept. On entry, `known` and
/// `known_normal` are an overlap measured along some direction (kInf: none): an upper bound on
/// the least overlap that each search starts from.
struct Candidates {
  std::vector<Candidate> kept;
  double tie = 0.0;  // m, overlaps closer than this are equal (round-off)
  double upper = kInf;
  Vec3 upper_normal = Vec3::UnitZ();
  double known = kInf;  // m
  Vec3 known_normal = Vec3::UnitZ();
};

/// The sign-free form of an axis: the one of +-n whose first nonzero component is positive, so
/// that an axis found from either body order compares equal.
inline Vec3 canonical(const Vec3& n) {
  const bool flip = n.x() < 0 || (n.x() == 0 && (n.y() < 0 || (n.y() == 0 && n.z() < 0)));
  return flip ? Vec3(-n) : n;
}

/// Whether the Gauss-map arcs p0-p1 (A's two face normals) and q0-q1 (B's, negated: the faces of
/// the Minkowski difference A - B) cross, so that the edges' cross product is a face normal of
/// A - B. Conservative: a pair within round-off of crossing passes (its overlap is then measured
/// by projections, which can only overestimate, never undercut, the least overlap).
inline bool arcs_cross(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  constexpr double kSlack = 1e-12;
  const Vec3 pn = p1.cross(p0), qn = q1.cross(q0);
  const double q0p = q0.dot(pn), q1p = q1.dot(pn), p0q = p0.dot(qn), p1q = p1.dot(qn);
  return q0p * q1p <= kSlack && p0q * p1q <= kSlack && q0p * p1q >= -kSlack;
}

/// The scan: every face measured (with a bound that skips the hopeless) and every solid edge near
/// the other shape paired (engine/contact_plane_scan.cpp). Its edge filters hold for shapes that
/// overlap; it returns false, keeping nothing, when it cannot prove that they do (then the search
/// answers).
bool scan_candidates(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                     const Pose& pb, Candidates& out);

/// The search: branch and bound over both shapes' Gauss maps
/// (engine/contact_plane_search.cpp).
void search_candidates(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                       const Pose& pb, Candidates& out);

}  // namespace rbx::plane_detail
