// The harness's evaluation of one scene (evaluate_scene, comparisons/eval/harness.h), one class
// whose checks live each in its own file: harness.cpp (the run and the JSON around it),
// contact_check.cpp, dynamics_check.cpp (the main runs and what is measured on them),
// dt_study_check.cpp (the time-step study, contact phases, trajectories), stability_check.cpp and
// mass_check.cpp. Internal to eval/.
#pragma once

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
#include "comparisons/eval/harness.h"
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

namespace rbx::eval_detail {

/// True when two answers to one query are the same contact (bit for bit: a prebuilt shape is
/// the same shape).
inline bool same_answer(const ContactPoint& x, const ContactPoint& y) {
  return x.normal == y.normal && x.point == y.point && x.depth == y.depth;
}

inline std::string pair_name(const RigidBody& a, const RigidBody& b) {
  return a.name + "-" + b.name;
}

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

  SceneEvaluation run();

 private:
  // Which parts of [expect] were bound: [expect.contact] by the oracle's query of the first pair
  // (whenever the contact check runs), [expect.body] by a bound engine's completed run (binds).
  // A reference outside the closed form is marked (disagrees), it does not bind it.
  void expect_binding();

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
  void contact_check();

  void contact_pair(const RigidBody& a, const RigidBody& b, bool first_pair,
                    const std::vector<std::string>& names, const Backend& exact);

  // The deepest point's and the whole set's metrics against the exact patch `sat.manifold`.
  void point_metrics(const std::string& name, const std::string& pair, const ContactResult& r,
                     const ContactPoint& deepest, const SatResult& sat, const RigidBody& a,
                     const RigidBody& b);
  // A touching answer with no normal: a library's convention at zero depth, right when the pair
  // touches there; a false contact when it does not; a miss when the pair penetrates beyond
  // `depth_tol` (its depth, zero, is scored as such; there is no normal to score).
  void touching_answer(const std::string& name, const std::string& pair, const ContactResult& r,
                       const ContactTruth& t, double depth_tol, const std::string& touch_src,
                       const std::string& depth_src);

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
    bool wants_studies = false;
    std::vector<double> dts;  // the dt study's steps, finest last
    double finest = 0.0;
  };

  // The dt study's runs of one backend; `fine` is the finest step's when it ran.
  struct StudyRuns {
    std::optional<DynRun> fine;
    std::vector<DynRun> runs;
    bool wants_velocity = false;      // the impulse or trajectory check asks for velocity errors
    bool stability_dt_study = false;  // a verdict at every step of its own dt study
  };

  void dynamics_checks();

  DynamicsFrame dynamics_frame();

  // Every metric of one backend's dynamics, in a fixed order: velocity against the closed form
  // or its finest step, the contact phases, the dt study, trajectory divergence, contact time,
  // conservation, [expect], stability.
  void backend_dynamics(const std::string& name, const DynRun& main, const DynamicsFrame& fr);

  // A run that stopped early: its stability verdict, and a failed [expect.body] for the engine
  // under test (no final state to compare is not a pass).
  void stopped_run(const std::string& name, const DynRun& main, const DynamicsFrame& fr);

  // The backend at every step of the dt study (or only the finest, the self-consistency
  // reference, when no study is asked for).
  StudyRuns study_runs(const Backend& be, const DynRun& main, const DynamicsFrame& fr);

  // The final velocities the main run is measured against ([expect], else the finest step's
  // run; `against` names it, "" : none) and the velocity error metric against them.
  std::vector<std::optional<RefState>> velocity_reference(const std::string& name,
                                                          const DynRun& main, const StudyRuns& sw,
                                                          const DynamicsFrame& fr,
                                                          std::string& against);

  // The same impact with first contact 1/3 and 2/3 of a step later (the headline stays the
  // scene as written), and the cause of a miss.
  void contact_phases(const std::string& name, const DynRun& main, const DynamicsFrame& fr,
                      Json& bj);

  // State divergence over time: how far any point of a body is from where the finest-step run
  // puts it at the same sample time, |dx| + (size / 2) * rotation angle (an upper bound),
  // relative to the body's size.
  void trajectory_divergence(const std::string& name, const DynRun& main, const StudyRuns& sw,
                             const DynamicsFrame& fr);

  // Conservation: momentum (where it is an invariant), energy against what e allows.
  void conservation(const std::string& name, const std::vector<BodyFinal>& f,
                    const DynamicsFrame& fr);

  std::string primary_check() const {
    if (scene_.has_check(CheckKind::Impulse)) return "impulse";
    if (scene_.has_check(CheckKind::Trajectory)) return "trajectory";
    return "stability";
  }

  void check_expect_bodies(const std::string& name, const std::vector<BodyFinal>& finals);

  // A reference outside the [expect] tolerance: a disagreement when its velocity error is above
  // kMarkVelocityErr (or only positions are expected), else a deviation.
  void mark_expect_disagreement(const std::string& name, const std::vector<BodyFinal>& finals,
                                double velocity_err);

  // Stability on stiff and extreme scenes: non-finite states, energy drift, momentum drift,
  // maximum penetration (whole run and at rest), tunnelling, jitter at rest, and a verdict.
  // `study_step`: a run at another step of the scene's dt study: its verdict goes to the JSON's
  // `stability_dt_study` (and the report's table), not to the metrics.
  void stability(const std::string& name, const DynRun& run, const DynamicsFrame& fr,
                 bool study_step = false);

  // The deepest exact overlap of every finite sample; a cached reference run's overlaps are
  // cached with it (they cost more than the run).
  std::vector<double> sample_overlaps(const DynRun& run, const StabilityGeometry& geo);

  // -- mass ------------------------------------------------------------------------------------
  // What each library computes by itself from the same hull (Bullet's bounding-box inertia,
  // MuJoCo's mesh inertia, FCL's Convex integrals) and the seed's vertex model, against the
  // exact uniform-density values. Every backend still runs with the exact values.
  void mass_check();

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
  Json stability_dt_study_json_;  // per backend: the verdicts at the dt study's other steps
};

}  // namespace rbx::eval_detail
