// `rbx contacts SCENE`: every backend's contact query at the t = 0 poses (or, with --at
// first-contact, at the first step where a pair touches), side by side, with the angle and depth
// differences against the `exact` oracle, marked as `compare` marks them.
#include <algorithm>
#include <iostream>

#include "comparisons/cli/commands.h"
#include "comparisons/eval/contact_eval.h"
#include "comparisons/eval/harness.h"
#include "comparisons/eval/json_io.h"
#include "comparisons/output/table.h"
#include "engine/bounding.h"
#include "engine/world.h"
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

// Where the bodies are at the first step whose start has a touching pair: the custom engine's
// motion (it is the only engine we can stop at a step), tested by the oracle before the engine
// resolves anything. Sets `step` (-1: no pair touches within the run) and the stop reason.
std::vector<RigidBody> first_contact_state(const Scene& scene, long& step, std::string& why) {
  World world(scene.sim, make_bodies(scene));
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

}  // namespace

int contacts_command(const SceneCommandOptions& opt) {
  const Scene scene = load_scene_for_command(opt.scenes.at(0), opt);
  const std::vector<std::string> names = select_backends(scene, opt.backends, Capability::Contact);
  std::ostream& out = opt.json == "-" ? std::cerr : std::cout;
  out << "scene: " << scene.name << " (" << scene.file << ")\n";
  long contact_step = 0;
  std::string stop_reason;
  const bool at_first = opt.at == "first-contact";
  const std::vector<RigidBody> bodies =
      at_first ? first_contact_state(scene, contact_step, stop_reason) : make_bodies(scene);
  if (at_first && contact_step >= 0)
    out << "first contact: step " << contact_step
        << ", t = " << fmt_num(contact_step * scene.sim.dt)
        << " s (the custom engine's motion up to there; the exact oracle's test)\n";
  const double tol = scene.expect ? scene.expect->tolerance : 1e-6;
  std::vector<std::string> marks;

  Json backends_json = Json::object();
  for (const std::string& name : names) {
    backends_json[name] = {{"status", "ok"},         {"message", ""},
                           {"runtime_s", 0.0},       {"contacts", Json::array()},
                           {"pairs", Json::array()}, {"bodies", bodies_json(bodies)}};
  }
  int pairs_shown = 0;
  for (size_t i = 0; i < bodies.size(); ++i) {
    for (size_t j = i + 1; j < bodies.size(); ++j) {
      const RigidBody &a = bodies[i], &b = bodies[j];
      if (a.is_static && b.is_static) continue;
      if (!bounding_check(a, b)) continue;
      // The oracle always runs: it is what the differences are measured against.
      const ContactRun truth = run_contact(*find_backend("exact"), a, b);
      const ContactPoint* t = deepest(truth.result);
      std::vector<std::pair<std::string, ContactRun>> runs;
      bool any = t != nullptr;
      for (const std::string& name : names) {
        runs.emplace_back(name, name == "exact" ? truth : run_contact(*find_backend(name), a, b));
        any = any || !runs.back().second.result.contacts.empty();
      }
      if (!any) continue;
      ++pairs_shown;
      out << "\npair " << a.name << "-" << b.name << " (normal from " << b.name << " toward "
          << a.name << "); exact: "
          << (t ? "depth " + fmt_num(t->depth) + ", normal " + fmt_vec(t->normal) : "no contact")
          << "\n";
      Table table({"backend", "status", "points", "normal", "depth", "point", "angle vs exact",
                   "depth - exact", "mark", "time (us)"});
      for (const auto& [name, run] : runs) {
        const ContactPoint* c = deepest(run.result);
        Json& bj = backends_json[name];
        if (run.result.status != Status::Ok) {
          bj["status"] = to_string(run.result.status);
          bj["message"] = run.result.message;
        } else if (!run.result.message.empty() && bj["message"] == "") {
          bj["message"] = run.result.message;  // e.g. a known-defect note
        }
        bj["runtime_s"] = bj["runtime_s"].get<double>() + run.runtime_s;
        for (const ContactPoint& p : run.result.contacts)
          bj["contacts"].push_back(contact_json(a.name, b.name, 0.0, p));
        Json pair = {{"bodies", {a.name, b.name}},
                     {"status", to_string(run.result.status)},
                     {"touching", c != nullptr}};
        std::string angle = "-", ddepth = "-", mark;
        if (c && t) {
          pair["normal_err_deg"] = angle_deg(c->normal, t->normal);
          pair["depth_err"] = c->depth - t->depth;
          angle = fmt_num(pair["normal_err_deg"].get<double>(), 3);
          ddepth = fmt_num(pair["depth_err"].get<double>(), 3);
          const double size = 2.0 * std::min(bounding_sphere(a).radius, bounding_sphere(b).radius);
          mark = mark_of(pair["normal_err_deg"].get<double>(), std::abs(c->depth - t->depth), size,
                         tol);
          if (!mark.empty())
            marks.push_back(mark + ": " + name + " on " + a.name + "-" + b.name +
                            ": normal off by " + angle + " deg, depth off by " +
                            fmt_num(std::abs(c->depth - t->depth), 3) + " m (against exact)");
        } else if (run.result.status == Status::Ok) {
          pair["touching_agrees"] = (c != nullptr) == (t != nullptr);
          if ((c != nullptr) != (t != nullptr)) {
            angle = c ? "false contact" : "missed";
            mark = "disagrees";
            marks.push_back("disagrees: " + name + " on " + a.name + "-" + b.name + ": " +
                            (c ? "reports a contact where there is none" : "misses a contact"));
          }
        }
        pair["mark"] = mark;
        bj["pairs"].push_back(pair);
        table.add({name, to_string(run.result.status), std::to_string(run.result.contacts.size()),
                   c ? fmt_vec(c->normal) : "-", c ? fmt_num(c->depth, 5) : "-",
                   c ? fmt_vec(c->point) : "-", angle, ddepth,
                   mark == "disagrees"  ? "✗"
                   : mark == "deviates" ? "~"
                                        : "",
                   fmt_num(run.runtime_s * 1e6, 3)});
      }
      table.print(out);
      for (const auto& [name, run] : runs)
        if (!run.result.message.empty()) out << "  " << name << ": " << run.result.message << "\n";
    }
  }
  for (const std::string& m : marks) out << "  " << m << "\n";
  if (pairs_shown == 0) {
    if (!at_first)
      out << "no pair of bodies touches at t = 0 (--at first-contact queries where one first "
             "does)\n";
    else
      out << "no pair of bodies touches within the run (" << scene.sim.steps()
          << " steps of the custom engine"
          << (stop_reason.empty() ? "" : "; it stopped: " + stop_reason) << ")\n";
  }
  Json result;
  result["scene"] = scene.name;
  result["file"] = scene.file;
  if (at_first) {
    result["at"] = {{"query", "first-contact"},
                    {"step", contact_step},
                    {"time", contact_step >= 0 ? contact_step * scene.sim.dt : -1.0},
                    {"message", stop_reason}};
  }
  result["disagreements"] = Json::array();
  result["deviations"] = Json::array();
  for (const std::string& m : marks)
    result[m.rfind("disagrees", 0) == 0 ? "disagreements" : "deviations"].push_back(
        m.substr(m.find(": ") + 2));
  result["backends"] = backends_json;
  if (!opt.json.empty()) write_json(opt.json, result);
  return 0;
}

}  // namespace rbx
