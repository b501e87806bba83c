#include "comparisons/eval/contacts_query.h"

#include <algorithm>
#include <cmath>

#include "comparisons/eval/harness.h"
#include "comparisons/eval/measures.h"
#include "engine/bounding.h"
#include "engine/detect.h"
#include "engine/format.h"
#include "engine/world.h"
#include "reference/backend.h"
#include "reference/exact.h"

namespace rbx {

namespace {

// True when some pair of bodies (not both static) touches by the exact oracle's test.
bool any_pair_touches(const std::vector<RigidBody>& bodies) {
  for (size_t i = 0; i < bodies.size(); ++i)
    for (size_t j = i + 1; j < bodies.size(); ++j) {
      const RigidBody &a = bodies[i], &b = bodies[j];
      if ((a.is_static && b.is_static) || !bounding_check(a, b)) continue;
      if (sat_query(*a.shape, a.pose(), *b.shape, b.pose()).touching) return true;
    }
  return false;
}

// Where the bodies are at the first step whose start has a touching pair: the seed model's motion
// (`custom-seed`'s engine, which we can stop at a step), tested by the oracle before the engine
// resolves anything.
// Sets `step` (-1: no pair touches within the run) and the stop reason.
std::vector<RigidBody> first_contact_state(const Scene& scene, long& step, std::string& why) {
  World world(scene.sim, make_bodies(scene), ContactModel::Seed);
  const long steps = scene.sim.steps();
  step = -1;
  while (true) {
    if (any_pair_touches(world.bodies())) {
      step = world.steps_taken();
      break;
    }
    if (world.steps_taken() >= steps) break;
    if (!world.step()) {
      why = world.failure();
      break;
    }
  }
  return world.bodies();
}

// The marks of `compare` (harness.h): clearly different from the oracle (disagrees), or beyond
// round-off of it (deviates: 1e-3 deg, the scene's tolerance or 1e-6 of the body size in depth).
std::string mark_of(double angle, double derr, double size, double tol) {
  if (angle > kMarkAngleDeg || derr > kMarkDepthRel * size) return "disagrees";
  if (angle > 1e-3 || derr > std::max(tol, 1e-6 * size)) return "deviates";
  return "";
}

// One backend's row on pair (a, b): its JSON into `bj`, its mark into `marks`.
ContactsRow compare_row(const std::string& name, const ContactRun& run, const ContactPoint* t,
                        const SatResult& sat, const RigidBody& a, const RigidBody& b, double tol,
                        Json& bj, std::vector<std::string>& marks) {
  ContactsRow row;
  row.backend = name;
  row.run = run;
  const ContactPoint* c = deepest(run.result);
  if (run.result.status != Status::Ok) {
    bj["status"] = to_string(run.result.status);
    bj["message"] = run.result.message;
  } else if (!run.result.message.empty() && bj["message"] == "") {
    bj["message"] = run.result.message;  // e.g. a known-defect note
  }
  bj["runtime_s"] = bj["runtime_s"].get<double>() + run.timing.median_s;
  for (const ContactPoint& p : run.result.contacts)
    bj["contacts"].push_back(contact_json(a.name, b.name, 0.0, p));
  Json pair = {{"bodies", {a.name, b.name}},
               {"status", to_string(run.result.status)},
               {"touching", c != nullptr}};
  put_timing(run.timing, pair);
  if (c && t) {
    pair["normal_err_deg"] = angle_deg(c->normal, t->normal);
    pair["depth_err"] = c->depth - t->depth;
    row.angle = fmt_num(pair["normal_err_deg"].get<double>(), 3);
    row.depth_diff = fmt_num(pair["depth_err"].get<double>(), 3);
    const double size = 2.0 * std::min(bounding_sphere(a).radius, bounding_sphere(b).radius);
    // The harness's rule for ties: a tied normal is as right as the oracle's, and is marked as
    // such.
    double angle = pair["normal_err_deg"].get<double>();
    if (angle > 0 && ties_true_depth(a, b, c->normal, t->depth, size)) {
      angle = 0.0;
      row.angle += " (tie)";
    }
    row.mark = mark_of(angle, std::abs(c->depth - t->depth), size, tol);
    if (sat.touching && !sat.manifold.empty()) {
      const SatPatch truth = true_patch(run.result, a, b, sat);
      row.cover = patch_cover(run.result.contacts, a, b, truth.corners, truth.normal);
      row.size = std::min(body_size(a), body_size(b));
      pair["contact_points"] = row.cover->points;
      pair["worst_point_err_rel"] = row.cover->worst_point_err / row.size;
      pair["coverage_err_rel"] = row.cover->coverage_err / row.size;
      if (row.cover->support_err) pair["support_err"] = *row.cover->support_err;
    }
    if (!row.mark.empty())
      marks.push_back(row.mark + ": " + name + " on " + a.name + "-" + b.name + ": normal off by " +
                      row.angle + " deg, depth off by " +
                      fmt_num(std::abs(c->depth - t->depth), 3) + " m (against exact)");
  } else if (run.result.status == Status::Ok) {
    pair["touching_agrees"] = (c != nullptr) == (t != nullptr);
    if ((c != nullptr) != (t != nullptr)) {
      row.angle = c ? "false contact" : "missed";
      row.mark = "disagrees";
      marks.push_back("disagrees: " + name + " on " + a.name + "-" + b.name + ": " +
                      (c ? "reports a contact where there is none" : "misses a contact"));
    }
  }
  pair["mark"] = row.mark;
  bj["pairs"].push_back(pair);
  return row;
}

// The document `rbx contacts --json` writes, around the backends' part.
Json contacts_json(const Scene& scene, const ContactsComparison& c, const Json& backends_json) {
  Json result;
  result["scene"] = scene.name;
  result["file"] = scene.file;
  if (c.at_first) {
    result["at"] = {{"query", "first-contact"},
                    {"step", c.contact_step},
                    {"time", c.contact_step >= 0 ? c.contact_step * scene.sim.dt : -1.0},
                    {"message", c.stop_reason}};
  }
  result["disagreements"] = Json::array();
  result["deviations"] = Json::array();
  for (const std::string& m : c.marks)
    result[m.rfind("disagrees", 0) == 0 ? "disagreements" : "deviations"].push_back(
        m.substr(m.find(": ") + 2));
  result["backends"] = backends_json;
  return result;
}

}  // namespace

ContactsComparison compare_contacts(const Scene& scene, const std::vector<std::string>& names,
                                    bool at_first, double budget_s) {
  ContactsComparison c;
  c.at_first = at_first;
  const std::vector<RigidBody> bodies =
      at_first ? first_contact_state(scene, c.contact_step, c.stop_reason) : make_bodies(scene);
  const double tol = scene.expect ? scene.expect->tolerance : 1e-6;
  Json backends_json = Json::object();
  for (const std::string& name : names) {
    backends_json[name] = {{"status", "ok"},         {"message", ""},
                           {"runtime_s", 0.0},       {"contacts", Json::array()},
                           {"pairs", Json::array()}, {"bodies", bodies_json(bodies)}};
  }
  for (size_t i = 0; i < bodies.size(); ++i) {
    for (size_t j = i + 1; j < bodies.size(); ++j) {
      const RigidBody &a = bodies[i], &b = bodies[j];
      if (a.is_static && b.is_static) continue;
      if (!bounding_check(a, b)) continue;
      // The oracle always runs, first: it is what the differences are measured against.
      std::vector<const Backend*> subjects = {find_backend("exact")};
      for (const std::string& name : names)
        if (name != "exact") subjects.push_back(find_backend(name));
      const PairRuns runs = contact_runs(subjects, a, b, ResultCache(), budget_s);
      ContactsPair p{a.name, b.name, runs.runs[0], {}};
      // The oracle's patch, which every backend's set of points is measured against.
      const SatResult sat = sat_query(*a.shape, a.pose(), *b.shape, b.pose());
      const ContactPoint* truth = deepest(p.truth_run.result);
      bool any = truth != nullptr;
      for (const ContactRun& r : runs.runs) any = any || !r.result.contacts.empty();
      if (!any) continue;
      for (size_t k = 0, other = 1; k < names.size(); ++k) {
        const ContactRun& run = names[k] == "exact" ? runs.runs[0] : runs.runs[other++];
        p.rows.push_back(
            compare_row(names[k], run, truth, sat, a, b, tol, backends_json[names[k]], c.marks));
      }
      c.pairs.push_back(std::move(p));
    }
  }
  c.json = contacts_json(scene, c, backends_json);
  return c;
}

}  // namespace rbx
