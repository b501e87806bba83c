// The contact check: every pair in bounding range, each backend against the truth.
#include "comparisons/eval/evaluator.h"
#include "comparisons/eval/patch_cover.h"

namespace rbx::eval_detail {

void Evaluator::contact_check() {
  const std::vector<std::string> names =
      select_backends(scene_, opt_.backends, Capability::Contact, table_);
  const Backend& exact = *find_backend("exact");
  int pairs = 0;
  for (size_t i = 0; i < inputs_.size(); ++i) {
    for (size_t k = i + 1; k < inputs_.size(); ++k) {
      const RigidBody &a = inputs_[i], &b = inputs_[k];
      const bool first_pair = i == 0 && k == 1;
      if (!first_pair && (!bounding_check(a, b) || (a.is_static && b.is_static))) continue;
      ++pairs;
      contact_pair(a, b, first_pair, names, exact);
    }
  }
  if (pairs == 0) out_.skipped.push_back("contact: no pair of bodies within bounding range");
}

namespace {

// [expect.contact] binds the oracle, whatever backends run: if the exact answer (computed for
// the pair anyway) disagrees with the closed form, the derivation or the oracle is wrong.
void exact_expect_failures(const ExpectContact& ex, const SatResult& sat, const RigidBody& a,
                           const RigidBody& b, const Vec3& true_normal, double tol,
                           std::vector<std::string>& failures) {
  expect_contact_failures("exact", ex, sat.touching, sat.normal, std::max(sat.depth, 0.0), tol,
                          failures);
  if (!sat.touching) return;
  // A stated point is one model's representative point of the contact (on A, on B or between
  // them): it is right when it lies in the true contact region, where every backend's point is
  // scored too (point_err_rel): inside both bodies, or on the oracle's manifold.
  if (ex.point) {
    const double off = contact_point_error(*ex.point, a, b, sat.manifold);
    if (off > tol)
      failures.push_back("exact: [expect.contact] point " + fmt_vec(*ex.point, 8) + " lies " +
                         fmt_num(off, 3) + " m from the true contact region");
  }
  // A stated patch binds the oracle's corners the same way, across the true normal.
  expect_patch_failures("exact", ex.patch, sat.manifold, true_normal, tol, failures);
}

}  // namespace

void Evaluator::contact_pair(const RigidBody& a, const RigidBody& b, bool first_pair,
                             const std::vector<std::string>& names, const Backend& exact) {
  const std::string pair = pair_name(a, b);
  const SatResult sat = sat_query(*a.shape, a.pose(), *b.shape, b.pose());
  // Truth: the [expect.contact] closed form for the first pair, else the exact oracle.
  const ExpectContact* ex =
      first_pair && scene_.expect && scene_.expect->contact ? &*scene_.expect->contact : nullptr;
  const bool have_normal = ex && ex->normal, have_depth = ex && ex->depth;
  const bool true_touch = ex && ex->touching ? *ex->touching : sat.touching;
  const Vec3 true_normal = have_normal ? ex->normal->normalized() : sat.normal;
  const double true_depth = have_depth ? *ex->depth : std::max(sat.depth, 0.0);
  // The truth [expect] holds: a closed form ("analytic") or the oracle's answer written down.
  const std::string stated = scene_.expect ? scene_.expect->truth : "analytic";
  const std::string normal_src = have_normal ? stated : "exact";
  const std::string depth_src = have_depth ? stated : "exact";
  const double size = std::min(body_size(a), body_size(b));
  const double tol = scene_.expect ? scene_.expect->tolerance : 1e-6;
  if (ex) {
    exact_expect_failures(*ex, sat, a, b, true_normal, tol, out_.expect_failures);
    expect_contact_bound_ = true;
  }

  std::vector<const Backend*> subjects;
  for (const std::string& name : names)
    subjects.push_back(name == "exact" ? &exact : &backend(name));
  const PairRuns runs = contact_runs(subjects, a, b, cache_, opt_.timing_budget_s);
  for (size_t i = 0; i < names.size(); ++i) {
    const std::string& name = names[i];
    const ContactRun& run = runs.runs[i];
    set_status(name, run.result.status, run.result.message);
    Json& bj = backend_json(name);
    bj["runtime_s"] = bj["runtime_s"].get<double>() + run.timing.median_s;
    if (run.cached) bj["cached"] = true;
    for (const ContactPoint& p : run.result.contacts)
      bj["contacts"].push_back(contact_json(a.name, b.name, 0.0, p));
    const ContactTruth truth{true_touch, true_normal, true_depth, size, centres_direction(a, b)};
    if (run.result.status == Status::Touching) {
      touching_answer(name, pair, run.result, truth, std::max(tol, 1e-6 * size),
                      ex && ex->touching ? stated : "exact", depth_src);
      // Timed like any answer; no normal to score: its error is the depth it is scored at.
      out_.error_vs_runtime.push_back(
          {name, "contact-touching", 0.0, run.timing, true_touch ? true_depth : 0.0, depth_src});
      continue;
    }
    if (run.result.status != Status::Ok) {
      failed_call(name + " on " + pair, run.result.status, run.result.message);
      continue;
    }

    const ContactPoint* c = deepest(run.result);
    const bool touch = c != nullptr;
    metric("contact", name, pair, "touching_err", touching_error(run.result, true_touch),
           ex && ex->touching ? stated : "exact");
    if (touch != true_touch) {
      out_.disagreements.push_back(
          name + " on " + pair + ": " +
          (touch ? "reports a contact where there is none" : "misses a contact"));
      if (auto cause = contact_cause(name, scene_.name, run.result, truth, 0.0))
        out_.causes.push_back(*cause);
    }
    if (!touch || !true_touch) continue;
    double angle = angle_deg(c->normal, true_normal);
    // A closed form that accepts either sign (a tie by symmetry): the nearer one.
    if (have_normal && ex->either_sign) angle = std::min(angle, 180.0 - angle);
    // Ties: where several directions give the same minimum translation (a cube on another's
    // diagonal: x, y and z), any of them is right. Against the oracle, a normal along which
    // the overlap equals the true depth (within round-off) has no angle error.
    if (!have_normal && angle > 0 && ties_true_depth(a, b, c->normal, true_depth, size))
      angle = 0.0;
    const double derr = std::abs(c->depth - true_depth);
    metric("contact", name, pair, "normal_err_deg", angle, normal_src);
    metric("contact", name, pair, "depth_err", derr, depth_src);
    if (sat.touching && !sat.manifold.empty()) point_metrics(name, pair, run.result, *c, sat, a, b);
    out_.error_vs_runtime.push_back({name, "contact", 0.0, run.timing, angle, normal_src});
    // The same query with the library's shapes built once (its "prebuilt" variant): the
    // figures time both, so that the cost of building a shape shows apart from the query.
    if (const std::optional<ContactRun>& pr = runs.prebuilt[i]) {
      const ContactPoint* pc = deepest(pr->result);
      if (pr->result.status != Status::Ok || !pc || !same_answer(*c, *pc))
        out_.disagreements.push_back(name + " on " + pair +
                                     ": the prebuilt variant answers differently");
      else
        out_.error_vs_runtime.push_back(
            {name, "contact-prebuilt", 0.0, pr->timing, angle, normal_src});
    }
    // Disagreement marks: beyond round-off-level tolerance of the truth (1e-6 rad ~ 6e-5 deg;
    // depth within the scene's tolerance or 1e-6 of the body size).
    const double depth_tol = std::max(tol, 1e-6 * size);
    if (angle > 1e-3 || derr > depth_tol) {
      std::ostringstream s;
      s << name << " on " << pair << ": normal off by " << fmt_num(angle, 3)
        << " deg, depth off by " << fmt_num(derr, 3) << " m (against " << normal_src << ")";
      const bool clear = angle > kMarkAngleDeg || derr > kMarkDepthRel * size;
      (clear ? out_.disagreements : out_.deviations).push_back(s.str());
      if (auto cause = contact_cause(name, scene_.name, run.result, truth, angle))
        out_.causes.push_back(*cause);
    }
    // [expect.contact] binds the engine under test too, like [expect.body]: a violation
    // fails the scene unless the scene documents it as a known failure.
    if (binds(name) && ex) {
      expect_contact_failures(name, *ex, touch, c->normal, c->depth, tol, out_.expect_failures);
      std::vector<Vec3> points;
      for (const ContactPoint& p : run.result.contacts) points.push_back(p.point);
      // Across the engine's own normal where it is one of the tied axes the truth allows (two
      // coincident cubes: any face's; angle 0 above), else across the truth's.
      const Vec3 across = !have_normal && angle == 0.0 ? c->normal.normalized() : true_normal;
      expect_patch_failures(name, ex->patch, points, across, tol, out_.expect_failures);
    }
  }
}

void Evaluator::point_metrics(const std::string& name, const std::string& pair,
                              const ContactResult& r, const ContactPoint& deepest,
                              const SatResult& sat, const RigidBody& a, const RigidBody& b) {
  const double size = std::min(body_size(a), body_size(b));
  metric("contact", name, pair, "point_err_rel",
         contact_point_error(deepest.point, a, b, sat.manifold) / size, "exact");
  // The whole set against the exact patch (patch_cover.h): a backend that returns one right
  // point and one that returns the patch differ here, not in point_err_rel.
  const SatPatch truth = true_patch(r, a, b, sat);
  const PatchCover cover = patch_cover(r.contacts, a, b, truth.corners, truth.normal);
  metric("contact", name, pair, "contact_points", cover.points, "exact");
  metric("contact", name, pair, "worst_point_err_rel", cover.worst_point_err / size, "exact");
  metric("contact", name, pair, "coverage_err_rel", cover.coverage_err / size, "exact");
  if (cover.support_err) metric("contact", name, pair, "support_err", *cover.support_err, "exact");
}

void Evaluator::touching_answer(const std::string& name, const std::string& pair,
                                const ContactResult& r, const ContactTruth& t, double depth_tol,
                                const std::string& touch_src, const std::string& depth_src) {
  metric("contact", name, pair, "touching_err", t.touching ? 0.0 : 1.0, touch_src);
  if (!t.touching)
    out_.disagreements.push_back(name + " on " + pair + ": reports a contact where there is none");
  if (t.touching) metric("contact", name, pair, "depth_err", t.depth, depth_src);
  if (t.touching && t.depth > depth_tol)
    (t.depth > kMarkDepthRel * t.size ? out_.disagreements : out_.deviations)
        .push_back(name + " on " + pair + ": reports touching with no normal on a pair " +
                   fmt_num(t.depth, 3) + " m deep (a miss)");
  if (auto c = contact_cause(name, scene_.name, r, t, 0.0)) out_.causes.push_back(*c);
}

}  // namespace rbx::eval_detail
