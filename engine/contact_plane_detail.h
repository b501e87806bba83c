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
#include <memory>
#include <vector>

#include "engine/contact_plane.h"
#include "engine/contact_scratch.h"
#include "engine/gauss_map.h"
#include "engine/polyhedron.h"

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
  /// The search's directions (on D's Gauss map, world): no candidate outside this cone can be
  /// within the tie margin of the least overlap (inner_polytope_bound); whole: every direction.
  DirectionCone within;
  /// Narrowed: the vertices of A and of B whose difference supports D along `within`'s axis.
  int within_a = -1, within_b = -1;
  /// The search: narrow it by the inner polytope first (false: the whole sphere, as a check).
  bool polytope = true;
  /// The search: stop when the polytope cannot prove the shapes overlap (no whole search).
  bool proof_only = false;
  /// Left by the method: whether it proved that the shapes overlap by more than round-off (the
  /// scan's point inside both, the polytope's tetrahedron around the origin).
  bool proved = false;
};

/// Each query file's own lists (defined in that file: the search's, the scan's, the inner
/// polytope's, the contact region's, the manifold's reduction), made on first use and kept by a
/// Scratch.
struct SearchLists;
struct ScanLists;
struct PolytopeLists;
struct RegionLists;
struct ManifoldLists;
/// Frees a file's lists where their type is complete (one overload defined in each file).
struct ListsDeleter {
  void operator()(SearchLists* p) const;
  void operator()(ScanLists* p) const;
  void operator()(PolytopeLists* p) const;
  void operator()(RegionLists* p) const;
  void operator()(ManifoldLists* p) const;
};

/// What a ContactScratch holds (engine/contact_scratch.h): the candidates of choose_contact_plane
/// and each query file's lists.
struct Scratch {
  Candidates found;
  std::unique_ptr<SearchLists, ListsDeleter> search;
  std::unique_ptr<ScanLists, ListsDeleter> scan;
  std::unique_ptr<PolytopeLists, ListsDeleter> polytope;
  std::unique_ptr<RegionLists, ListsDeleter> region;
  std::unique_ptr<ManifoldLists, ListsDeleter> manifold;
};

/// Shapes with at most this many vertices take their support by a scan, larger ones by a climb:
/// the crossover measured on hulls of random points on a sphere, on poses the processor has not
/// seen, with the scan on AVX (docs/bench.md). One bound whatever the processor: on a tie, a
/// climb may keep another of the highest vertices than the scan, and the same scene must give
/// the same numbers on every machine.
constexpr std::size_t kScanSupport = 160;

/// One shape of a query: its Gauss map and its pose.
struct Side {
  const ConvexPolyhedron* shape = nullptr;
  const GaussMap* map = nullptr;
  Mat3 r = Mat3::Identity();
  Mat3 rt = Mat3::Identity();
  Vec3 p = Vec3::Zero();

  /// Places `s` at pose `pose`.
  void set(const ConvexPolyhedron& s, const Pose& pose) {
    shape = &s;
    map = &s.gauss_map();
    r = pose.rotation();
    rt = r.transpose();
    p = pose.position;
  }
  /// The support h(d) = max over the shape of x . d along a world direction: on shapes of at
  /// most kScanSupport vertices by a scan of them all (the first highest), on larger ones
  /// climbing from `at` or from the cube map's start vertex for d, whichever is further along d
  /// (left in `at`: a vertex that reaches it).
  double support(const Vec3& d, int& at) const {
    const Vec3 local = rt * d;
    double h = 0.0;
    if (shape->vertices().size() <= kScanSupport) {
      // No branch on the data: a climb's steps and a branchy scan's both depend on the pose, and
      // on poses the processor has not seen their mispredictions cost more than the scan
      // (docs/bench.md).
      at = map->scan_vertices(local, h);
      return h + p.dot(d);
    }
    at = map->climb(shape->vertices(), local, map->better_start(shape->vertices(), local, at), h);
    return h + p.dot(d);
  }
  /// Vertex v in the world.
  Vec3 world(int v) const { return r * shape->vertices()[v] + p; }
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
                     const Pose& pb, Candidates& out, Scratch& scratch);

/// Whether two cones of directions (axes unit, world) hold no direction in common: the angle
/// between their axes exceeds the sum of their angles.
inline bool cones_apart(const Vec3& axis0, const DirectionCone& c0, const Vec3& axis1,
                        const DirectionCone& c1) {
  if (c0.whole || c1.whole) return false;
  const double cos_sum = c0.cos_angle * c1.cos_angle - c0.sin_angle * c1.sin_angle;
  const bool sum_below_pi = c0.sin_angle * c1.cos_angle + c0.cos_angle * c1.sin_angle > 0.0;
  return sum_below_pi && axis0.dot(axis1) < cos_sum;
}

/// The inner polytope (engine/contact_plane_polytope.cpp): GJK then EPA on D = A - B, with the
/// shapes' own supports. Every triangle of the polytope lies in D, so along every direction that
/// meets it D's support is at least the triangle's plane distance; the least support found along
/// a triangle normal bounds the answer from above. Leaves in `out` that upper bound (`known`)
/// and the cone `within` of the triangles whose plane distance does not exceed it (with a
/// margin), the only directions that can hold a candidate within the tie margin of the least.
/// Returns false, leaving `out` alone, when it cannot bound (shapes apart, touching, or a
/// degenerate polytope): then the search covers every direction.
bool inner_polytope_bound(const Side& a, const Side& b, double tie, Candidates& out,
                          Scratch& scratch);

/// The search: branch and bound over both shapes' Gauss maps
/// (engine/contact_plane_search.cpp).
void search_candidates(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                       const Pose& pb, Candidates& out, Scratch& scratch);

}  // namespace rbx::plane_detail
