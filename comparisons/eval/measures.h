// What the harness measures, as free functions of the bodies and the runs: contact queries and
// dynamics runs (through the reference-result cache), energies and momenta, the dt study's steps
// and contact phases, and the stability check's trace (exact overlaps, tunnelling, drift).
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "comparisons/eval/contact_eval.h"
#include "comparisons/eval/result_cache.h"
#include "comparisons/scene/scene.h"
#include "engine/body.h"
#include "reference/backend.h"
#include "reference/exact.h"

namespace rbx {

/// A dynamics run with its wall-clock time; library exceptions become status Error.
struct DynRun {
  DynamicsResult result;
  double runtime_s = 0.0;  // the answering run's time, or the median of its timed repeats
  Timing timing;           // cold_s: the answering run; the rest once timed (time_dynamics)
  double dt = 0.0;
  bool cached = false;    // from the reference-result cache
  std::string cache_key;  // the run's cache key ("" : not cacheable)
};

/// Runs `b` on the scene at step `dt`, sampling every `sample_every` steps (0: none), at solver
/// budget `budget` (DynamicsOptions::budget; 0: as configured). A reference backend's run comes
/// from the cache when it holds this very call (the bodies as built from the scene, the
/// settings, dt, sampling and budget); otherwise it runs and is stored.
DynRun run_dynamics(const Backend& b, const Scene& scene, double dt, long sample_every,
                    const ResultCache& cache, const std::vector<RigidBody>& bodies, int budget = 0);

/// Times the fresh, answered runs of one scene together, interleaved (timing.h: warmed up,
/// repeated to at least `budget_s` each, the median with its spread), each as its answering call
/// was made (step `dt`, sampling every `sample_every`); each run's runtime_s becomes the median.
/// A run that fails while being timed keeps its answering call's time, counted as one round.
void time_dynamics(const std::vector<const Backend*>& backends, const std::vector<DynRun*>& runs,
                   const Scene& scene, long sample_every, double budget_s);

/// A contact query's answer: the cached run of the same query (a reference backend's, see
/// result_cache.h, with the timing stored with it), or one fresh call, not yet timed.
ContactRun answer_contact(const Backend& be, const RigidBody& a, const RigidBody& b,
                          const ResultCache& cache);

/// Every backend's query on one pair: its run, and the run of its "prebuilt" variant (the
/// library's shapes built once) where it has one and answered.
struct PairRuns {
  std::vector<ContactRun> runs;                     // one per backend, in order
  std::vector<std::optional<ContactRun>> prebuilt;  // likewise
};

/// Every backend answers (answer_contact), then the fresh answers are timed together, interleaved
/// (time_contacts, at least `budget_s` each; 0: untimed, each with its one call's time) and stored
/// in the cache with their timing.
PairRuns contact_runs(const std::vector<const Backend*>& backends, const RigidBody& a,
                      const RigidBody& b, const ResultCache& cache, double budget_s);

/// Kinetic energy of the bodies at t = 0 (J).
double initial_kinetic_energy(const std::vector<RigidBody>& inputs);
/// Linear momentum of the moving bodies in states `s` (kg m/s).
Vec3 linear_momentum(const std::vector<RigidBody>& inputs, const std::vector<BodyFinal>& s);
/// Angular momentum about the origin of the moving bodies in states `s` (kg m^2/s).
Vec3 angular_momentum(const std::vector<RigidBody>& inputs, const std::vector<BodyFinal>& s);
/// The scales (linear, angular) a momentum drift in states `s` is measured against: the run's
/// own from its start (`p_scale`, `h_scale`), or, where every body started still (both 0), the
/// sums of the bodies' momentum magnitudes in `s`, so that equal and opposite momenta count as
/// conserved to their own round-off; 1 where nothing moves at all.
std::pair<double, double> drift_scales(const std::vector<RigidBody>& inputs,
                                       const std::vector<BodyFinal>& s, double p_scale,
                                       double h_scale);
/// The bodies' states at t = 0.
std::vector<BodyFinal> initial_states(const std::vector<RigidBody>& inputs);
/// Size of a body: its bounding-box diagonal (m).
double body_size(const RigidBody& b);
/// "self dt=..." : a metric measured against the same backend at step `dt`.
std::string fmt_dt(double dt);

/// f(0), ..., f(n - 1) on two threads (the machine's two cores), interleaved. Each value is
/// computed as it would be on one thread, so results are the same; f must not share mutable
/// state (the exact oracle does not). A thrown exception is rethrown here.
std::vector<double> parallel_map(size_t n, const std::function<double(size_t)>& f);

/// Time steps of the dt study, coarsest first: the scene's dt_study, else its dt scaled by 4, 2,
/// 1, 1/2, 1/4.
std::vector<double> dt_study_steps(const Scene& scene);

/// Contact phases besides the scene as written (phase 0: first contact on a step boundary, as
/// every analytic scene is written): first contact 1/3 and 2/3 of a step later.
struct ContactPhase {
  const char* label;  // as written into metric names and JSON
  double fraction;    // of a step
};
constexpr ContactPhase kContactPhases[] = {{"1_3", 1.0 / 3.0}, {"2_3", 2.0 / 3.0}};

/// The scene with every moving body moved back along its velocity by `shift` seconds and one
/// more step of duration: first contact comes `shift` later in the step, and the run ends
/// dt - shift after the written end, in free flight (no gravity: the closed form's final
/// velocities are unchanged).
Scene shifted_scene(const Scene& scene, double shift);

/// The bodies' geometry for the stability check, built once per run.
struct StabilityGeometry {
  std::vector<SatShape> shapes;  // each body's exact-query topology
  std::vector<double> radius;    // about the centre of mass, holding every vertex
  /// A pair watched for tunnelling: apart at t = 0 along `normal`, with the half-thicknesses
  /// of both bodies along it summed in `reach`.
  struct Watch {
    size_t i, k;
    Vec3 normal;
    double reach;
  };
  std::vector<Watch> watch;
};

/// Watched: every pair with a static body (walls, floors), and every pair in scenes of up to
/// three bodies; free bodies in a crowd legitimately change sides, and 500,000 pairs cost too
/// much.
StabilityGeometry stability_geometry(const std::vector<RigidBody>& inputs);

/// The deepest exact overlap of any pair in a sample, relative to the pair's smaller body.
double deepest_overlap(const StabilityGeometry& g, const std::vector<RigidBody>& inputs,
                       const StateSample& smp);

/// The number of samples before the first one with a non-finite state.
size_t finite_prefix(const std::vector<StateSample>& samples);

/// The initial invariants a run is measured against.
struct StabilityInvariants {
  double e0;
  Vec3 p0, h0;
  bool closed;  // momentum is an invariant
  double p_scale, h_scale;
};

/// What the stability check reads off a run's samples.
struct StabilityTrace {
  bool nonfinite = false;
  double growth = 0.0;    // the largest energy gain, relative
  double made_j = 0.0;    // J: the most kinetic energy reached, where the bodies started still
                          // with no energy (growth is then relative to it); 0 otherwise
  double drift_e = 0.0;   // the largest |E - E0|, relative, signed (+ gained, - lost)
  double e_change = 0.0;  // at the end (the final state when the run finished)
  double drift = 0.0, hdrift = 0.0;  // momentum drifts (closed systems)
  double pen_max = 0.0;              // the deepest overlap of any sample
  double pen_rest = 0.0;  // the least over the last fifth of the run of each sample's deepest
  int tunnelled = 0;      // watched pairs that passed through each other
};

/// The trace of `run` from `overlaps` (deepest_overlap of each finite sample).
StabilityTrace trace_stability(const std::vector<RigidBody>& inputs, const DynamicsResult& run,
                               const std::vector<double>& overlaps, const StabilityGeometry& g,
                               const StabilityInvariants& inv, const Vec3& gravity);

/// Jitter at rest: RMS speed of the moving bodies over the last fifth of the run (0 without
/// gravity, where it means nothing, or with fewer than 5 samples).
double rest_jitter(const std::vector<RigidBody>& inputs, const std::vector<StateSample>& samples,
                   const Vec3& gravity);

/// The final states that miss [expect.body] beyond its tolerance, one line each, named by
/// `backend` ("custom: body A velocity (...), expected (...) (tolerance 1e-06)").
std::vector<std::string> expect_violations(const std::string& backend, const Expect& expect,
                                           const std::vector<BodyFinal>& finals);

}  // namespace rbx
