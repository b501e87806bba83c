// A scene library evaluated over MPI ranks and threads, results back in scene order on rank 0.
#include "comparisons/eval/scene_batch.h"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace rbx {

namespace {

// A scene's evaluation as bytes for the ranks' exchange (ParallelRun::map) and back: JSON in its
// binary form (CBOR), whose doubles are their own bits, so rank 0 rebuilds the very same
// numbers without printing and reading them back as text (most of the exchange's cost).
std::string encode_evaluation(const SceneEvaluation& ev) {
  Json j;
  j["family"] = ev.family;
  j["json"] = ev.json;
  j["metrics"] = Json::array();
  for (const Metric& m : ev.metrics)
    j["metrics"].push_back({m.check, m.backend, m.pair, m.name, m.value, m.against});
  j["error_vs_runtime"] = Json::array();
  for (const ErrorRuntimePoint& p : ev.error_vs_runtime)
    j["error_vs_runtime"].push_back({p.backend, p.kind, p.dt, p.error, p.against, p.budget,
                                     p.timing.median_s, p.timing.q25_s, p.timing.q75_s,
                                     p.timing.calls, p.timing.rounds, p.timing.cold_s});
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
  const std::vector<std::uint8_t> bytes = Json::to_cbor(j);
  return std::string(bytes.begin(), bytes.end());
}

SceneEvaluation decode_evaluation(const std::string& bytes) {
  const Json j = Json::from_cbor(bytes);
  SceneEvaluation ev;
  ev.family = j["family"];
  ev.json = j["json"];
  for (const Json& m : j["metrics"]) ev.metrics.push_back({m[0], m[1], m[2], m[3], m[4], m[5]});
  for (const Json& p : j["error_vs_runtime"])
    ev.error_vs_runtime.push_back(
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

// A rough cost of evaluating a scene: its steps times the pairs its bodies make. Only the order
// it gives matters.
double cost_estimate(const Scene& s) {
  const double n = static_cast<double>(s.bodies.size());
  return (static_cast<double>(s.sim.steps()) + 1.0) * n * n;
}

// The order the scenes are handed out in: dealt, costliest first, round-robin over the ranks'
// blocks (ParallelRun::map gives each rank a block of the order, its threads take chunks as
// they come free). A few long scenes started last left one core to run them alone while the
// other idled; started first, they overlap the many short ones.
std::vector<size_t> hand_out_order(const std::vector<Scene>& scenes, int ranks) {
  std::vector<size_t> by_cost(scenes.size());
  for (size_t i = 0; i < by_cost.size(); ++i) by_cost[i] = i;
  std::vector<double> cost(scenes.size());
  for (size_t i = 0; i < scenes.size(); ++i) cost[i] = cost_estimate(scenes[i]);
  std::stable_sort(by_cost.begin(), by_cost.end(),
                   [&](size_t a, size_t b) { return cost[a] > cost[b]; });
  std::vector<size_t> order;
  const size_t r = static_cast<size_t>(std::max(1, ranks));
  for (size_t k = 0; k < r; ++k)
    for (size_t i = k; i < by_cost.size(); i += r) order.push_back(by_cost[i]);
  return order;
}

}  // namespace

std::vector<SceneEvaluation> evaluate_scenes(ParallelRun& par, const std::vector<Scene>& scenes,
                                             const HarnessOptions& opt,
                                             const std::function<void(size_t)>& on_done) {
  const std::vector<size_t> order = hand_out_order(scenes, par.ranks());
  const std::vector<std::string> raw = par.map(
      scenes.size(),
      [&](size_t k) { return encode_evaluation(evaluate_scene(scenes[order[k]], opt)); },
      [&](size_t k) {
        if (on_done) on_done(order[k]);
      });
  std::vector<SceneEvaluation> evs;
  if (!par.root()) return evs;
  // Back in scene order: what comes out is the same for any order of evaluation.
  evs.resize(scenes.size());
  for (size_t k = 0; k < raw.size(); ++k) evs[order[k]] = decode_evaluation(raw[k]);
  return evs;
}

}  // namespace rbx
