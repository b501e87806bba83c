// The time-step study, the contact phases and the trajectories of the dynamics checks.
#include "comparisons/eval/evaluator.h"

namespace rbx::eval_detail {

Evaluator::StudyRuns Evaluator::study_runs(const Backend& be, const DynRun& main,
                                           const DynamicsFrame& fr) {
  StudyRuns sw;
  // Velocity errors belong to the impulse and trajectory checks: a stability-only scene
  // does not pay for the self-consistency run.
  sw.wants_velocity =
      scene_.has_check(CheckKind::Impulse) || scene_.has_check(CheckKind::Trajectory);
  sw.stability_dt_study =
      scene_.has_check(CheckKind::Stability) && !scene_.dt_study.empty() && fr.wants_studies;
  if (!fr.wants_studies && (fr.have_expect || !sw.wants_velocity) &&
      !scene_.has_check(CheckKind::Trajectory))
    return sw;
  const std::vector<double> to_run = fr.wants_studies ? fr.dts : std::vector<double>{fr.finest};
  for (double dt : to_run) {
    if (std::abs(dt - scene_.sim.dt) <= 1e-15 * dt) {
      sw.runs.push_back(main);
      continue;
    }
    // The finest run of a trajectory check is sampled at the same times as the main run; so
    // is every run of a stability scene that names its own dt study (its verdict is given
    // at each step: the thin wall must not tunnel at any).
    const bool sample =
        (scene_.has_check(CheckKind::Trajectory) && dt == fr.finest) || sw.stability_dt_study;
    const long every =
        sample ? std::max<long>(1, std::lround(fr.sample_every * scene_.sim.dt / dt)) : 0;
    sw.runs.push_back(run_dynamics(be, scene_, dt, every, cache_, inputs_));
  }
  if (sw.runs.back().result.status == Status::Ok) sw.fine = sw.runs.back();
  return sw;
}

std::vector<std::optional<RefState>> Evaluator::velocity_reference(const std::string& name,
                                                                   const DynRun& main,
                                                                   const StudyRuns& sw,
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
      ref[i] = RefState{sw.fine->result.finals[i].velocity,
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

void Evaluator::contact_phases(const std::string& name, const DynRun& main, const DynamicsFrame& fr,
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
    out_.causes.push_back(
        impact_cause(scene_, inputs_, name, as_written ? main.result.first_impulse : worst_fi,
                     as_written ? inputs_ : worst_start, written, worst, worst_phase, fr.expected));
  }
}

void Evaluator::trajectory_divergence(const std::string& name, const DynRun& main,
                                      const StudyRuns& sw, const DynamicsFrame& fr) {
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

}  // namespace rbx::eval_detail
