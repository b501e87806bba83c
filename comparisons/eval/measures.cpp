#include "comparisons/eval/measures.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <thread>

#include "comparisons/eval/metrics.h"
#include "engine/bounding.h"
#include "engine/format.h"

namespace rbx {

// A reference backend's run comes from the cache when it holds this very call (the bodies as
// built from the scene, the settings, dt and sampling); otherwise it runs and is stored.
DynRun run_dynamics(const Backend& b, const Scene& scene, double dt, long sample_every,
                    const ResultCache& cache, const std::vector<RigidBody>& bodies, int budget) {
  DynRun run;
  run.dt = dt;
  const DynamicsOptions opt{dt, sample_every, budget};
  const bool cacheable = cache.enabled() && ResultCache::caches(b.name);
  const std::string key =
      cacheable ? cache.dynamics_key(b.name, scene, bodies, opt) : std::string();
  run.cache_key = key;
  if (cacheable)
    if (auto hit = cache.load_dynamics(key)) {
      run.result = std::move(hit->result);
      run.runtime_s = hit->runtime_s;
      run.timing = Timing::once(run.runtime_s);
      run.cached = true;
      return run;
    }
  const TimedDynamics t = run_dynamics_isolated(b, scene, opt);
  run.result = t.result;
  run.runtime_s = t.runtime_s;
  run.timing = Timing::once(t.runtime_s);
  // A backend that returns fewer final states than bodies has failed in a way we must show.
  if (run.result.status == Status::Ok && run.result.finals.size() != scene.bodies.size()) {
    run.result.status = Status::Error;
    run.result.message = "backend returned " + std::to_string(run.result.finals.size()) +
                         " final states for " + std::to_string(scene.bodies.size()) + " bodies";
  }
  if (cacheable) cache.store(key, run.result, run.runtime_s);
  return run;
}

void time_dynamics(const std::vector<const Backend*>& backends, const std::vector<DynRun*>& runs,
                   const Scene& scene, long sample_every, double budget_s) {
  if (budget_s <= 0) return;
  std::vector<TimedSubject> subjects;
  std::vector<Timing*> timed;
  std::vector<DynRun*> fresh;
  for (size_t i = 0; i < backends.size() && i < runs.size(); ++i) {
    const Backend& be = *backends[i];
    DynRun& run = *runs[i];
    if (run.cached || run.result.status != Status::Ok || !be.dynamics) continue;
    const DynamicsOptions opt{run.dt, sample_every};
    subjects.push_back({be.name, be.library, [&be, &scene, opt] { be.dynamics(scene, opt); },
                        CallDeadlines{}.dynamics_s});
    timed.push_back(&run.timing);
    fresh.push_back(&run);
  }
  TimingPlan plan;
  plan.min_time_s = budget_s;
  time_into(subjects, timed, plan);
  for (DynRun* run : fresh)
    if (run->timing.rounds > 0)
      run->runtime_s = run->timing.median_s;
    else
      run->timing = Timing::once(run->runtime_s);
}

ContactRun answer_contact(const Backend& be, const RigidBody& a, const RigidBody& b,
                          const ResultCache& cache) {
  if (cache.enabled() && ResultCache::caches(be.name))
    if (auto hit = cache.load_contact(cache.contact_key(be.name, a, b))) {
      ContactRun run;
      run.result = std::move(hit->result);
      run.timing = hit->timing;
      run.cached = true;
      return run;
    }
  return run_contact(be, a, b);
}

PairRuns contact_runs(const std::vector<const Backend*>& backends, const RigidBody& a,
                      const RigidBody& b, const ResultCache& cache, double budget_s) {
  PairRuns out;
  std::vector<Backend> variants;
  variants.reserve(backends.size());  // the subjects below point into it
  std::vector<const Backend*> subjects;
  for (const Backend* be : backends) {
    out.runs.push_back(answer_contact(*be, a, b, cache));
    out.prebuilt.emplace_back();
  }
  for (size_t i = 0; i < backends.size(); ++i) {
    const QueryVariant* v = find_query_variant(backends[i]->name, "prebuilt");
    if (!v || !timeable(out.runs[i])) continue;
    variants.push_back(*backends[i]);
    variants.back().name = backends[i]->name + "+prebuilt";
    variants.back().contact = v->contact;
    out.prebuilt[i] = answer_contact(variants.back(), a, b, cache);
  }
  std::vector<ContactRun*> runs;
  for (size_t i = 0; i < backends.size(); ++i) {
    subjects.push_back(backends[i]);
    runs.push_back(&out.runs[i]);
  }
  size_t k = 0;
  for (size_t i = 0; i < backends.size(); ++i)
    if (out.prebuilt[i]) {
      subjects.push_back(&variants[k++]);
      runs.push_back(&*out.prebuilt[i]);
    }
  // Untimed answers (rbx check's) are stored with their one call's time: only rbx check reads
  // the cache, and it reports no query times.
  if (budget_s > 0) {
    TimingPlan plan;
    plan.min_time_s = budget_s;
    time_contacts(subjects, runs, a, b, plan);
  } else {
    // No repeats: an answer's time is the one call that gave it, as a dynamics run's is.
    for (ContactRun* r : runs)
      if (!r->cached && r->timing.rounds == 0 && timeable(*r))
        r->timing = Timing::once(r->timing.cold_s);
  }
  if (cache.enabled())
    for (size_t i = 0; i < subjects.size(); ++i)
      if (!runs[i]->cached && ResultCache::caches(subjects[i]->name))
        cache.store(cache.contact_key(subjects[i]->name, a, b), runs[i]->result, runs[i]->timing);
  return out;
}

// Kinetic energy of the bodies at t = 0 (J).
double initial_kinetic_energy(const std::vector<RigidBody>& inputs) {
  double e = 0.0;
  for (const RigidBody& b : inputs) e += b.kinetic_energy();
  return e;
}

Vec3 linear_momentum(const std::vector<RigidBody>& inputs, const std::vector<BodyFinal>& s) {
  Vec3 p = Vec3::Zero();
  for (size_t i = 0; i < inputs.size() && i < s.size(); ++i)
    if (!inputs[i].is_static) p += inputs[i].mass * s[i].velocity;
  return p;
}

Vec3 angular_momentum(const std::vector<RigidBody>& inputs, const std::vector<BodyFinal>& s) {
  Vec3 h = Vec3::Zero();
  for (size_t i = 0; i < inputs.size() && i < s.size(); ++i) {
    const RigidBody& b = inputs[i];
    if (b.is_static) continue;
    const Mat3 rot = s[i].orientation.toRotationMatrix();
    h += s[i].position.cross(b.mass * s[i].velocity) +
         rot * b.inertia_body * rot.transpose() * s[i].angular_velocity;
  }
  return h;
}

std::pair<double, double> drift_scales(const std::vector<RigidBody>& inputs,
                                       const std::vector<BodyFinal>& s, double p_scale,
                                       double h_scale) {
  if (p_scale > 0 || h_scale > 0) return {p_scale, h_scale};
  double p = 0.0, h = 0.0;
  for (size_t i = 0; i < inputs.size() && i < s.size(); ++i) {
    if (inputs[i].is_static) continue;
    const std::vector<BodyFinal> one = {s[i]};
    const std::vector<RigidBody> body = {inputs[i]};
    p += linear_momentum(body, one).norm();
    h += angular_momentum(body, one).norm();
  }
  return {p > 0 ? p : 1.0, h > 0 ? h : 1.0};
}

std::vector<BodyFinal> initial_states(const std::vector<RigidBody>& inputs) {
  std::vector<BodyFinal> s;
  for (const RigidBody& b : inputs)
    s.push_back({b.name, b.position, b.orientation, b.velocity, b.angular_velocity});
  return s;
}

// Size of a body: its bounding-box diagonal (m).
double body_size(const RigidBody& b) { return shape_size(*b.shape); }

std::string fmt_dt(double dt) { return "self dt=" + fmt_num(dt, 3); }

// f(0), ..., f(n - 1) on two threads (the machine's two cores), interleaved. Each value is
// computed as it would be on one thread, so results are the same; f must not share mutable
// state (the exact oracle does not). A thrown exception is rethrown here.
std::vector<double> parallel_map(size_t n, const std::function<double(size_t)>& f) {
  std::vector<double> out(n, 0.0);
  std::exception_ptr failure[2];
  auto work = [&](size_t first, std::exception_ptr& error) {
    try {
      for (size_t t = first; t < n; t += 2) out[t] = f(t);
    } catch (...) {
      error = std::current_exception();
    }
  };
  if (n < 8) {
    work(0, failure[0]);
    work(1, failure[1]);
  } else {
    std::thread helper(work, 1, std::ref(failure[1]));
    work(0, failure[0]);
    helper.join();
  }
  for (const std::exception_ptr& e : failure)
    if (e) std::rethrow_exception(e);
  return out;
}

// Default time steps for the dt study: the scene's dt scaled by 4, 2, 1, 1/2, 1/4.
std::vector<double> dt_study_steps(const Scene& scene) {
  if (!scene.dt_study.empty()) {
    std::vector<double> s = scene.dt_study;
    std::sort(s.rbegin(), s.rend());
    return s;
  }
  const double dt = scene.sim.dt;
  return {4 * dt, 2 * dt, dt, dt / 2, dt / 4};
}

// The scene with every moving body moved back along its velocity by `shift` seconds and one
// more step of duration: first contact comes `shift` later in the step, and the run ends
// dt - shift after the written end, in free flight (no gravity: the closed form's final
// velocities are unchanged).
Scene shifted_scene(const Scene& scene, double shift) {
  Scene out = scene;
  for (BodySpec& b : out.bodies)
    if (!b.is_static) b.position -= b.velocity * shift;
  out.sim.duration += scene.sim.dt;
  return out;
}

StabilityGeometry stability_geometry(const std::vector<RigidBody>& inputs) {
  StabilityGeometry g;
  for (const RigidBody& b : inputs) {
    g.shapes.emplace_back(*b.shape);
    g.radius.push_back(bounding_sphere(b).radius + b.shape->bounds().center().norm());
  }
  // Initial separating direction per pair (exact), to see who ends up past whom.
  for (size_t i = 0; i < inputs.size(); ++i)
    for (size_t k = i + 1; k < inputs.size(); ++k) {
      if (inputs[i].is_static && inputs[k].is_static) continue;
      if (inputs.size() > 3 && !inputs[i].is_static && !inputs[k].is_static) continue;
      const SatResult sat = sat_query(g.shapes[i], inputs[i].pose(), g.shapes[k], inputs[k].pose());
      if (sat.touching) continue;
      // Half-thickness of both bodies along the separating normal, at the t = 0 poses.
      double reach = 0.0;
      for (size_t m : {i, k}) {
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (size_t v = 0; v < inputs[m].shape->vertices().size(); ++v) {
          const double d = inputs[m].world_vertex(static_cast<int>(v)).dot(sat.normal);
          lo = std::min(lo, d);
          hi = std::max(hi, d);
        }
        reach += 0.5 * (hi - lo);
      }
      g.watch.push_back({i, k, sat.normal, reach});
    }
  return g;
}

double deepest_overlap(const StabilityGeometry& g, const std::vector<RigidBody>& inputs,
                       const StateSample& smp) {
  // Exact depth of every pair in bounding range, relative to the smaller body.
  double pen_sample = 0.0;
  for (size_t i = 0; i < inputs.size(); ++i) {
    for (size_t k = i + 1; k < inputs.size(); ++k) {
      if (inputs[i].is_static && inputs[k].is_static) continue;
      const Pose pa{smp.bodies[i].position, smp.bodies[i].orientation};
      const Pose pb{smp.bodies[k].position, smp.bodies[k].orientation};
      const double reach = g.radius[i] + g.radius[k];
      if ((pa.position - pb.position).norm() > reach + 1e-9 * reach) continue;
      const SatResult sat = sat_query(g.shapes[i], pa, g.shapes[k], pb);
      if (!sat.touching) continue;
      pen_sample =
          std::max(pen_sample, sat.depth / std::min(body_size(inputs[i]), body_size(inputs[k])));
    }
  }
  return pen_sample;
}

namespace {

bool finite_state(const BodyFinal& b) {
  return b.position.allFinite() && b.velocity.allFinite() && b.angular_velocity.allFinite();
}

}  // namespace

size_t finite_prefix(const std::vector<StateSample>& samples) {
  for (size_t t = 0; t < samples.size(); ++t)
    for (const BodyFinal& b : samples[t].bodies)
      if (!finite_state(b)) return t;
  return samples.size();
}

StabilityTrace trace_stability(const std::vector<RigidBody>& inputs, const DynamicsResult& run,
                               const std::vector<double>& overlaps, const StabilityGeometry& g,
                               const StabilityInvariants& inv, const Vec3& gravity) {
  StabilityTrace tr;
  const auto& samples = run.samples;
  tr.nonfinite = run.status == Status::Error && run.message.find("non-finite") != std::string::npos;
  double e_max = inv.e0, e_min = inv.e0, e_end = inv.e0;
  // Penetration at rest: the least, over the last fifth of the run, of each sample's deepest
  // overlap. An impact overlaps for a step or two and is gone; sinking persists in every sample.
  double pen_rest = std::numeric_limits<double>::infinity();
  // Against the starting energy; where the bodies start still with no potential energy, against
  // the most kinetic energy the run reaches (a growth of 1: all of it made by the run).
  double e_scale = std::max(std::abs(inv.e0), initial_kinetic_energy(inputs)), ke_max = 0.0;
  std::vector<bool> passed(g.watch.size(), false);
  const size_t rest_from = samples.size() * 4 / 5;
  size_t sample_index = 0;
  for (const StateSample& smp : samples) {
    const bool at_rest = sample_index++ >= rest_from;
    for (const BodyFinal& b : smp.bodies)
      if (!finite_state(b)) tr.nonfinite = true;
    if (tr.nonfinite) break;
    const double e = total_energy(inputs, smp.bodies, gravity);
    ke_max = std::max(ke_max, kinetic_energy(inputs, smp.bodies));
    e_max = std::max(e_max, e);
    e_min = std::min(e_min, e);
    e_end = e;
    if (inv.closed) {
      const auto [p_scale, h_scale] = drift_scales(inputs, smp.bodies, inv.p_scale, inv.h_scale);
      tr.drift =
          std::max(tr.drift, (linear_momentum(inputs, smp.bodies) - inv.p0).norm() / p_scale);
      tr.hdrift =
          std::max(tr.hdrift, (angular_momentum(inputs, smp.bodies) - inv.h0).norm() / h_scale);
    }
    const double pen_sample = overlaps[sample_index - 1];
    tr.pen_max = std::max(tr.pen_max, pen_sample);
    if (at_rest) pen_rest = std::min(pen_rest, pen_sample);
    // Tunnelling: a pair that started apart and now lies fully on the other side of its
    // initial separating plane, while too close sideways to have gone round: passed through.
    for (size_t w = 0; w < g.watch.size(); ++w) {
      const StabilityGeometry::Watch& p = g.watch[w];
      const Vec3 d0 = inputs[p.i].position - inputs[p.k].position;
      const Vec3 d = smp.bodies[p.i].position - smp.bodies[p.k].position;
      const double side0 = d0.dot(p.normal), side = d.dot(p.normal);
      const double lateral = (d - side * p.normal).norm();
      const double beside = g.radius[p.i] + g.radius[p.k];
      if (side0 > 0 && side < -p.reach && lateral < beside) passed[w] = true;
    }
  }
  for (bool p : passed) tr.tunnelled += p ? 1 : 0;
  if (!(e_scale > 0)) {
    e_scale = ke_max > 0 ? ke_max : 1.0;
    tr.made_j = ke_max;
  }
  tr.growth = (e_max - inv.e0) / e_scale;
  tr.pen_rest = std::isfinite(pen_rest) ? pen_rest : 0.0;  // 0: no sample at rest
  // Signed drift: the largest |E - E0| / scale over the run, with its sign (gain +, loss -);
  // and the change at the end (the final state when the run finished).
  tr.drift_e = e_max - inv.e0 >= inv.e0 - e_min ? tr.growth : (e_min - inv.e0) / e_scale;
  if (run.status == Status::Ok && !tr.nonfinite) e_end = total_energy(inputs, run.finals, gravity);
  tr.e_change = (e_end - inv.e0) / e_scale;
  return tr;
}

double rest_jitter(const std::vector<RigidBody>& inputs, const std::vector<StateSample>& samples,
                   const Vec3& gravity) {
  if (gravity.norm() <= 0 || samples.size() < 5) return 0.0;
  double sum = 0.0;
  int count = 0;
  for (size_t t = samples.size() * 4 / 5; t < samples.size(); ++t)
    for (size_t i = 0; i < inputs.size(); ++i)
      if (!inputs[i].is_static) {
        sum += samples[t].bodies[i].velocity.squaredNorm();
        ++count;
      }
  return count ? std::sqrt(sum / count) : 0.0;
}

// The final states that miss [expect.body] beyond its tolerance, one line each ("BACKEND: body
// NAME velocity (...), expected (...) (tolerance ...)").
std::vector<std::string> expect_violations(const std::string& backend, const Expect& expect,
                                           const std::vector<BodyFinal>& finals) {
  std::vector<std::string> v;
  const double tol = expect.tolerance;
  for (const ExpectBody& eb : expect.bodies) {
    auto it = std::find_if(finals.begin(), finals.end(),
                           [&](const BodyFinal& f) { return f.name == eb.name; });
    if (it == finals.end()) continue;
    auto check = [&](const char* what, const std::optional<Vec3>& want, const Vec3& got) {
      if (want && (got - *want).cwiseAbs().maxCoeff() > tol)
        v.push_back(backend + ": body " + eb.name + " " + what + " " + fmt_vec(got, 8) +
                    ", expected " + fmt_vec(*want, 8) + " (tolerance " + fmt_num(tol, 3) + ")");
    };
    check("velocity", eb.velocity, it->velocity);
    check("angular_velocity", eb.angular_velocity, it->angular_velocity);
    check("position", eb.position, it->position);
  }
  return v;
}

}  // namespace rbx
