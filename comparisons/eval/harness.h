// The comparison harness: runs the checks a scene asks for, with only the backends that serve
// them, and measures every backend against the best available truth: the scene's closed form
// ([expect]) first, else the `exact` oracle (contacts), else the same backend at its finest
// time step (self-consistency, Erez, Tassa & Todorov 2015), else another backend (marked).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "comparisons/eval/json_io.h"
#include "comparisons/eval/timing.h"
#include "comparisons/scene/scene.h"
#include "comparisons/scene/scene_collection.h"  // scene_family, for the harness's users
#include "reference/backend.h"

namespace rbx {

/// Harness settings.
struct HarnessOptions {
  std::string backends;           // --backends LIST ("" : the scene's, or all that serve a check)
  bool studies = true;            // run the dt and budget studies for error against run time
  double timing_budget_s = 0.01;  // per contact query and per main dynamics run, each backend:
                                  // timed at least this long (timing.h); 0: the answers only
  /// Backends to choose from; nullptr: the registry (reference/registry.cpp). Tests pass their
  /// own table to add a failing backend without touching the registry.
  const std::vector<Backend>* registry = nullptr;
  /// Reference-result cache folder (comparisons/eval/result_cache.h); "" : no cache. Results are
  /// byte-identical either way; a cached backend's JSON says "cached": true (its timings are
  /// those of the run that filled the cache).
  std::string cache_dir;
  /// false: the cache is filled, never read (rbx report: its timings are its own).
  bool cache_reads = true;
  /// Run every impact scene with a closed form also with first contact 1/3 and 2/3 of a step
  /// later (the bodies moved back along their velocities; metrics velocity_err_ke_phase_*).
  bool phases = true;
};

/// A measured explanation of a backend's miss: on an impact, what its first impulse saw against
/// the exact oracle at the same poses (impact_cause.h); on a contact query, the first sign on
/// its answer (contact_cause.h).
struct Cause {
  std::string backend;
  std::string scene;
  std::string kind;    // the first measured sign (one line, shared by scenes with that sign)
  std::string detail;  // the measurements behind it
  std::string check = "impulse";  // the check it explains: "impulse" or "contact"
};

/// One measured number.
struct Metric {
  std::string check;  // contact | impulse | trajectory | stability | mass
  std::string backend;
  std::string pair;  // "A-B" for contact metrics, "" otherwise
  std::string name;  // e.g. normal_err_deg; names of errors contain "err"
  double value = 0.0;
  std::string against;  // analytic | exact | self dt=... | backend NAME | invariant
};

/// One point of error against run time.
struct ErrorRuntimePoint {
  std::string backend;
  std::string kind;    // "dynamics" (a time step), "budget" (a solver budget at the scene's
                       // step), "contact" or "contact-prebuilt" (a query)
  double dt = 0.0;     // s (dynamics, budget)
  Timing timing;       // a query's (timing.h); a dynamics run's is its one run: one round, one call
  double error = 0.0;  // velocity error in the kinetic-energy norm, or normal angle (deg)
  std::string against;
  int budget = 0;  // the solver budget (kind "budget"; Backend::budget), else 0: as configured
};

struct EnsembleResult;  // comparisons/eval/ensemble.h

/// One stability run of a backend: at the scene's step, or at another step of the scene's
/// dt study. The scene's JSON holds it as "stability" (the scene's step) and
/// "stability_dt_study" (stability_json and read_runs convert).
struct StabilityRow {
  std::string backend;
  bool study_step = false;  // a step of the scene's dt study, not the scene's own
  std::string status;       // the run's status
  double dt = 0.0, restitution = 0.0;
  bool nonfinite = false;
  double energy_growth_rel = 0.0, energy_drift_rel = 0.0, energy_change_rel = 0.0;
  std::optional<double> momentum_drift_rel, angular_momentum_drift_rel;  // closed systems
  double max_penetration_rel = 0.0, rest_penetration_rel = 0.0;
  int tunnelled_pairs = 0;
  std::optional<double> jitter_rms_mps;  // under gravity
  std::string verdict;
  std::vector<std::string> why;
};

/// The contract's JSON of one stability run (docs/contract.md).
Json stability_json(const StabilityRow& row);

/// One backend's run on a scene, as the scene's JSON records it ("backends" and "stability"):
/// read back once (read_runs), so that what renders a scene reads no JSON.
/// One run of a contact phase: its velocity error (energy norm), or its failure ("error: ...");
/// neither where the phase was not run.
struct ContactPhaseCell {
  std::optional<double> error;
  std::string failure;
};

/// A backend's velocity error with first contact as written and 1/3 and 2/3 of a step later,
/// and the worst of them (the scene's "contact_phase").
struct ContactPhaseRow {
  ContactPhaseCell written, one_third, two_thirds, worst;
};

struct BackendRun {
  std::string backend;
  Status status = Status::Ok;       // the first failure of its calls, else ok (or touching)
  std::string message;              // the first failure's message, or a note on an ok answer
  std::optional<double> runtime_s;  // its calls' summed median time (s), where recorded
  std::string stability;  // the stability check's verdict; "" where that check did not run
  std::optional<ContactPhaseRow> contact_phase;  // where the scene's impacts were rerun so
};

/// Everything the harness learned about one scene.
struct SceneEvaluation {
  std::string family;  // folder under scenes/, or "scenes"
  Json json;           // the contract's per-scene object, metrics included
  std::vector<Metric> metrics;
  std::vector<ErrorRuntimePoint> error_vs_runtime;
  std::vector<std::string> skipped;          // what was left out, and why
  std::vector<std::string> expect_failures;  // violated [expect] entries, "SUBJECT: what"
                                             // (custom: the engine; exact: the oracle)
  bool expect_checked = false;  // some part of [expect] was bound by a backend that ran: never
                                // "passed" otherwise
  std::vector<std::string> expect_unchecked;  // parts of [expect] no backend run could bind, why
  bool expect_known = false;  // failures are all custom's and the scene's known_failure explains
                              // them: compare does not fail on them
  std::vector<std::string> disagreements;  // clearly different from the truth (see kMark*)
  std::vector<std::string> deviations;     // beyond the scene's tolerance, yet close
  std::vector<Cause> causes;               // why each impact miss happened, measured
  std::vector<BackendRun> runs;            // every backend that ran, by name (read_runs)
  // Every stability run, by backend: the scene's step, then its dt study's (read_runs).
  std::vector<StabilityRow> stability;
  std::string known_failure;  // the scene's [expect] known_failure ("ENGINE: why"), "" if none
  bool has_geometry = false;  // the contact check drew the pair's geometry (its figure exists)
  // The scene's [ensemble] run (the report's, run_scene_ensembles), also in `json` as
  // "ensemble"; null when none ran.
  std::shared_ptr<const EnsembleResult> ensemble;

  /// The run of `backend`; nullptr when it did not run on this scene.
  const BackendRun* run_of(const std::string& backend) const;
};

/// Fills `ev.runs`, `ev.stability` and `ev.known_failure` from `ev.json` (the one reading of it,
/// after an evaluation and after a transfer between processes).
void read_runs(SceneEvaluation& ev);

/// Thresholds between a deviation and a disagreement: a contact normal more than 1 degree off or
/// a depth more than 1 % of the smaller body off; a velocity error above 0.1 % (energy norm).
constexpr double kMarkAngleDeg = 1.0;
constexpr double kMarkDepthRel = 0.01;
constexpr double kMarkVelocityErr = 1e-3;

/// Runs every check of the scene. Never throws for a backend's failure (that backend's status
/// becomes error); throws InputError only for bad options.
SceneEvaluation evaluate_scene(const Scene& scene, const HarnessOptions& opt);

}  // namespace rbx
