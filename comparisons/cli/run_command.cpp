// `rbx run SCENE`: the custom engine (plus any dynamics reference named by --backends).
#include <cstdio>
#include <iostream>

#include "comparisons/cli/commands.h"
#include "comparisons/eval/contact_eval.h"
#include "comparisons/eval/json_io.h"
#include "comparisons/output/table.h"

namespace rbx {

namespace {

// Prints one backend's events and final states as readable tables.
void print_dynamics(std::ostream& out, const std::string& name, const Scene& scene,
                    const DynamicsResult& r, double runtime_s) {
  out << name << ": " << to_string(r.status);
  if (!r.message.empty()) out << " (" << r.message << ")";
  out << ", " << r.events.size() << " collision events, " << fmt_num(runtime_s, 3) << " s\n";
  if (r.status == Status::Unsupported) return;
  if (!r.events.empty()) {
    Table t({"t (s)", "bodies", "feature", "point", "normal (B->A)", "depth", "impulse"});
    const size_t shown = std::min<size_t>(r.events.size(), 20);
    for (size_t i = 0; i < shown; ++i) {
      const CollisionEvent& e = r.events[i];
      t.add({fmt_num(e.time), e.body_a + "-" + e.body_b, e.contact.feature,
             fmt_vec(e.contact.point), fmt_vec(e.contact.normal), fmt_num(e.contact.depth),
             fmt_num(e.impulse)});
    }
    t.print(out);
    if (shown < r.events.size()) out << "  ... " << r.events.size() - shown << " more events\n";
  }
  Table f({"body", "position (COM)", "velocity", "angular velocity"});
  for (const BodyFinal& b : r.finals)
    f.add({b.name, fmt_vec(b.position), fmt_vec(b.velocity), fmt_vec(b.angular_velocity)});
  // A run that stopped early (its message says where) did not reach the scene's end.
  if (r.status == Status::Ok)
    out << "final state at t = " << fmt_num(scene.sim.steps() * scene.sim.dt) << " s:\n";
  else
    out << "state where the run stopped (before t = " << fmt_num(scene.sim.steps() * scene.sim.dt)
        << " s, the scene's end):\n";
  f.print(out);
}

}  // namespace

int run_command(const SceneCommandOptions& opt) {
  const Scene scene = load_scene_for_command(opt.scenes.at(0), opt);
  // `custom` always; further dynamics backends only when --backends names them.
  std::vector<std::string> names = {"custom"};
  if (!opt.backends.empty()) names = select_backends(scene, opt.backends, Capability::Dynamics);
  std::ostream& out = opt.json == "-" ? std::cerr : std::cout;
  out << "scene: " << scene.name << " (" << scene.file << ")\n";

  const std::vector<RigidBody> inputs = make_bodies(scene);
  Json result;
  result["scene"] = scene.name;
  result["file"] = scene.file;
  result["settings"] = settings_json(scene);
  Json backends_json = Json::object();
  int failed = 0;
  for (const std::string& name : names) {
    const Backend* b = find_backend(name);
    DynamicsResult r;
    double runtime = 0.0;
    if (!b->dynamics) {
      r.status = Status::Unsupported;
      r.message = name + " has no dynamics (contact queries only)";
    } else {
      TimedDynamics t = run_dynamics_isolated(*b, scene, DynamicsOptions{0.0, opt.sample_every});
      r = std::move(t.result);
      runtime = t.runtime_s;
    }
    if (r.status == Status::Error || r.status == Status::Timeout) ++failed;
    print_dynamics(out, name, scene, r, runtime);
    backends_json[name] = dynamics_result_json(inputs, r, runtime);
  }
  result["backends"] = backends_json;
  if (!opt.json.empty()) write_json(opt.json, result);
  return failed > 0 ? 1 : 0;
}

}  // namespace rbx
