// `rbx contacts SCENE`: every backend's contact query at the t = 0 poses, side by side, with
// the angle and depth differences against the `exact` oracle.
#include <iostream>

#include "comparisons/cli/commands.h"
#include "comparisons/eval/contact_eval.h"
#include "comparisons/eval/json_io.h"
#include "comparisons/output/table.h"
#include "engine/bounding.h"

namespace rbx {

int contacts_command(const SceneCommandOptions& opt) {
  const Scene scene = load_scene_for_command(opt.scenes.at(0), opt);
  const std::vector<std::string> names = select_backends(scene, opt.backends, Capability::Contact);
  const std::vector<RigidBody> bodies = make_bodies(scene);
  std::ostream& out = opt.json == "-" ? std::cerr : std::cout;
  out << "scene: " << scene.name << " (" << scene.file << ")\n";

  Json backends_json = Json::object();
  for (const std::string& name : names) {
    backends_json[name] = {{"status", "ok"}, {"message", ""}, {"runtime_s", 0.0},
                           {"contacts", Json::array()}, {"pairs", Json::array()},
                           {"bodies", bodies_json(bodies)}};
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
                   "depth - exact", "time (us)"});
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
        std::string angle = "-", ddepth = "-";
        if (c && t) {
          pair["normal_err_deg"] = angle_deg(c->normal, t->normal);
          pair["depth_err"] = c->depth - t->depth;
          angle = fmt_num(pair["normal_err_deg"].get<double>(), 3);
          ddepth = fmt_num(pair["depth_err"].get<double>(), 3);
        } else if (run.result.status == Status::Ok) {
          pair["touching_agrees"] = (c != nullptr) == (t != nullptr);
          if ((c != nullptr) != (t != nullptr)) angle = c ? "false contact" : "missed";
        }
        bj["pairs"].push_back(pair);
        table.add({name, to_string(run.result.status), std::to_string(run.result.contacts.size()),
                   c ? fmt_vec(c->normal) : "-", c ? fmt_num(c->depth, 5) : "-",
                   c ? fmt_vec(c->point) : "-", angle, ddepth,
                   fmt_num(run.runtime_s * 1e6, 3)});
      }
      table.print(out);
      for (const auto& [name, run] : runs)
        if (!run.result.message.empty()) out << "  " << name << ": " << run.result.message << "\n";
    }
  }
  if (pairs_shown == 0) out << "no pair of bodies touches at t = 0\n";
  Json result;
  result["scene"] = scene.name;
  result["file"] = scene.file;
  result["backends"] = backends_json;
  if (!opt.json.empty()) write_json(opt.json, result);
  return 0;
}

}  // namespace rbx
