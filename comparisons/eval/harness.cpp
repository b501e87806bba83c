#include "comparisons/eval/harness.h"

#include <limits>

#include "comparisons/eval/evaluator.h"

namespace rbx {

namespace eval_detail {

SceneEvaluation Evaluator::run() {
  Json& j = out_.json;
  j["scene"] = scene_.name;
  j["file"] = scene_.file;
  j["family"] = out_.family;
  j["description"] = scene_.description;
  if (!scene_.input_notes.empty()) j["input_notes"] = scene_.input_notes;
  j["checks"] = scene_.check_names();
  j["settings"] = settings_json(scene_);
  backends_json_ = Json::object();
  if (scene_.checks.empty()) out_.skipped.push_back("scene lists no checks: nothing to run");
  if (scene_.has_check(CheckKind::Contact)) contact_check();
  const bool dynamics = scene_.has_check(CheckKind::Impulse) ||
                        scene_.has_check(CheckKind::Trajectory) ||
                        scene_.has_check(CheckKind::Stability);
  if (dynamics) dynamics_checks();
  if (scene_.has_check(CheckKind::Mass)) mass_check();
  j["backends"] = backends_json_;
  Json metrics = Json::array();
  for (const Metric& m : out_.metrics)
    metrics.push_back({{"check", m.check},
                       {"backend", m.backend},
                       {"pair", m.pair},
                       {"name", m.name},
                       {"value", m.value},
                       {"against", m.against}});
  j["metrics"] = metrics;
  Json causes = Json::array();
  for (const Cause& c : out_.causes)
    causes.push_back(
        {{"backend", c.backend}, {"check", c.check}, {"kind", c.kind}, {"detail", c.detail}});
  j["causes"] = causes;
  Json points = Json::array();
  for (const ErrorRuntimePoint& s : out_.error_vs_runtime) {
    Json point = {{"backend", s.backend}, {"kind", s.kind}, {"dt", s.dt}, {"error", s.error}};
    point["against"] = s.against;
    put_timing(s.timing, point);
    if (s.kind == "budget") point["budget"] = s.budget;
    points.push_back(std::move(point));
  }
  j["error_vs_runtime"] = points;
  j["stability"] = stability_json_.is_null() ? Json::object() : stability_json_;
  if (!stability_dt_study_json_.is_null()) j["stability_dt_study"] = stability_dt_study_json_;
  j["skipped"] = out_.skipped;
  // A documented limitation excuses the engine it names only ("ENGINE: why"): any other
  // engine's or the oracle's failure (a wrong derivation) still fails the scene.
  const std::string known = scene_.expect ? scene_.expect->known_failure : "";
  const std::string subject = known.substr(0, known.find(':'));
  out_.expect_known =
      !known.empty() && !out_.expect_failures.empty() && binds(subject) &&
      std::all_of(out_.expect_failures.begin(), out_.expect_failures.end(),
                  [&](const std::string& f) { return f.rfind(subject + ":", 0) == 0; });
  expect_binding();
  j["expect"] = {{"checked", out_.expect_checked},
                 {"passed", out_.expect_checked && out_.expect_failures.empty()},
                 {"unchecked", out_.expect_unchecked},
                 {"failures", out_.expect_failures},
                 {"engines", scene_.expect ? scene_.expect->engines : std::vector<std::string>()},
                 {"known_failure", known},
                 {"excused", out_.expect_known}};
  j["disagreements"] = out_.disagreements;
  j["deviations"] = out_.deviations;
  read_runs(out_);
  return std::move(out_);
}

void Evaluator::expect_binding() {
  if (!scene_.expect) return;
  const Expect& e = *scene_.expect;
  if (e.contact && !expect_contact_bound_)
    out_.expect_unchecked.push_back("[expect.contact]: the scene runs no contact check");
  if (!e.bodies.empty() && !expect_bodies_bound_) {
    const bool dynamics = scene_.has_check(CheckKind::Impulse) ||
                          scene_.has_check(CheckKind::Trajectory) ||
                          scene_.has_check(CheckKind::Stability);
    out_.expect_unchecked.push_back(
        !dynamics ? "[expect.body]: the scene runs no dynamics check"
                  : "[expect.body]: binds " + Json(e.engines).dump() +
                        ", none of which ran (backends: " + join_names() + ")");
  }
  out_.expect_checked =
      (e.contact && expect_contact_bound_) || (!e.bodies.empty() && expect_bodies_bound_);
  if (!e.contact && e.bodies.empty())
    out_.expect_unchecked.push_back(
        e.distance || e.toi ? "[expect] states a distance or a time of impact only: rbx distance "
                              "and rbx toi check those"
                            : "[expect] gives nothing to check");
}

}  // namespace eval_detail

Json stability_json(const StabilityRow& r) {
  Json s;
  s["status"] = r.status;
  s["dt"] = r.dt;
  s["restitution"] = r.restitution;
  s["nonfinite"] = r.nonfinite;
  s["energy_growth_rel"] = r.energy_growth_rel;
  s["energy_drift_rel"] = r.energy_drift_rel;
  s["energy_change_rel"] = r.energy_change_rel;
  if (r.momentum_drift_rel) s["momentum_drift_rel"] = *r.momentum_drift_rel;
  if (r.angular_momentum_drift_rel) s["angular_momentum_drift_rel"] = *r.angular_momentum_drift_rel;
  s["max_penetration_rel"] = r.max_penetration_rel;
  s["rest_penetration_rel"] = r.rest_penetration_rel;
  s["tunnelled_pairs"] = r.tunnelled_pairs;
  if (r.jitter_rms_mps) s["jitter_rms_mps"] = *r.jitter_rms_mps;
  s["verdict"] = r.verdict;
  s["why"] = r.why;
  return s;
}

namespace {

// A number of a stability entry: a value that was not finite was written as null (JSON has no
// NaN or infinity) when the evaluation crossed processes; it reads back as NaN, never throws.
double number_at(const Json& s, const char* key) {
  const Json& v = s.at(key);
  return v.is_null() ? std::numeric_limits<double>::quiet_NaN() : v.get<double>();
}

StabilityRow stability_row(const std::string& backend, bool study_step, const Json& s) {
  StabilityRow r;
  r.backend = backend;
  r.study_step = study_step;
  r.status = s.at("status");
  r.dt = number_at(s, "dt");
  r.restitution = number_at(s, "restitution");
  r.nonfinite = s.at("nonfinite");
  r.energy_growth_rel = number_at(s, "energy_growth_rel");
  r.energy_drift_rel = number_at(s, "energy_drift_rel");
  r.energy_change_rel = number_at(s, "energy_change_rel");
  if (s.contains("momentum_drift_rel")) r.momentum_drift_rel = number_at(s, "momentum_drift_rel");
  if (s.contains("angular_momentum_drift_rel"))
    r.angular_momentum_drift_rel = number_at(s, "angular_momentum_drift_rel");
  r.max_penetration_rel = number_at(s, "max_penetration_rel");
  r.rest_penetration_rel = number_at(s, "rest_penetration_rel");
  r.tunnelled_pairs = s.at("tunnelled_pairs");
  if (s.contains("jitter_rms_mps")) r.jitter_rms_mps = number_at(s, "jitter_rms_mps");
  r.verdict = s.at("verdict");
  r.why = s.at("why").get<std::vector<std::string>>();
  return r;
}

}  // namespace

const BackendRun* SceneEvaluation::run_of(const std::string& backend) const {
  for (const BackendRun& r : runs)
    if (r.backend == backend) return &r;
  return nullptr;
}

void read_runs(SceneEvaluation& ev) {
  ev.runs.clear();
  ev.stability.clear();
  if (ev.json.contains("stability"))
    for (const auto& [name, s] : ev.json["stability"].items()) {
      ev.stability.push_back(stability_row(name, false, s));
      if (ev.json.contains("stability_dt_study") && ev.json["stability_dt_study"].contains(name))
        for (const Json& sw : ev.json["stability_dt_study"][name])
          ev.stability.push_back(stability_row(name, true, sw));
    }
  if (ev.json.contains("expect")) ev.known_failure = ev.json["expect"].value("known_failure", "");
  ev.has_geometry = ev.json.contains("geometry") && !ev.json["geometry"].empty();
  if (!ev.json.contains("backends")) return;
  const Json& stability = ev.json.value("stability", Json::object());
  for (const auto& [name, bj] : ev.json["backends"].items()) {
    BackendRun r;
    r.backend = name;
    const std::string s = bj.value("status", "ok");
    for (const Status c :
         {Status::Ok, Status::Error, Status::Unsupported, Status::Timeout, Status::Touching})
      if (s == to_string(c)) r.status = c;
    r.message = bj.value("message", "");
    if (bj.contains("runtime_s")) r.runtime_s = bj["runtime_s"].get<double>();
    if (stability.contains(name)) r.stability = stability[name].value("verdict", "");
    if (bj.contains("contact_phase")) {
      const Json& p = bj["contact_phase"];
      auto cell = [&](const char* k) {
        ContactPhaseCell c;
        if (p.contains(k) && p[k].is_number()) c.error = p[k].get<double>();
        if (p.contains(k) && p[k].is_string()) c.failure = p[k].get<std::string>();
        return c;
      };
      r.contact_phase = ContactPhaseRow{cell("written"), cell("1_3"), cell("2_3"), cell("worst")};
    }
    ev.runs.push_back(std::move(r));
  }
}

SceneEvaluation evaluate_scene(const Scene& scene, const HarnessOptions& opt) {
  if (!scene.expect || scene.expect_set_aside_by.empty())
    return eval_detail::Evaluator(scene, opt).run();
  // An override changed the physics [expect] was written for: run without it, and say so.
  Scene changed = scene;
  changed.expect.reset();
  SceneEvaluation ev = eval_detail::Evaluator(changed, opt).run();
  std::string keys;
  for (const std::string& k : scene.expect_set_aside_by) keys += (keys.empty() ? "" : ", ") + k;
  ev.expect_checked = false;
  ev.expect_unchecked.push_back("[expect]: written for the scene as its file gives it; " + keys +
                                " changed that");
  ev.json["expect"]["checked"] = false;
  ev.json["expect"]["passed"] = false;
  ev.json["expect"]["unchecked"] = ev.expect_unchecked;
  ev.json["expect"]["known_failure"] = scene.expect->known_failure;
  read_runs(ev);
  return ev;
}

}  // namespace rbx
