#include "comparisons/eval/harness.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <thread>

#include "comparisons/eval/budgets.h"
#include "comparisons/eval/contact_cause.h"
#include "comparisons/eval/contact_eval.h"
#include "comparisons/eval/impact_cause.h"
#include "comparisons/eval/measures.h"
#include "comparisons/eval/metrics.h"
#include "comparisons/eval/result_cache.h"
#include "comparisons/eval/select_backends.h"
#include "comparisons/eval/trajectory.h"
#include "comparisons/scene/scene_collection.h"
#include "engine/bounding.h"
#include "engine/detect.h"
#include "engine/format.h"
#include "reference/exact.h"

namespace rbx {

namespace {

/// True when two answers to one query are the same contact (bit for bit: a prebuilt shape is
/// the same shape).
bool same_answer(const ContactPoint& x, const ContactPoint& y) {
  return x.normal == y.normal && x.point == y.point && x.depth == y.depth;
}

// ---------------------------------------------------------------------------------------------
// Small helpers

std::string pair_name(const RigidBody& a, const RigidBody& b) { return a.name + "-" + b.name; }

// ---------------------------------------------------------------------------------------------
// The checks

class Evaluator {
 public:
  Evaluator(const Scene& scene, const HarnessOptions& opt)
      : scene_(scene),
        opt_(opt),
        table_(opt.registry ? *opt.registry : backends()),
        inputs_(make_bodies(scene)),
        cache_(opt.cache_dir, ResultCache::code_fingerprint(), opt.cache_reads) {
    out_.family = scene_family(scene.file);
  }

  SceneEvaluation run() {
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
    Json sweep = Json::array();
    for (const SweepPoint& s : out_.sweep) {
      Json point = {{"backend", s.backend}, {"kind", s.kind}, {"dt", s.dt}, {"error", s.error}};
      point["against"] = s.against;
      put_timing(s.timing, point);
      if (s.kind == "budget") point["budget"] = s.budget;
      sweep.push_back(std::move(point));
    }
    j["sweep"] = sweep;
    j["stability"] = stability_json_.is_null() ? Json::object() : stability_json_;
    if (!stability_sweep_json_.is_null()) j["stability_sweep"] = stability_sweep_json_;
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
    return std::move(out_);
  }

 private:
  // Which parts of [expect] were bound: [expect.contact] by the oracle's query of the first pair
  // (whenever the contact check runs), [expect.body] by a bound engine's completed run (binds).
  // A reference outside the closed form is marked (disagrees), it does not bind it.
  void expect_binding() {
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
      out_.expect_unchecked.push_back("[expect] gives nothing to check");
  }

  bool binds(const std::string& name) const {  // an engine under test [expect] binds
    const std::vector<std::string>* e = scene_.expect ? &scene_.expect->engines : nullptr;
    return e && std::find(e->begin(), e->end(), name) != e->end();
  }

  std::string join_names() const {
    std::string s;
    for (const auto& [name, bj] : backends_json_.items()) s += (s.empty() ? "" : ", ") + name;
    return s.empty() ? "none" : s;
  }

  void metric(const std::string& check, const std::string& backend, const std::string& pair,
              const std::string& name, double value, const std::string& against) {
    out_.metrics.push_back({check, backend, pair, name, value, against});
  }

  // The backend called `name` in the table (select_backends only returns names from it).
  const Backend& backend(const std::string& name) const {
    return *std::find_if(table_.begin(), table_.end(),
                         [&](const Backend& b) { return b.name == name; });
  }

  Json& backend_json(const std::string& name) {
    if (!backends_json_.contains(name))
      backends_json_[name] = {{"status", "ok"},
                              {"message", ""},
                              {"runtime_s", 0.0},
                              {"contacts", Json::array()},
                              {"bodies", bodies_json(inputs_)}};
    return backends_json_[name];
  }

  void set_status(const std::string& name, Status s, const std::string& message) {
    Json& bj = backend_json(name);
    if (s != Status::Ok && bj["status"] == "ok") {
      bj["status"] = to_string(s);
      bj["message"] = message;
    } else if (s == Status::Ok && !message.empty() && bj["message"] == "") {
      bj["message"] = message;
    }
  }

  // A call that failed or ran out of time gave no answer to agree with: it disagrees, saying so
  // (a backend that cannot take the scene, Unsupported, does not).
  void failed_call(const std::string& who, Status s, const std::string& message) {
    if (s == Status::Error || s == Status::Timeout)
      out_.disagreements.push_back(who + ": " + to_string(s) + ": " + message);
  }

