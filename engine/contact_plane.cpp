// The contact plane: the scan or the search for the candidate axes (engine/contact_plane_detail.h),
// then one choice among them by keys of the geometry.
#include "engine/contact_plane.h"

#include <algorithm>
#include <optional>

#include "engine/contact_plane_detail.h"
#include "engine/gauss_map.h"

namespace rbx {

namespace {

using plane_detail::Candidate;

bool lex_less(const Vec3& p, const Vec3& q) {
  if (p.x() != q.x()) return p.x() < q.x();
  if (p.y() != q.y()) return p.y() < q.y();
  return p.z() < q.z();
}

}  // namespace

ContactPlane choose_contact_plane(const ConvexPolyhedron& a, const Pose& pa,
                                  const ConvexPolyhedron& b, const Pose& pb, PlaneMethod method) {
  ContactScratch scratch;
  return choose_contact_plane(a, pa, b, pb, Vec3::UnitZ(), plane_detail::kInf, method, scratch);
}

namespace {

// Both entry points: the plane, or nothing when `proof_only` and the method could not prove that
// the shapes overlap (then the whole search is not run).
std::optional<ContactPlane> choose(const ConvexPolyhedron& a, const Pose& pa,
                                   const ConvexPolyhedron& b, const Pose& pb,
                                   const Vec3& known_normal, double known_overlap,
                                   PlaneMethod method, bool proof_only, ContactScratch& scratch) {
  plane_detail::Candidates& found = scratch.lists().found;
  found.kept.clear();
  found.upper = plane_detail::kInf;
  // A NaN is no bound.
  found.known = known_overlap == known_overlap ? known_overlap : plane_detail::kInf;
  found.known_normal = known_normal;
  found.within = DirectionCone{};
  found.within_a = found.within_b = -1;
  found.polytope = method != PlaneMethod::WholeSearch;
  found.proof_only = proof_only;
  found.proved = false;
  // The search on every pair: on poses the processor has not seen, it is the faster down to two
  // boxes (docs/contact_plane.md); the scan stays as its independent check.
  if (method == PlaneMethod::Automatic) method = PlaneMethod::Search;
  // The scan answers only for shapes it proves to overlap; the search for every pair.
  if (method == PlaneMethod::Scan &&
      plane_detail::scan_candidates(a, pa, b, pb, found, scratch.lists())) {
    found.proved = true;
  } else {
    found.kept.clear();
    plane_detail::search_candidates(a, pa, b, pb, found, scratch.lists());
  }
  if (proof_only && !found.proved) return std::nullopt;

  // Among the candidates within the tie margin of the least overlap: faces first, then the
  // smaller sign-free axis, then the smaller overlap. Every key so far is the geometry's, not the
  // slot's. One tie is left: the two senses of one axis with the same overlap (shapes level with
  // each other along it). No key of the geometry alone can reverse with the body order there (the
  // swapped pose is the same pose turned), so the next key is the bodies': the normal from B
  // toward A goes the way A's position lies from B's, or, level, points along the axis when A's
  // pose is the lexicographically greater (position, then orientation). Last, a face of A and a
  // face of B on one plane give the same contact: the lower PlaneAxis names it, whatever order
  // the method kept them in.
  const Vec3 apart = pa.position - pb.position;
  const bool a_greater = pa.position != pb.position
                             ? lex_less(pb.position, pa.position)
                             : std::lexicographical_compare(pb.orientation.coeffs().data(),
                                                            pb.orientation.coeffs().data() + 4,
                                                            pa.orientation.coeffs().data(),
                                                            pa.orientation.coeffs().data() + 4);
  auto toward_a = [&](const Candidate& c) {
    const double along = c.normal.dot(apart);
    return along != 0 ? along > 0 : (c.normal == c.axis) == a_greater;
  };
  auto before = [&](const Candidate& c, const Candidate& p) {
    if (c.kind != p.kind) return c.kind < p.kind;
    if (c.axis != p.axis) return lex_less(c.axis, p.axis);
    if (c.overlap != p.overlap) return c.overlap < p.overlap;
    if (toward_a(c) != toward_a(p)) return toward_a(c);
    return c.source < p.source;
  };
  double best = plane_detail::kInf;
  for (const Candidate& c : found.kept) best = std::min(best, c.overlap);
  const Candidate* pick = nullptr;
  for (const Candidate& c : found.kept)
    if (c.overlap <= best + found.tie && (!pick || before(c, *pick))) pick = &c;
  ContactPlane out;
  // No candidate kept: cannot happen (the least overlap is a candidate that no bound skips); the
  // search's upper bound keeps the answer finite should round-off prove otherwise.
  if (!pick) {
    out.normal = found.upper_normal;
    out.depth = std::max(found.upper, 0.0);
    return out;
  }
  out.normal = pick->normal;
  out.depth = std::max(pick->overlap, 0.0);
  out.axis = pick->source;
  out.vertex_a = found.within_a;
  out.vertex_b = found.within_b;
  return out;
}

}  // namespace

ContactPlane choose_contact_plane(const ConvexPolyhedron& a, const Pose& pa,
                                  const ConvexPolyhedron& b, const Pose& pb,
                                  const Vec3& known_normal, double known_overlap,
                                  PlaneMethod method, ContactScratch& scratch) {
  return *choose(a, pa, b, pb, known_normal, known_overlap, method, false, scratch);
}

ContactPlane choose_contact_plane(const ConvexPolyhedron& a, const Pose& pa,
                                  const ConvexPolyhedron& b, const Pose& pb,
                                  const Vec3& known_normal, double known_overlap,
                                  PlaneMethod method) {
  ContactScratch scratch;
  return choose_contact_plane(a, pa, b, pb, known_normal, known_overlap, method, scratch);
}

std::optional<ContactPlane> choose_overlap_plane(const ConvexPolyhedron& a, const Pose& pa,
                                                 const ConvexPolyhedron& b, const Pose& pb,
                                                 ContactScratch& scratch) {
  return choose(a, pa, b, pb, Vec3::UnitZ(), plane_detail::kInf, PlaneMethod::Automatic, true,
                scratch);
}

}  // namespace rbx
