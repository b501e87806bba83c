#include "comparisons/eval/contact_cause.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "comparisons/eval/contact_eval.h"
#include "engine/format.h"

namespace rbx {

namespace {

// A depth off by round-off only, relative to the body: the harness's floor for a depth error.
constexpr double kRoundOffDepthRel = 1e-6;

// How near a ratio of depths must be to 1/2 to be called "half": a factor named, not a fit (a
// depth off by another amount is "too shallow", with its ratio in the detail).
constexpr double kHalfRatioTol = 5e-3;

// A point "carries another face's normal" when its normal is this far from the truth (a face
// of a box turned by 90 deg, of a hull by its dihedral angles; 45 deg is far from both 0 and any
// round-off) while another point of the same answer is within the mark.
constexpr double kOtherFaceDeg = 45.0;

}  // namespace

std::optional<Cause> contact_cause(const std::string& backend, const std::string& scene,
                                   const ContactResult& r, const ContactTruth& t,
                                   double deepest_angle) {
  namespace s = contact_sign;
  Cause c;
  c.backend = backend;
  c.scene = scene;
  c.check = "contact";
  std::ostringstream d;
  if (r.status == Status::Touching) {
    if (!t.touching) {
      c.kind = s::kFalseContact;
      c.detail = "touching with no normal on a separated pair";
    } else if (t.depth > kRoundOffDepthRel * t.size) {
      c.kind = s::kTouchingWhenDeep;
      d << "true depth " << fmt_num(t.depth, 3) << " m";
      c.detail = d.str();
    } else {
      c.kind = s::kTouchingAtZeroDepth;
      d << "true depth " << fmt_num(t.depth, 3) << " m";
      c.detail = d.str();
    }
    return c;
  }
  if (r.status != Status::Ok) return std::nullopt;
  const ContactPoint* p = deepest(r);
  if ((p != nullptr) != t.touching) {
    c.kind = p ? s::kFalseContact : s::kMissed;
    d << (p ? "reported depth " + fmt_num(p->depth, 3) : "true depth " + fmt_num(t.depth, 3))
      << " m";
    c.detail = d.str();
    return c;
  }
  if (!p) return std::nullopt;
  const double derr = std::abs(p->depth - t.depth);
  if (deepest_angle <= kMarkAngleDeg && derr <= kMarkDepthRel * t.size) return std::nullopt;

  d << r.contacts.size() << (r.contacts.size() == 1 ? " point" : " points") << "; deepest normal "
    << fmt_num(deepest_angle, 3) << " deg off, depth " << fmt_num(p->depth, 3) << " m against "
    << fmt_num(t.depth, 3) << " m";
  c.detail = d.str();
  size_t right = 0, other = 0;
  for (const ContactPoint& q : r.contacts) {
    const double a = angle_deg(q.normal, t.normal);
    right += a <= kMarkAngleDeg;
    other += a >= kOtherFaceDeg;
  }
  if (right > 0 && other > 0) {
    c.kind = s::kMixedNormals;
    c.detail += "; " + std::to_string(other) + " of " + std::to_string(r.contacts.size()) +
                " points over 45 deg off";
    return c;
  }
  if (deepest_angle > kMarkAngleDeg) {
    const double centre_line = angle_deg(p->normal, t.centres);
    const bool truth_on_line = angle_deg(t.normal, t.centres) <= kMarkAngleDeg;
    if (t.centres.norm() > 0.5 && centre_line <= kMarkAngleDeg && !truth_on_line) {
      c.kind = s::kCentreLine;
      c.detail += "; " + fmt_num(centre_line, 2) + " deg from the centres' line";
    } else {
      c.kind = s::kWrongNormal;
    }
    return c;
  }
  // The normal is right: the depth's sign and size.
  const double ratio = t.depth > 0 ? p->depth / t.depth : 0.0;
  if (t.depth > 0) c.detail += " (ratio " + fmt_num(ratio, 4) + ")";
  if (p->depth < 0 && std::abs(p->depth + t.depth) <= kMarkDepthRel * t.size)
    c.kind = s::kNegatedDepth;
  else if (t.depth > 0 && std::abs(ratio - 0.5) <= kHalfRatioTol)
    c.kind = s::kHalfDepth;
  else
    c.kind = p->depth > t.depth ? s::kTooDeep : s::kTooShallow;
  return c;
}

}  // namespace rbx