  // -- contact ---------------------------------------------------------------------------------
  void contact_check() {
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

  void contact_pair(const RigidBody& a, const RigidBody& b, bool first_pair,
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
    // [expect.contact] binds the oracle, whatever backends run: if the exact answer (computed
    // here anyway) disagrees with the closed form, the derivation or the oracle is wrong.
    if (ex)
      expect_contact_failures("exact", *ex, sat.touching, sat.normal, std::max(sat.depth, 0.0), tol,
                              out_.expect_failures);
    if (ex) expect_contact_bound_ = true;
    // A stated point is one model's representative point of the contact (on A, on B or between
    // them): it is right when it lies in the true contact region, where every backend's point is
    // scored too (point_err_rel): inside both bodies, or on the oracle's manifold.
    if (ex && ex->point && sat.touching) {
      const double off = contact_point_error(*ex->point, a, b, sat.manifold);
      if (off > tol)
        out_.expect_failures.push_back("exact: [expect.contact] point " + fmt_vec(*ex->point, 8) +
                                       " lies " + fmt_num(off, 3) +
                                       " m from the true contact region");
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
        out_.sweep.push_back(
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
      if (sat.touching && !sat.manifold.empty())
        metric("contact", name, pair, "point_err_rel",
               contact_point_error(c->point, a, b, sat.manifold) / size, "exact");
      out_.sweep.push_back({name, "contact", 0.0, run.timing, angle, normal_src});
      // The same query with the library's shapes built once (its "prebuilt" variant): the
      // figures time both, so that the cost of building a shape shows apart from the query.
      if (const std::optional<ContactRun>& pr = runs.prebuilt[i]) {
        const ContactPoint* pc = deepest(pr->result);
        if (pr->result.status != Status::Ok || !pc || !same_answer(*c, *pc))
          out_.disagreements.push_back(name + " on " + pair +
                                       ": the prebuilt variant answers differently");
        else
          out_.sweep.push_back({name, "contact-prebuilt", 0.0, pr->timing, angle, normal_src});
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
      if (binds(name) && ex)
        expect_contact_failures(name, *ex, touch, c->normal, c->depth, tol, out_.expect_failures);
    }
  }

  // A touching answer with no normal: a library's convention at zero depth, right when the pair
  // touches there; a false contact when it does not; a miss when the pair penetrates beyond
  // `depth_tol` (its depth, zero, is scored as such; there is no normal to score).
  void touching_answer(const std::string& name, const std::string& pair, const ContactResult& r,
                       const ContactTruth& t, double depth_tol, const std::string& touch_src,
                       const std::string& depth_src) {
    metric("contact", name, pair, "touching_err", t.touching ? 0.0 : 1.0, touch_src);
    if (!t.touching)
      out_.disagreements.push_back(name + " on " + pair +
                                   ": reports a contact where there is none");
    if (t.touching) metric("contact", name, pair, "depth_err", t.depth, depth_src);
    if (t.touching && t.depth > depth_tol)
      (t.depth > kMarkDepthRel * t.size ? out_.disagreements : out_.deviations)
          .push_back(name + " on " + pair + ": reports touching with no normal on a pair " +
                     fmt_num(t.depth, 3) + " m deep (a miss)");
    if (auto c = contact_cause(name, scene_.name, r, t, 0.0)) out_.causes.push_back(*c);
  }

  // -- impulse, trajectory, stability ----------------------------------------------------------

  // What every backend's dynamics is measured against, from the scene alone (and, for
  // `angular`, every backend's main run).
  struct DynamicsFrame {
    double e0_kin = 0.0, e0 = 0.0;  // initial kinetic and total energy
    Vec3 p0 = Vec3::Zero(), h0 = Vec3::Zero();
    bool closed = false;   // momentum is an invariant: no static body, no gravity
    bool angular = false;  // angular metrics only where something rotates
    double p_scale = 0.0, h_scale = 0.0;
    std::vector<std::optional<RefState>> expected;  // [expect] final velocities
    bool have_expect = false;
    bool phases = false;  // the contact-phase runs apply
    long sample_every = 1;
    bool wants_sweep = false;
    std::vector<double> dts;  // the sweep's steps, finest last
    double finest = 0.0;
  };

  // The swept runs of one backend; `fine` is the finest step's when it ran.
  struct SweepRuns {
    std::optional<DynRun> fine;
    std::vector<DynRun> runs;
    bool wants_velocity = false;   // the impulse or trajectory check asks for velocity errors
    bool stability_sweep = false;  // a stability verdict at every step of the scene's own sweep
  };

  void dynamics_checks() {
    const std::vector<std::string> names =
        select_backends(scene_, opt_.backends, Capability::Dynamics, table_);
    DynamicsFrame fr = dynamics_frame();
    // Every backend's main run first: whether the angular metrics apply is decided from the
    // scene and from all results before any metric is emitted, so that every backend gets the
    // same metric set whatever the order of the backends.
    std::vector<std::pair<std::string, DynRun>> mains;
    for (const std::string& name : names) {
      const Backend& be = backend(name);
      if (!be.dynamics) {
        set_status(name, Status::Unsupported, name + " has no dynamics (contact queries only)");
        continue;
      }
      mains.emplace_back(name,
                         run_dynamics(be, scene_, scene_.sim.dt, fr.sample_every, cache_, inputs_));
    }
    for (const auto& [name, run] : mains)
      if (run.result.status == Status::Ok)
        for (const BodyFinal& f : run.result.finals)
          fr.angular = fr.angular || f.angular_velocity.norm() > 1e-12;
    for (const auto& [name, main] : mains) backend_dynamics(name, main, fr);
    if (!fr.angular) out_.skipped.push_back("angular metrics: nothing rotates in this scene");
  }

  DynamicsFrame dynamics_frame() {
    DynamicsFrame fr;
    fr.e0_kin = initial_kinetic_energy(inputs_);
    const std::vector<BodyFinal> s0 = initial_states(inputs_);
    fr.e0 = total_energy(inputs_, s0, scene_.sim.gravity);
    fr.p0 = linear_momentum(inputs_, s0);
    fr.h0 = angular_momentum(inputs_, s0);
    bool any_static = false;
    double mass_total = 0.0, size_max = 0.0;
    for (const RigidBody& b : inputs_) {
      any_static = any_static || b.is_static;
      if (!b.is_static) mass_total += b.mass;
      size_max = std::max(size_max, body_size(b));
    }
    fr.closed = !any_static && scene_.sim.gravity.norm() == 0.0;
    if (!fr.closed)
      out_.skipped.push_back("momentum drift: not an invariant here (static bodies or gravity)");
    for (const RigidBody& b : inputs_) fr.angular = fr.angular || b.angular_velocity.norm() > 0;
    // Momentum scale: the largest momentum any body has or could get from the energy.
    fr.p_scale = std::max(fr.p0.norm(), std::sqrt(2.0 * mass_total * fr.e0_kin));
    fr.h_scale = std::max(fr.h0.norm(), fr.p_scale * size_max);

    // Reference for final velocities: the [expect] block, if it gives any.
    fr.expected.resize(inputs_.size());
    if (scene_.expect)
      for (const ExpectBody& eb : scene_.expect->bodies)
        for (size_t i = 0; i < inputs_.size(); ++i)
          if (inputs_[i].name == eb.name && (eb.velocity || eb.angular_velocity)) {
            fr.expected[i] = RefState{eb.velocity, eb.angular_velocity};
            fr.have_expect = true;
          }
    for (const auto& r : fr.expected)
      fr.angular = fr.angular || (r && r->angular_velocity && r->angular_velocity->norm() > 0);

    // Contact phases apply where the closed form does not depend on when in a step contact
    // begins: an impulse scene with [expect] velocities, no gravity, nothing spinning (moving a
    // spinning body back would also need its rotation undone).
    fr.phases = opt_.phases && fr.have_expect && scene_.has_check(CheckKind::Impulse) &&
                scene_.sim.gravity.norm() == 0.0;
    for (const RigidBody& b : inputs_)
      fr.phases = fr.phases && (b.is_static || b.angular_velocity.norm() == 0.0);
    if (fr.have_expect && scene_.has_check(CheckKind::Impulse) && !fr.phases && opt_.phases)
      out_.skipped.push_back(
          "contact phases: gravity or a spinning body (the closed form depends on the phase)");

    fr.sample_every = std::max<long>(1, scene_.sim.steps() / 400);
    fr.wants_sweep = opt_.sweep && (scene_.has_check(CheckKind::Impulse) ||
                                    scene_.has_check(CheckKind::Trajectory));
    fr.dts = sweep_steps(scene_);
    fr.finest = fr.dts.back();
    return fr;
  }

  // Every metric of one backend's dynamics, in a fixed order: velocity against the closed form
  // or its finest step, the contact phases, the sweep, trajectory divergence, contact time,
  // conservation, [expect], stability.
  void backend_dynamics(const std::string& name, const DynRun& main, const DynamicsFrame& fr) {
    Json& bj = backend_json(name);
    bj = dynamics_result_json(inputs_, main.result, main.runtime_s);
    if (main.cached) bj["cached"] = true;
    // The sampled trajectory, for results.json and the 3-D replay (rbx view).
    const size_t moving = static_cast<size_t>(std::count_if(
        inputs_.begin(), inputs_.end(), [](const RigidBody& b) { return !b.is_static; }));
    bj["trajectory"] = trajectory_json(main.result.samples, inputs_, frame_budget(moving));
    if (main.result.status != Status::Ok) {
      failed_call(name, main.result.status, main.result.message);
      stopped_run(name, main, fr);
      return;
    }
    const SweepRuns sw = sweep_runs(backend(name), main, fr);
    std::string against;
    const std::vector<std::optional<RefState>> ref =
        velocity_reference(name, main, sw, fr, against);
    contact_phases(name, main, fr, bj);
    if (fr.wants_sweep && !against.empty()) {
      const auto error_of = [&](const std::vector<BodyFinal>& finals) {
        return ke_norm_error(inputs_, finals, ref, fr.e0_kin);
      };
      for (const DynRun& r : sw.runs) {
        if (r.result.status != Status::Ok) continue;
        if (!fr.have_expect && &r == &sw.runs.back()) continue;  // zero by construction
        out_.sweep.push_back({name, "dynamics", r.dt, Timing::once(r.runtime_s),
                              error_of(r.result.finals), against});
      }
      const std::vector<SweepPoint> budgets = budget_points(
          backend(name), scene_, main, cache_, inputs_, error_of, against, &out_.skipped);
      out_.sweep.insert(out_.sweep.end(), budgets.begin(), budgets.end());
    }
    trajectory_divergence(name, main, sw, fr);
    // Contact time: first event against the finest-step run of the same backend.
    if (sw.fine && !main.result.events.empty() && !sw.fine->result.events.empty() &&
        std::abs(fr.finest - scene_.sim.dt) > 1e-15)
      metric(primary_check(), name, "", "contact_time_err",
             std::abs(main.result.events.front().time - sw.fine->result.events.front().time),
             fmt_dt(fr.finest));
    conservation(name, main.result.finals, fr);
    // [expect.body] binds the engines the scene names (the custom engine by default); every
    // backend, those included, is marked by the same rule where it misses the closed form.
    if (binds(name)) {
      check_expect_bodies(name, main.result.finals);
      expect_bodies_bound_ = true;
    }
    if (scene_.expect)
      mark_expect_disagreement(
          name, main.result.finals,
          fr.have_expect ? ke_norm_error(inputs_, main.result.finals, fr.expected, fr.e0_kin)
                         : 0.0);
    if (scene_.has_check(CheckKind::Stability)) stability(name, main, fr);
    // The verdict at every other swept step (report rows; not metrics of the check).
    if (sw.stability_sweep)
      for (const DynRun& r : sw.runs)
        if (std::abs(r.dt - scene_.sim.dt) > 1e-15 * r.dt) stability(name, r, fr, /*swept=*/true);
  }

  // A run that stopped early: its stability verdict, and a failed [expect.body] for the engine
  // under test (no final state to compare is not a pass).
  void stopped_run(const std::string& name, const DynRun& main, const DynamicsFrame& fr) {
    if (scene_.has_check(CheckKind::Stability)) stability(name, main, fr);
    if (binds(name) && !scene_.expect->bodies.empty()) {
      out_.expect_failures.push_back(
          name + ": the run stopped before t = duration: " + main.result.message);
      expect_bodies_bound_ = true;
    }
  }

  // The backend at every step of the sweep (or only the finest, the self-consistency
  // reference, when no sweep is asked for).
  SweepRuns sweep_runs(const Backend& be, const DynRun& main, const DynamicsFrame& fr) {
    SweepRuns sw;
    // Velocity errors belong to the impulse and trajectory checks: a stability-only scene
    // does not pay for the self-consistency run.
    sw.wants_velocity =
        scene_.has_check(CheckKind::Impulse) || scene_.has_check(CheckKind::Trajectory);
    sw.stability_sweep =
        scene_.has_check(CheckKind::Stability) && !scene_.sim.sweep_dt.empty() && fr.wants_sweep;
    if (!fr.wants_sweep && (fr.have_expect || !sw.wants_velocity) &&
        !scene_.has_check(CheckKind::Trajectory))
      return sw;
    const std::vector<double> to_run = fr.wants_sweep ? fr.dts : std::vector<double>{fr.finest};
    for (double dt : to_run) {
      if (std::abs(dt - scene_.sim.dt) <= 1e-15 * dt) {
        sw.runs.push_back(main);
        continue;
      }
      // The finest run of a trajectory check is sampled at the same times as the main run; so
      // is every swept run of a stability scene that names its own sweep (its verdict is given
      // at each step: the thin wall must not tunnel at any).
      const bool sample =
          (scene_.has_check(CheckKind::Trajectory) && dt == fr.finest) || sw.stability_sweep;
      const long every =
          sample ? std::max<long>(1, std::lround(fr.sample_every * scene_.sim.dt / dt)) : 0;
      sw.runs.push_back(run_dynamics(be, scene_, dt, every, cache_, inputs_));
    }
    if (sw.runs.back().result.status == Status::Ok) sw.fine = sw.runs.back();
    return sw;
  }

  // The final velocities the main run is measured against ([expect], else the finest step's
  // run; `against` names it, "" : none) and the velocity error metric against them.
  std::vector<std::optional<RefState>> velocity_reference(const std::string& name,
                                                          const DynRun& main, const SweepRuns& sw,
                                                          const DynamicsFrame& fr,
                                                          std::string& against) {
    std::vector<std::optional<RefState>> ref;
    if (fr.have_expect) {
      against = scene_.expect->truth;
      ref = fr.expected;
    } else if (sw.fine) {
      against = fmt_dt(fr.finest);
      ref.resize(inputs_.size());
      for (size_t i = 0; i < inputs_.size(); ++i)
        ref[i] =
            RefState{sw.fine->result.finals[i].velocity,
                     fr.angular ? std::optional<Vec3>(sw.fine->result.finals[i].angular_velocity)
                                : std::nullopt};
    }
    if (!against.empty() &&
        !(sw.fine && !fr.have_expect && std::abs(fr.finest - scene_.sim.dt) < 1e-15)) {
      metric(primary_check(), name, "", "velocity_err_ke",
             ke_norm_error(inputs_, main.result.finals, ref, fr.e0_kin), against);
    } else if (against.empty() && sw.wants_velocity) {
      out_.skipped.push_back(name + ": no reference for the velocity error");
    }
    return ref;
  }

  // The same impact with first contact 1/3 and 2/3 of a step later (the headline stays the
  // scene as written), and the cause of a miss.
  void contact_phases(const std::string& name, const DynRun& main, const DynamicsFrame& fr,
                      Json& bj) {
    double worst = 0.0, written = 0.0;
    std::string worst_phase = "written";
    if (fr.have_expect)
      written = worst = ke_norm_error(inputs_, main.result.finals, fr.expected, fr.e0_kin);
    FirstImpulse worst_fi = main.result.first_impulse;
    std::vector<RigidBody> worst_start = inputs_;  // the bodies at t = 0 of the worst run
    if (fr.phases) {
      Json pj = {{"written", written}};
      for (const ContactPhase& ph : kContactPhases) {
        const Scene shifted = shifted_scene(scene_, ph.fraction * scene_.sim.dt);
        const DynRun r =
            run_dynamics(backend(name), shifted, scene_.sim.dt, 0, cache_, make_bodies(shifted));
        if (r.result.status != Status::Ok) {
          pj[ph.label] = "error: " + r.result.message;
          continue;
        }
        const double err = ke_norm_error(inputs_, r.result.finals, fr.expected, fr.e0_kin);
        pj[ph.label] = err;
        metric(primary_check(), name, "", std::string("velocity_err_ke_phase_") + ph.label, err,
               "analytic");
        if (err > worst) {
          worst = err;
          worst_phase = ph.label;
          worst_fi = r.result.first_impulse;
          worst_start = make_bodies(shifted);
        }
      }
      pj["worst"] = worst;
      pj["worst_phase"] = worst_phase;
      bj["contact_phase"] = pj;
      if (written <= kMarkVelocityErr && worst > kMarkVelocityErr)
        out_.disagreements.push_back(name + ": velocity error " + fmt_num(worst, 3) +
                                     " with first contact " + phase_text(worst_phase) +
                                     " (as written: " + fmt_num(written, 3) + ")");
    }
    if (fr.have_expect && scene_.has_check(CheckKind::Impulse) &&
        std::max(written, worst) > kMarkVelocityErr) {
      // The scene as written explains itself when it misses; else the worst phase does.
      const bool as_written = written > kMarkVelocityErr;
      out_.causes.push_back(impact_cause(
          scene_, inputs_, name, as_written ? main.result.first_impulse : worst_fi,
          as_written ? inputs_ : worst_start, written, worst, worst_phase, fr.expected));
    }
  }

  // State divergence over time: how far any point of a body is from where the finest-step run
  // puts it at the same sample time, |dx| + (size / 2) * rotation angle (an upper bound),
  // relative to the body's size.
  void trajectory_divergence(const std::string& name, const DynRun& main, const SweepRuns& sw,
                             const DynamicsFrame& fr) {
    if (!scene_.has_check(CheckKind::Trajectory) || !sw.fine || sw.fine->result.samples.empty() ||
        std::abs(fr.finest - scene_.sim.dt) <= 1e-15)
      return;
    const std::vector<StateSample>& fine = sw.fine->result.samples;
    double worst = 0.0;
    size_t k = 0;
    for (const StateSample& smp : main.result.samples) {
      while (k + 1 < fine.size() &&
             std::abs(fine[k + 1].time - smp.time) <= std::abs(fine[k].time - smp.time))
        ++k;
      const StateSample& ref = fine[k];
      if (std::abs(ref.time - smp.time) > 0.5 * scene_.sim.dt) continue;  // no partner
      for (size_t i = 0; i < inputs_.size() && i < ref.bodies.size(); ++i)
        if (!inputs_[i].is_static)
          worst = std::max(
              worst,
              (smp.bodies[i].position - ref.bodies[i].position).norm() / body_size(inputs_[i]) +
                  0.5 * smp.bodies[i].orientation.angularDistance(ref.bodies[i].orientation));
    }
    metric("trajectory", name, "", "state_divergence_err", worst, fmt_dt(fr.finest));
  }

  // Conservation: momentum (where it is an invariant), energy against what e allows.
  void conservation(const std::string& name, const std::vector<BodyFinal>& f,
                    const DynamicsFrame& fr) {
    if (fr.closed) {
      const auto [p_scale, h_scale] = drift_scales(inputs_, f, fr.p_scale, fr.h_scale);
      metric(primary_check(), name, "", "momentum_drift_err",
             (linear_momentum(inputs_, f) - fr.p0).norm() / p_scale, "invariant");
      if (fr.angular)
        metric(primary_check(), name, "", "angular_momentum_drift_err",
               (angular_momentum(inputs_, f) - fr.h0).norm() / h_scale, "invariant");
    }
    const double e1 = total_energy(inputs_, f, scene_.sim.gravity);
    const double e_scale = std::max(std::abs(fr.e0), fr.e0_kin);
    if (e_scale <= 0) return;
    metric(primary_check(), name, "", "energy_change_rel", (e1 - fr.e0) / e_scale, "initial");
    // Against the closed form's final kinetic energy where [expect] gives every moving body's
    // velocities, else the invariant rule of the restitution.
    const EnergyError err = energy_error(fr.e0, e1, kinetic_energy(inputs_, f),
                                         expected_kinetic_energy(inputs_, f, fr.expected),
                                         scene_.sim.restitution, e_scale);
    metric(primary_check(), name, "", "energy_err", err.value, err.against);
  }

  std::string primary_check() const {
    if (scene_.has_check(CheckKind::Impulse)) return "impulse";
    if (scene_.has_check(CheckKind::Trajectory)) return "trajectory";
    return "stability";
  }

  void check_expect_bodies(const std::string& name, const std::vector<BodyFinal>& finals) {
    for (std::string& s : expect_violations(name, *scene_.expect, finals))
      out_.expect_failures.push_back(s);
  }

  // A reference outside the [expect] tolerance: a disagreement when its velocity error is above
  // kMarkVelocityErr (or only positions are expected), else a deviation.
  void mark_expect_disagreement(const std::string& name, const std::vector<BodyFinal>& finals,
                                double velocity_err) {
    const auto v = expect_violations(name, *scene_.expect, finals);
    if (v.empty()) return;
    const std::string text = v.front() + (v.size() > 1 ? " (and more)" : "");
    const bool velocities = velocity_err > 0.0;
    (velocities && velocity_err <= kMarkVelocityErr ? out_.deviations : out_.disagreements)
        .push_back(text + (velocities ? "; velocity error " + fmt_num(velocity_err, 3) : ""));
  }

  // Stability on stiff and extreme scenes: non-finite states, energy drift, momentum drift,
  // maximum penetration (whole run and at rest), tunnelling, jitter at rest, and a verdict.
  // `swept`: a run at another step of the scene's sweep: its verdict goes to the JSON's
  // `stability_sweep` (and the report's table), not to the metrics.
  void stability(const std::string& name, const DynRun& run, const DynamicsFrame& fr,
                 bool swept = false) {
    const StabilityGeometry geo = stability_geometry(inputs_);
    StabilityInvariants inv{fr.e0, fr.p0, fr.h0, fr.closed, fr.p_scale, fr.h_scale};
    const StabilityTrace tr = trace_stability(inputs_, run.result, sample_overlaps(run, geo), geo,
                                              inv, scene_.sim.gravity);
    const double jitter = rest_jitter(inputs_, run.result.samples, scene_.sim.gravity);
    Json s;
    s["status"] = to_string(run.result.status);
    s["dt"] = run.dt;
    s["restitution"] = scene_.sim.restitution;
    s["nonfinite"] = tr.nonfinite;
    s["energy_growth_rel"] = tr.growth;
    s["energy_drift_rel"] = tr.drift_e;
    s["energy_change_rel"] = tr.e_change;
    if (fr.closed) {
      s["momentum_drift_rel"] = tr.drift;
      s["angular_momentum_drift_rel"] = tr.hdrift;
    }
    s["max_penetration_rel"] = tr.pen_max;
    s["rest_penetration_rel"] = tr.pen_rest;
    s["tunnelled_pairs"] = tr.tunnelled;
    if (scene_.sim.gravity.norm() > 0) s["jitter_rms_mps"] = jitter;
    // Verdict: the rules of stability_verdict (metrics.h).
    StabilityFacts facts;
    facts.nonfinite = tr.nonfinite;
    facts.stopped = run.result.status == Status::Error;
    facts.stop_message = run.result.message;
    facts.energy_growth = tr.growth;
    facts.energy_made_j = tr.made_j;
    facts.closed = fr.closed;
    facts.momentum_drift = tr.drift;
    facts.max_penetration = tr.pen_max;
    facts.rest_penetration = tr.pen_rest;
    facts.energy_final = tr.e_change;
    facts.restitution = scene_.sim.restitution;
    facts.friction = scene_.sim.friction;
    facts.tunnelled_pairs = tr.tunnelled;
    const StabilityVerdict verdict = stability_verdict(facts);
    s["verdict"] = verdict.verdict;
    s["why"] = verdict.why;
    if (swept) {
      stability_sweep_json_[name].push_back(s);
      return;
    }
    stability_json_[name] = s;
    metric("stability", name, "", "energy_growth_err", std::max(tr.growth, 0.0), "invariant");
    metric("stability", name, "", "max_penetration_rel_err", tr.pen_max, "exact");
    metric("stability", name, "", "tunnelled_pairs_err", tr.tunnelled, "invariant");
    if (scene_.sim.gravity.norm() > 0)
      metric("stability", name, "", "jitter_rms_mps_err", jitter, "invariant");
  }

  // The deepest exact overlap of every finite sample; a cached reference run's overlaps are
  // cached with it (they cost more than the run).
  std::vector<double> sample_overlaps(const DynRun& run, const StabilityGeometry& geo) {
    const auto& samples = run.result.samples;
    const size_t finite_samples = finite_prefix(samples);
    std::optional<std::vector<double>> stored;
    if (!run.cache_key.empty()) stored = cache_.load_derived(run.cache_key, "stability overlaps");
    if (stored && stored->size() == finite_samples) return *stored;
    const std::vector<double> overlaps = parallel_map(
        finite_samples, [&](size_t t) { return deepest_overlap(geo, inputs_, samples[t]); });
    if (!run.cache_key.empty()) cache_.store_derived(run.cache_key, "stability overlaps", overlaps);
    return overlaps;
  }

  // -- mass ------------------------------------------------------------------------------------
  // What each library computes by itself from the same hull (Bullet's bounding-box inertia,
  // MuJoCo's mesh inertia, FCL's Convex integrals) and the seed's vertex model, against the
  // exact uniform-density values. Every backend still runs with the exact values.
  void mass_check() {
    std::vector<const Backend*> libs;
    const std::vector<std::string> wanted =
        select_backends(scene_, opt_.backends, Capability::Contact, table_);
    for (const Backend& b : table_)
      if (b.mass && (opt_.backends.empty() ||
                     std::find(wanted.begin(), wanted.end(), b.name) != wanted.end()))
        libs.push_back(&b);
    for (size_t i = 0; i < inputs_.size(); ++i) {
      const RigidBody& body = inputs_[i];
      const MassProperties exact = solid_mass_properties(*body.shape, body.mass);
      const double volume = body.shape->volume();
      const double size = body_size(body);
      auto record = [&](const std::string& name, const MassResult& r) {
        set_status(name, r.status, r.message);
        if (r.status != Status::Ok) return;
        metric("mass", name, body.name, "mass_err_rel", std::abs(r.mass - exact.mass) / exact.mass,
               "exact solid");
        metric("mass", name, body.name, "com_err_rel",
               (r.center_of_mass - exact.center_of_mass).norm() / size, "exact solid");
        metric("mass", name, body.name, "inertia_err_rel",
               (r.inertia - exact.inertia).norm() / exact.inertia.norm(), "exact solid");
        if (r.volume >= 0)
          metric("mass", name, body.name, "volume_err_rel", std::abs(r.volume - volume) / volume,
                 "exact solid");
        // Marks: above 1 % a different model or a defect (✗); above 1e-6, more than the
        // round-off of a library storing vertices in float (MuJoCo), a deviation (~).
        const double worst = std::max({std::abs(r.mass - exact.mass) / exact.mass,
                                       (r.center_of_mass - exact.center_of_mass).norm() / size,
                                       (r.inertia - exact.inertia).norm() / exact.inertia.norm()});
        const std::string what =
            name + " on " + body.name + ": mass properties off by " + fmt_num(worst, 3) +
            " (relative, worst of mass, centre of mass and inertia) against the exact solid" +
            (name == "custom-seed" ? " (the seed's point masses at the vertices)" : "");
        if (worst > 1e-2)
          out_.disagreements.push_back(what);
        else if (worst > 1e-6)
          out_.deviations.push_back(what);
      };
      // The engines' own rows: `custom` with the model it simulates this body with (the
      // scene's mass_model, solid by default), `custom-seed` with the seed's point masses at the
      // vertices.
      const MassProperties own =
          mass_properties(*body.shape, body.mass, scene_.bodies[i].mass_model);
      record("custom", {Status::Ok, "", own.mass, -1.0, own.center_of_mass, own.inertia});
      const MassProperties seed = vertex_mass_properties(*body.shape, body.mass);
      record("custom-seed", {Status::Ok, "", seed.mass, -1.0, seed.center_of_mass, seed.inertia});
      for (const Backend* b : libs) {
        MassResult r;
        const bool cacheable = cache_.enabled() && ResultCache::caches(b->name);
        const std::string key = cacheable ? cache_.mass_key(b->name, body) : std::string();
        std::optional<CachedResult<MassResult>> hit;
        if (cacheable) hit = cache_.load_mass(key);
        if (hit) {
          r = hit->result;
          backend_json(b->name)["cached"] = true;
        } else {
          r = isolated_mass(b->name, CallDeadlines{}.mass_s, [&] { return b->mass(body); });
          if (cacheable) cache_.store(key, r, 0.0);
        }
        record(b->name, r);
      }
    }
    // A backend named with --backends that computes no mass properties of its own is reported,
    // not dropped (the contract: named but not applicable -> unsupported).
    const bool named = !opt_.backends.empty() || !scene_.backends.empty();
    for (const std::string& name : wanted)
      if (named && name != "custom" && name != "custom-seed" && !backend(name).mass)
        set_status(name, Status::Unsupported,
                   name +
                       " computes no mass properties of its own (every backend is given the "
                       "exact solid values)");
    out_.skipped.push_back(
        "mass: custom is the model it simulates with, custom-seed the seed's vertex model; ode has "
        "no hull mass routine");
  }

  const Scene& scene_;
  const HarnessOptions& opt_;
  const std::vector<Backend>& table_;  // the backends to choose from
  std::vector<RigidBody> inputs_;
  ResultCache cache_;  // reference results on disk (disabled when opt.cache_dir is empty)
  bool expect_contact_bound_ = false;  // [expect.contact] compared with the oracle's answer
  bool expect_bodies_bound_ = false;   // [expect.body] compared with custom's final states
  SceneEvaluation out_;
  Json backends_json_;
  Json stability_json_;
  Json stability_sweep_json_;  // per backend: the verdicts at the other swept steps
};

}  // namespace

SceneEvaluation evaluate_scene(const Scene& scene, const HarnessOptions& opt) {
  if (!scene.expect || scene.expect_set_aside_by.empty()) return Evaluator(scene, opt).run();
  // An override changed the physics [expect] was written for: run without it, and say so.
  Scene changed = scene;
  changed.expect.reset();
  SceneEvaluation ev = Evaluator(changed, opt).run();
  std::string keys;
  for (const std::string& k : scene.expect_set_aside_by) keys += (keys.empty() ? "" : ", ") + k;
  ev.expect_checked = false;
  ev.expect_unchecked.push_back("[expect]: written for the scene as its file gives it; " + keys +
                                " changed that");
  ev.json["expect"]["checked"] = false;
  ev.json["expect"]["passed"] = false;
  ev.json["expect"]["unchecked"] = ev.expect_unchecked;
  ev.json["expect"]["known_failure"] = scene.expect->known_failure;
  return ev;
}

}  // namespace rbx
