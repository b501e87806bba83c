// The dynamics checks: every backend's main run and what is measured on it.
#include "comparisons/eval/evaluator.h"

namespace rbx::eval_detail {

void Evaluator::dynamics_checks() {
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
  // The run times: every fresh run timed again, the backends interleaved over this scene.
  std::vector<const Backend*> timed;
  std::vector<DynRun*> runs;
  for (auto& [name, run] : mains) {
    timed.push_back(&backend(name));
    runs.push_back(&run);
  }
  time_dynamics(timed, runs, scene_, fr.sample_every, opt_.timing_budget_s);
  for (const auto& [name, run] : mains)
    if (run.result.status == Status::Ok)
      for (const BodyFinal& f : run.result.finals)
        fr.angular = fr.angular || f.angular_velocity.norm() > 1e-12;
  for (const auto& [name, main] : mains) backend_dynamics(name, main, fr);
  if (!fr.angular) out_.skipped.push_back("angular metrics: nothing rotates in this scene");
}

Evaluator::DynamicsFrame Evaluator::dynamics_frame() {
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
  fr.wants_studies = opt_.studies && (scene_.has_check(CheckKind::Impulse) ||
                                      scene_.has_check(CheckKind::Trajectory));
  fr.dts = dt_study_steps(scene_);
  fr.finest = fr.dts.back();
  return fr;
}

void Evaluator::backend_dynamics(const std::string& name, const DynRun& main,
                                 const DynamicsFrame& fr) {
  Json& bj = backend_json(name);
  bj = dynamics_result_json(inputs_, main.result, main.runtime_s);
  put_timing(main.timing, bj);
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
  const StudyRuns sw = study_runs(backend(name), main, fr);
  std::string against;
  const std::vector<std::optional<RefState>> ref = velocity_reference(name, main, sw, fr, against);
  contact_phases(name, main, fr, bj);
  if (fr.wants_studies && !against.empty()) {
    const auto error_of = [&](const std::vector<BodyFinal>& finals) {
      return ke_norm_error(inputs_, finals, ref, fr.e0_kin);
    };
    for (const DynRun& r : sw.runs) {
      if (r.result.status != Status::Ok) continue;
      if (!fr.have_expect && &r == &sw.runs.back()) continue;  // zero by construction
      out_.error_vs_runtime.push_back(
          {name, "dynamics", r.dt, Timing::once(r.runtime_s), error_of(r.result.finals), against});
    }
    const std::vector<ErrorRuntimePoint> budgets = budget_points(
        backend(name), scene_, main, cache_, inputs_, error_of, against, &out_.skipped);
    out_.error_vs_runtime.insert(out_.error_vs_runtime.end(), budgets.begin(), budgets.end());
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
        fr.have_expect ? ke_norm_error(inputs_, main.result.finals, fr.expected, fr.e0_kin) : 0.0);
  if (scene_.has_check(CheckKind::Stability)) stability(name, main, fr);
  // The verdict at every other step of the dt study (report rows; not metrics of the check).
  if (sw.stability_dt_study)
    for (const DynRun& r : sw.runs)
      if (std::abs(r.dt - scene_.sim.dt) > 1e-15 * r.dt)
        stability(name, r, fr, /*study_step=*/true);
}

void Evaluator::stopped_run(const std::string& name, const DynRun& main, const DynamicsFrame& fr) {
  if (scene_.has_check(CheckKind::Stability)) stability(name, main, fr);
  if (binds(name) && !scene_.expect->bodies.empty()) {
    out_.expect_failures.push_back(name +
                                   ": the run stopped before t = duration: " + main.result.message);
    expect_bodies_bound_ = true;
  }
}

void Evaluator::conservation(const std::string& name, const std::vector<BodyFinal>& f,
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

void Evaluator::check_expect_bodies(const std::string& name, const std::vector<BodyFinal>& finals) {
  for (std::string& s : expect_violations(name, *scene_.expect, finals))
    out_.expect_failures.push_back(s);
}

void Evaluator::mark_expect_disagreement(const std::string& name,
                                         const std::vector<BodyFinal>& finals,
                                         double velocity_err) {
  const auto v = expect_violations(name, *scene_.expect, finals);
  if (v.empty()) return;
  const std::string text = v.front() + (v.size() > 1 ? " (and more)" : "");
  const bool velocities = velocity_err > 0.0;
  (velocities && velocity_err <= kMarkVelocityErr ? out_.deviations : out_.disagreements)
      .push_back(text + (velocities ? "; velocity error " + fmt_num(velocity_err, 3) : ""));
}

}  // namespace rbx::eval_detail
