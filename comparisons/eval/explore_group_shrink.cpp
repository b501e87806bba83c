// Shrinking one of `rbx explore`'s disagreement groups: its first sample simplified while the
// disagreement stays, written as a scene with its truth as [expect] and the comment that says
// where it was found and how to reproduce it, and checked through the harness.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "comparisons/eval/contact_eval.h"
#include "comparisons/eval/distance_query.h"
#include "comparisons/eval/explore.h"
#include "comparisons/eval/explore_detail.h"
#include "comparisons/eval/json_io.h"
#include "comparisons/eval/metrics.h"
#include "comparisons/scene/mesh_io.h"
#include "comparisons/scene/scene_file.h"
#include "engine/bounding.h"
#include "engine/format.h"
#include "reference/exact.h"

namespace rbx::explore_detail {

namespace {

// Whether a direction of least overlap other than `normal` (or its reverse) gives the same depth:
// the face normals of either shape and the directions across an edge of each, the oracle's
// candidate axes. Two boxes overlapping as much along x as along z tie; so do faces of a hull
// meeting another's at equal depth.
bool another_axis_ties(const RigidBody& a, const RigidBody& b, const Vec3& normal, double depth,
                       double size) {
  auto tie = [&](const Vec3& d) {
    if (!(d.norm() > 1e-9)) return false;
    const Vec3 u = d.normalized();
    // The same axis, to round-off of unit normals: not another one.
    if ((u - normal).norm() < 1e-9 || (u + normal).norm() < 1e-9) return false;
    return ties_true_depth(a, b, u, depth, size) || ties_true_depth(a, b, -u, depth, size);
  };
  const Mat3 ra = a.orientation.toRotationMatrix(), rb = b.orientation.toRotationMatrix();
  for (const Plane& p : a.shape->planes())
    if (tie(ra * p.normal)) return true;
  for (const Plane& p : b.shape->planes())
    if (tie(rb * p.normal)) return true;
  const auto& va = a.shape->vertices();
  const auto& vb = b.shape->vertices();
  for (const Edge& ea : a.shape->edges())
    for (const Edge& eb : b.shape->edges())
      if (tie((ra * (va[ea.b] - va[ea.a])).cross(rb * (vb[eb.b] - vb[eb.a])))) return true;
  return false;
}

}  // namespace

// The [expect] block of a shrunk scene: the exact oracle's answer at the t = 0 poses.
std::string expect_block(const std::string& text) {
  const Scene scene = parse_scene(text, "explore.toml");
  const std::vector<RigidBody> bodies = make_bodies(scene);
  const SatResult sat =
      sat_query(*bodies[0].shape, bodies[0].pose(), *bodies[1].shape, bodies[1].pose());
  const double size = std::min(shape_size(*bodies[0].shape), shape_size(*bodies[1].shape));
  NumberFormat full;  // every digit, as the oracle computed it
  full.digits = 17;
  full.signed_zero = true;
  std::ostringstream o;
  o << "# Truth: the exact oracle (separating axes over faces and edge pairs), not a closed form.\n"
       "# Tolerance: 1e-6 of the smaller body (round-off of exact methods is ~1e-15 relative;\n"
       "# the disagreements explore looks for are above 1 degree or 1 % of that size).\n";
  o << "[expect]\ntruth = \"exact\"\n";
  o << "tolerance = " << fmt_num(std::max(1e-12, 1e-6 * size), 3) << "\n[expect.contact]\n"
    << "touching = " << (sat.touching ? "true" : "false") << "\n";
  // A pair as deep along the reversed normal (a body centred in another) is a tie by symmetry:
  // either sign is right, and each takes the patch on its own side, so none is stated.
  const bool mirrored =
      sat.touching && ties_true_depth(bodies[0], bodies[1], -sat.normal, sat.depth, size);
  // Another axis as deep (two boxes overlapping as much along x as along z): any of them is
  // right, each with the patch on its own plane, so neither the normal nor the patch is stated
  // and the harness's rule for ties against the oracle decides (docs/contract.md).
  const bool tied = sat.touching && !mirrored &&
                    another_axis_ties(bodies[0], bodies[1], sat.normal, sat.depth, size);
  if (sat.touching) {
    if (tied)
      o << "# Several directions give this least overlap; the normal is any of them.\n";
    else
      o << "normal = [" << format_number(sat.normal.x(), full) << ", "
        << format_number(sat.normal.y(), full) << ", " << format_number(sat.normal.z(), full)
        << "]\n";
    o << "depth = " << format_number(std::max(sat.depth, 0.0), full) << "\n";
  }
  if (mirrored) o << "either_sign = true\n";
  if (sat.touching && !sat.manifold.empty() && !mirrored && !tied) {
    // The oracle's contact patch (docs/contact_manifold.md), compared across the normal.
    o << "patch = [";
    for (size_t k = 0; k < sat.manifold.size(); ++k) {
      const Vec3& c = sat.manifold[k];
      o << (k ? ",\n         [" : "[") << format_number(c.x(), full) << ", "
        << format_number(c.y(), full) << ", " << format_number(c.z(), full) << "]";
    }
    o << "]\n";
  }
  return o.str();
}

std::string describe_outcome(const BackendOutcome& b) {
  std::ostringstream o;
  if (b.error == "error" || b.error == "timeout") {
    // One line: the message goes into a scene file's comment.
    std::string m = b.message;
    std::replace(m.begin(), m.end(), '\n', ' ');
    std::replace(m.begin(), m.end(), '\r', ' ');
    return "status " + b.error + ": " + m;
  }
  if (b.error == "misses") return "misses a contact";
  if (b.error == "overlap") return "says the pair overlaps; it is apart";
  if (b.error == "false_distance") return "gives a distance to an overlapping pair";
  if (b.error == "distance" || b.error == "witness")
    return "distance off by " + fmt_num(b.distance_err_rel, 3) + ", witness points off by " +
           fmt_num(b.witness_err_rel, 3) + " of the true distance";
  if (b.error == "early" || b.error == "late")
    return "first touch " + fmt_num(b.time_err, 3) + " of the interval " + b.error + ", the pair " +
           (b.separation_m >= 0 ? fmt_num(b.separation_m, 3) + " m apart"
                                : "overlapping by " + fmt_num(-b.separation_m, 3) + " m") +
           " then";
  if (b.error == "coverage")
    return "its points fall short of the exact contact patch by " + fmt_num(b.coverage_err_rel, 3) +
           " of the smaller body";
  if (b.error == "no_normal") return "reports touching with no normal on a penetrating pair";
  if (b.error == "false_contact") return "reports a contact where there is none";
  if (b.error == "missed") return "the body flew on untouched (no impulse)";
  if (b.error == "tunnel")
    return "ends past the wall's near face (through it or inside), " +
           fmt_num(b.position_err_m, 3) + " m from the closed form, velocity error " +
           fmt_num(b.velocity_err_ke, 3);
  if (b.error == "velocity")
    return "bounces off the wall with velocity error " + fmt_num(b.velocity_err_ke, 3) +
           " (energy norm)";
  if (b.error == "impulse" || b.error == "spin")
    return "velocity error " + fmt_num(b.velocity_err_ke, 3) + ", momentum error " +
           fmt_num(b.momentum_err_ke, 3) + " (energy norm; " +
           (b.error == "impulse" ? "the impulse is wrong"
                                 : "the impulse is right, the spin after it is not") +
           ")";
  if (b.error == "deep_contact")
    return "rests " + fmt_num(b.position_err_m, 3) + " m from the closed form, turned by " +
           fmt_num(b.turn_rad, 3) + " rad, after its collider reported a contact " +
           fmt_num(b.reported_depth_m, 3) + " m deep (no landing or resting box is)";
  if (b.error == "cone_excess")
    return "rests " + fmt_num(b.position_err_m, 3) + " m from the closed form, turned by " +
           fmt_num(b.turn_rad, 3) +
           " rad, by friction beyond the Coulomb cone (measured on the library's own impulses: "
           "friction at contact points that carry no normal impulse; the closed form's friction "
           "is bounded by mu times the push)";
  if (b.error == "lift_off")
    return "rests " + fmt_num(b.position_err_m, 3) + " m from the closed form, turned by " +
           fmt_num(b.turn_rad, 3) + " rad, its time to rest off by " +
           fmt_num(b.rest_time_err_s, 3) + " s, after it rose " + fmt_num(b.rise_m, 3) +
           " m off its surface while sliding (the closed form's box never leaves it)";
  if (b.error == "late_landing")
    return "rests " + fmt_num(b.position_err_m, 3) +
           " m off along its launch: the landing resolved at the step after the touch (no time "
           "of impact), the slide of the rest of that step, or less where the deeper landing "
           "pushed back harder and its friction took more of the slide (Coulomb's throughout, "
           "measured on the run's steps)";
  if (b.error == "position" || b.error == "turn" || b.error == "rest_time")
    return "rests " + fmt_num(b.position_err_m, 3) + " m from the closed form, turned by " +
           fmt_num(b.turn_rad, 3) + " rad, its time to rest off by " +
           fmt_num(b.rest_time_err_s, 3) + " s";
  o << "normal off by " << fmt_num(b.normal_err_deg, 3) << " deg, depth off by "
    << fmt_num(b.depth_err_rel, 3) << " and its worst point off by " << fmt_num(b.point_err_rel, 3)
    << " of the smaller body";
  return o.str();
}

BackendOutcome outcome_of(const SampleOutcome& o, const std::string& backend) {
  BackendOutcome found;
  for (const BackendOutcome& b : o.backends)
    if (b.backend == backend) found = b;
  return found;
}

bool shows_signature(const SampleOutcome& o, const std::string& sig, SampleOutcome* out) {
  for (const BackendOutcome& b : o.backends)
    if (!b.error.empty() && signature(o, b) == sig) {
      if (out) *out = o;
      return true;
    }
  return false;
}

std::string points_shrunk(int before, int after, int kept, int tried) {
  return "from " + std::to_string(before) + " to " + std::to_string(after) + " points (" +
         std::to_string(kept) + " simplifications kept, " + std::to_string(tried) + " tried)";
}

namespace {

// What a group's shrink sends back to rank 0, as JSON text: the scene, whether the harness
// shows the disagreement on it, and the kind's own `fields`.
std::string shrunk_json(const std::string& text, const BackendOutcome& found, Json fields) {
  std::string detail;
  fields["ok"] = true;
  fields["text"] = text;
  fields["reproduced"] = harness_reproduces(text, "explore.toml", found, &detail);
  fields["harness"] = detail;
  fields["message"] = found.message;
  return fields.dump();
}

// The leading comment of a shrunk closed-form scene (impact, landing kinds): where it was
// found, what the backend does on it, how it was shrunk (`shrunk`), how to reproduce it.
std::string closed_form_header(const std::string& kind, uint64_t seed, long count, uint64_t index,
                               const Json& g, const BackendOutcome& found,
                               const std::string& shrunk) {
  const std::string backend = g["backend"], sig = g["signature"];
  std::ostringstream h;
  h << "# Found by `rbx explore --kind " << kind << " --seed " << seed << " --count " << count
    << "`: sample " << index << ", group '" << sig << "',\n# " << g["count"].get<long>()
    << " samples. " << backend << " against the closed form: " << describe_outcome(found) << ".\n"
    << "# Shrunk " << shrunk << ", while the disagreement stayed.\n"
    << "# Reproduce: rbx compare THIS_FILE --backends " << backend << "\n";
  return h.str();
}

// One contact group's shrink: the scene's [expect] is the exact oracle's answer.
std::string shrink_contact_group(const Json& g, uint64_t seed, long count, int budget) {
  const ContactSample start = make_contact_sample(seed, g["first_sample"].get<uint64_t>());
  const std::string backend = g["backend"], sig = g["signature"];
  const ShrinkResult r = shrink(start, backend, sig, budget);
  const BackendOutcome found = outcome_of(r.outcome, backend);
  // The start's own text not showing the signature should not happen (the text is built as
  // the sample is); it is reported instead of writing a scene that shows nothing.
  if (found.error.empty()) return Json{{"ok", false}}.dump();
  std::ostringstream h;
  h << "# Found by `rbx explore --seed " << seed << " --count " << count << "`: sample "
    << start.index << " (" << start.pose_class << " pose), group '" << sig << "',\n# "
    << g["count"].get<long>() << " samples. " << backend
    << " against the exact oracle: " << describe_outcome(found) << ".\n# Shrunk "
    << points_shrunk(r.vertices_before, r.vertices_after, r.steps_accepted, r.evaluations)
    << ", while the disagreement stayed.\n# Reproduce: rbx compare THIS_FILE --backends " << backend
    << "\n";
  const std::string body = sample_scene_text(r.sample, h.str());
  return shrunk_json(body + "\n" + expect_block(body), found,
                     {{"points_before", r.vertices_before},
                      {"points_after", r.vertices_after},
                      {"evaluations", r.evaluations},
                      {"normal_err_deg", found.normal_err_deg},
                      {"depth_err_rel", found.depth_err_rel},
                      {"point_err_rel", found.point_err_rel}});
}

// One closed-form group's shrink (impact, landing kinds): the scene carries its closed form
// ([expect]) already. `make` and `shrink` are the kind's sampler and shrinker; `how` says how
// the shrink went and `numbers` are the kind's measures in the record, both from its result.
template <class Make, class Shrink, class How, class Numbers>
std::string shrink_closed_form_group(const char* kind, const Json& g, uint64_t seed, long count,
                                     int budget, Make make, Shrink shrink, How how,
                                     Numbers numbers) {
  const auto start = make(seed, g["first_sample"].get<uint64_t>());
  const std::string backend = g["backend"], sig = g["signature"];
  const auto r = shrink(start, backend, sig, budget);
  const BackendOutcome found = outcome_of(r.outcome, backend);
  if (found.error.empty()) return Json{{"ok", false}}.dump();
  return shrunk_json(
      closed_form_header(kind, seed, count, start.index, g, found, how(r)) + r.sample.text, found,
      numbers(r, found));
}

std::string shrink_impact_group(const Json& g, uint64_t seed, long count, int budget) {
  return shrink_closed_form_group(
      "impact", g, seed, count, budget, make_impact_sample, shrink_impact,
      [](const ImpactShrinkResult& r) {
        return points_shrunk(r.vertices_before, r.vertices_after, r.steps_accepted, r.evaluations);
      },
      [](const ImpactShrinkResult& r, const BackendOutcome& found) {
        return Json{{"points_before", r.vertices_before},
                    {"points_after", r.vertices_after},
                    {"evaluations", r.evaluations},
                    {"phase", r.sample.phase},
                    {"velocity_err_ke", found.velocity_err_ke},
                    {"momentum_err_ke", found.momentum_err_ke}};
      });
}

// A landing's box keeps its 8 points: its shrink moves numbers toward round ones.
std::string shrink_landing_group(const Json& g, uint64_t seed, long count, int budget) {
  return shrink_closed_form_group(
      "landing", g, seed, count, budget, make_landing_sample, shrink_landing,
      [](const LandingShrinkResult& r) {
        return "toward round numbers (" + std::to_string(r.steps_accepted) +
               " simplifications kept, " + std::to_string(r.evaluations) + " tried)";
      },
      [](const LandingShrinkResult& r, const BackendOutcome& found) {
        return Json{{"evaluations", r.evaluations},
                    {"phase", r.sample.phase},
                    {"position_err_m", found.position_err_m},
                    {"turn_rad", found.turn_rad},
                    {"rest_time_err_s", found.rest_time_err_s}};
      });
}

// A slide's box, too: its shrink moves numbers toward round ones.
std::string shrink_slide_group(const Json& g, uint64_t seed, long count, int budget) {
  return shrink_closed_form_group(
      "slide", g, seed, count, budget, make_slide_sample, shrink_slide,
      [](const SlideShrinkResult& r) {
        return "toward round numbers (" + std::to_string(r.steps_accepted) +
               " simplifications kept, " + std::to_string(r.evaluations) + " tried)";
      },
      [](const SlideShrinkResult& r, const BackendOutcome& found) {
        return Json{{"evaluations", r.evaluations},
                    {"position_err_m", found.position_err_m},
                    {"turn_rad", found.turn_rad},
                    {"rest_time_err_s", found.rest_time_err_s}};
      });
}

// A projectile's box keeps its 8 points: its shrink moves numbers toward round ones.
std::string shrink_tunnel_group(const Json& g, uint64_t seed, long count, int budget) {
  return shrink_closed_form_group(
      "tunnel", g, seed, count, budget, make_tunnel_sample, shrink_tunnel,
      [](const TunnelShrinkResult& r) {
        return "toward round numbers (" + std::to_string(r.steps_accepted) +
               " simplifications kept, " + std::to_string(r.evaluations) + " tried)";
      },
      [](const TunnelShrinkResult& r, const BackendOutcome& found) {
        return Json{{"evaluations", r.evaluations},
                    {"phase", r.sample.phase},
                    {"velocity_err_ke", found.velocity_err_ke},
                    {"position_err_m", found.position_err_m}};
      });
}

// One distance group: its first sample shrunk (shrink_with) while the backend's own distance
// query still shows the group's signature, reproduced when `rbx distance`'s comparison of the
// written scene marks the backend.
std::string distance_group(const Json& g, uint64_t seed, long count, int budget) {
  const ContactSample start = make_distance_sample(seed, g["first_sample"].get<uint64_t>());
  const std::string backend = g["backend"], sig = g["signature"];
  const ShrinkResult r = shrink_with(
      start,
      [&](const ContactSample& c, SampleOutcome* out) {
        return shows_signature(evaluate_distance_sample(c, {backend}), sig, out);
      },
      budget);
  const BackendOutcome found = outcome_of(r.outcome, backend);
  if (found.error.empty()) return Json{{"ok", false}}.dump();
  std::ostringstream h;
  h << "# Found by `rbx explore --kind distance --seed " << seed << " --count " << count
    << "`: sample " << start.index << " (" << start.pose_class << " gap), group '" << sig
    << "',\n# " << g["count"].get<long>() << " samples. " << backend
    << " against the exact oracle: " << describe_outcome(found) << ".\n# Shrunk "
    << points_shrunk(r.vertices_before, r.vertices_after, r.steps_accepted, r.evaluations)
    << ", while the disagreement stayed.\n# Reproduce: rbx distance THIS_FILE --backends "
    << backend << "\n";
  // The oracle's answer on the shrunk pair, stated: rbx distance checks it, and custom by it.
  const RigidBody sa = build_body(r.sample.a, "A"), sb = build_body(r.sample.b, "B");
  const ExactDistance truth = exact_distance(*sa.shape, sa.pose(), *sb.shape, sb.pose());
  const std::string text = sample_scene_text(r.sample, h.str()) +
                           "\n[expect]\ntruth = \"exact\"\n\n[expect.distance]\n" +
                           (truth.overlapping ? std::string("overlapping = true\n")
                                              : "distance = " + num(truth.distance) + "\n");
  const DistanceComparison c = compare_distances(parse_scene(text, "explore.toml"), {backend}, 0.0);
  const DistanceRow& row = c.pairs.at(0).rows.at(0);
  // A status error is the row's answer, not a mark: reproduced when the written scene's is one.
  const bool failed = row.result.status != Status::Ok;
  Json fields = {
      {"ok", true},
      {"text", text},
      {"reproduced", row.verdict.mark == "disagrees" ||
                         (failed && (found.error == "error" || found.error == "timeout"))},
      {"harness", "rbx distance: " + (failed ? std::string("status ") + to_string(row.result.status)
                                      : row.verdict.why.empty() ? std::string("no mark")
                                                                : row.verdict.why)},
      {"message", found.message},
      {"points_before", r.vertices_before},
      {"points_after", r.vertices_after},
      {"evaluations", r.evaluations},
      {"distance_err_rel", found.distance_err_rel},
      {"witness_err_rel", found.witness_err_rel}};
  return fields.dump();
}

}  // namespace

std::string shrink_group(const Json& group, const ExploreSettings& set) {
  try {
    if (set.kind == "impact")
      return shrink_impact_group(group, set.seed, set.count, std::min(set.shrink_budget, 120));
    if (set.kind == "landing")
      return shrink_landing_group(group, set.seed, set.count, std::min(set.shrink_budget, 60));
    if (set.kind == "slide")
      return shrink_slide_group(group, set.seed, set.count, std::min(set.shrink_budget, 60));
    if (set.kind == "tunnel")
      return shrink_tunnel_group(group, set.seed, set.count, std::min(set.shrink_budget, 60));
    // The oracle's closed form visits every feature pair: fewer tries than the contact kind's.
    if (set.kind == "distance")
      return distance_group(group, set.seed, set.count, std::min(set.shrink_budget, 150));
    if (set.kind == "toi")
      return toi_group(group, set.seed, set.count, std::min(set.shrink_budget, 100));
    return shrink_contact_group(group, set.seed, set.count, set.shrink_budget);
  } catch (const std::exception& e) {
    return Json{{"ok", false}, {"message", e.what()}}.dump();
  }
}

}  // namespace rbx::explore_detail
