// The stability check of the stiff and extreme scenes.
#include "comparisons/eval/evaluator.h"

namespace rbx::eval_detail {

void Evaluator::stability(const std::string& name, const DynRun& run, const DynamicsFrame& fr,
                          bool study_step) {
  const StabilityGeometry geo = stability_geometry(inputs_);
  StabilityInvariants inv{fr.e0, fr.p0, fr.h0, fr.closed, fr.p_scale, fr.h_scale};
  const StabilityTrace tr =
      trace_stability(inputs_, run.result, sample_overlaps(run, geo), geo, inv, scene_.sim.gravity);
  const double jitter = rest_jitter(inputs_, run.result.samples, scene_.sim.gravity);
  StabilityRow row;
  row.backend = name;
  row.study_step = study_step;
  row.status = to_string(run.result.status);
  row.dt = run.dt;
  row.restitution = scene_.sim.restitution;
  row.nonfinite = tr.nonfinite;
  row.energy_growth_rel = tr.growth;
  row.energy_drift_rel = tr.drift_e;
  row.energy_change_rel = tr.e_change;
  if (fr.closed) {
    row.momentum_drift_rel = tr.drift;
    row.angular_momentum_drift_rel = tr.hdrift;
  }
  row.max_penetration_rel = tr.pen_max;
  row.rest_penetration_rel = tr.pen_rest;
  row.tunnelled_pairs = tr.tunnelled;
  if (scene_.sim.gravity.norm() > 0) row.jitter_rms_mps = jitter;
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
  row.verdict = verdict.verdict;
  row.why = verdict.why;
  if (study_step) {
    stability_dt_study_json_[name].push_back(stability_json(row));
    return;
  }
  stability_json_[name] = stability_json(row);
  metric("stability", name, "", "energy_growth_err", std::max(tr.growth, 0.0), "invariant");
  metric("stability", name, "", "max_penetration_rel_err", tr.pen_max, "exact");
  metric("stability", name, "", "tunnelled_pairs_err", tr.tunnelled, "invariant");
  if (scene_.sim.gravity.norm() > 0)
    metric("stability", name, "", "jitter_rms_mps_err", jitter, "invariant");
}

std::vector<double> Evaluator::sample_overlaps(const DynRun& run, const StabilityGeometry& geo) {
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

}  // namespace rbx::eval_detail
