// A scene library evaluated over MPI ranks and threads, results back in scene order on rank 0.
#include "comparisons/eval/scene_batch.h"

namespace rbx {

namespace {

// A scene's evaluation as text for the ranks' exchange (ParallelRun::map) and back; doubles go
// through JSON's shortest round-trip form, so rank 0 rebuilds the very same numbers.
std::string encode_evaluation(const SceneEvaluation& ev) {
  Json j;
  j["family"] = ev.family;
  j["json"] = ev.json;
  j["metrics"] = Json::array();
  for (const Metric& m : ev.metrics)
    j["metrics"].push_back({m.check, m.backend, m.pair, m.name, m.value, m.against});
  j["sweep"] = Json::array();
  for (const SweepPoint& p : ev.sweep)
    j["sweep"].push_back({p.backend, p.kind, p.dt, p.error, p.against, p.budget, p.timing.median_s,
                          p.timing.q25_s, p.timing.q75_s, p.timing.calls, p.timing.rounds,
                          p.timing.cold_s});
  j["skipped"] = ev.skipped;
  j["expect_failures"] = ev.expect_failures;
  j["expect_checked"] = ev.expect_checked;
  j["expect_unchecked"] = ev.expect_unchecked;
  j["expect_known"] = ev.expect_known;
  j["disagreements"] = ev.disagreements;
  j["deviations"] = ev.deviations;
  j["causes"] = Json::array();
  for (const Cause& c : ev.causes)
    j["causes"].push_back({c.backend, c.scene, c.kind, c.detail, c.check});
  return j.dump();
}

SceneEvaluation decode_evaluation(const std::string& text) {
  const Json j = Json::parse(text);
  SceneEvaluation ev;
  ev.family = j["family"];
  ev.json = j["json"];
  for (const Json& m : j["metrics"]) ev.metrics.push_back({m[0], m[1], m[2], m[3], m[4], m[5]});
  for (const Json& p : j["sweep"])
    ev.sweep.push_back(
        {p[0], p[1], p[2], Timing{p[6], p[7], p[8], p[9], p[10], p[11]}, p[3], p[4], p[5]});
  ev.skipped = j["skipped"].get<std::vector<std::string>>();
  ev.expect_failures = j["expect_failures"].get<std::vector<std::string>>();
  ev.expect_checked = j["expect_checked"];
  ev.expect_unchecked = j["expect_unchecked"].get<std::vector<std::string>>();
  ev.expect_known = j["expect_known"];
  ev.disagreements = j["disagreements"].get<std::vector<std::string>>();
  ev.deviations = j["deviations"].get<std::vector<std::string>>();
  for (const Json& c : j["causes"]) ev.causes.push_back({c[0], c[1], c[2], c[3], c[4]});
  read_runs(ev);
  return ev;
}

}  // namespace

std::vector<SceneEvaluation> evaluate_scenes(ParallelRun& par, const std::vector<Scene>& scenes,
                                             const HarnessOptions& opt,
                                             const std::function<void(size_t)>& on_done) {
  const std::vector<std::string> raw = par.map(
      scenes.size(), [&](size_t i) { return encode_evaluation(evaluate_scene(scenes[i], opt)); },
      on_done);
  std::vector<SceneEvaluation> evs;
  if (!par.root()) return evs;
  for (const std::string& r : raw) evs.push_back(decode_evaluation(r));
  return evs;
}

}  // namespace rbx
