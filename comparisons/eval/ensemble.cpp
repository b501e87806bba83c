#include "comparisons/eval/ensemble.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <numeric>

#include "comparisons/eval/contact_eval.h"
#include "comparisons/eval/explore.h"
#include "comparisons/eval/metrics.h"
#include "comparisons/eval/select_backends.h"
#include "reference/result_codec.h"

namespace rbx {

namespace {

// A Gaussian vector of independent components with standard deviation `sd` (Box-Muller).
Vec3 gaussian(SampleRng& rng, double sd) {
  Vec3 v;
  for (int i = 0; i < 3; ++i) {
    const double u = 1.0 - rng.uniform();  // in (0, 1]: the logarithm is finite
    v[i] = sd * std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * M_PI * rng.uniform());
  }
  return v;
}

// The rotation by the rotation vector w.
Quat rotation_by(const Vec3& w) {
  const double angle = w.norm();
  if (!(angle > 0.0)) return Quat::Identity();
  return Quat(Eigen::AngleAxisd(angle, w / angle));
}

// The width of the 5-95 % range of values.
double range_5_95(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return sorted_quantile(values, 0.95) - sorted_quantile(values, 0.05);
}

// Root mean square distance of vectors from their mean, and the widest 5-95 % coordinate range.
std::pair<double, double> vector_spread(const std::vector<Vec3>& v) {
  if (v.empty()) return {0.0, 0.0};
  Vec3 mean = Vec3::Zero();
  for (const Vec3& x : v) mean += x;
  mean /= static_cast<double>(v.size());
  double sum = 0.0;
  for (const Vec3& x : v) sum += (x - mean).squaredNorm();
  double widest = 0.0;
  for (int i = 0; i < 3; ++i) {
    std::vector<double> c;
    for (const Vec3& x : v) c.push_back(x[i]);
    widest = std::max(widest, range_5_95(std::move(c)));
  }
  return {std::sqrt(sum / static_cast<double>(v.size())), widest};
}

// Root mean square angle of orientations from their mean (the normalised sum, each taken in the
// first one's hemisphere: q and -q are one orientation), and the 5-95 % range of that angle.
std::pair<double, double> orientation_spread(const std::vector<Quat>& q) {
  if (q.empty()) return {0.0, 0.0};
  Eigen::Vector4d sum = Eigen::Vector4d::Zero();
  for (const Quat& x : q) sum += (x.coeffs().dot(q[0].coeffs()) < 0 ? -1.0 : 1.0) * x.coeffs();
  if (!(sum.norm() > 0.0)) return {M_PI, M_PI};
  const Eigen::Vector4d mean = sum.normalized();
  std::vector<double> angles;
  double squares = 0.0;
  for (const Quat& x : q) {
    const double c = std::min(1.0, std::abs(x.coeffs().dot(mean)));
    angles.push_back(2.0 * std::acos(c));
    squares += angles.back() * angles.back();
  }
  return {std::sqrt(squares / static_cast<double>(q.size())), range_5_95(angles)};
}

// One backend and step of the ensemble's items: copy k's final states and contact sequence.
struct CopyRun {
  Status status = Status::Ok;
  std::string message;
  std::vector<BodyFinal> finals;
  std::string sequence;
};

std::string encode_copy(const CopyRun& c) {
  ByteWriter w;
  w.io(c.status, c.message, c.sequence);
  w.io_list(c.finals, [](ByteWriter& x, const BodyFinal& b) {
    x.io(b.name, b.position, b.orientation, b.velocity, b.angular_velocity);
  });
  return w.str();
}

CopyRun decode_copy(const std::string& bytes) {
  CopyRun c;
  ByteReader r(bytes);
  r.io(c.status, c.message, c.sequence);
  r.io_list(c.finals, [](ByteReader& x, BodyFinal& b) {
    x.io(b.name, b.position, b.orientation, b.velocity, b.angular_velocity);
  });
  return c;
}

// The states of the copies that ran to the end.
CopyStates finished(const std::vector<CopyRun>& runs) {
  CopyStates states;
  for (const CopyRun& c : runs)
    if (c.status == Status::Ok) states.push_back(c.finals);
  return states;
}

// The ratio of two spreads, 0 when the denominator is 0.
double ratio(double num, double den) { return den > 0.0 ? num / den : 0.0; }

// One backend's summary from its copies' runs at the scene's step (and at dt / 10).
BackendEnsemble summarise(const Scene& scene, const std::string& name, const StateSpread& input,
                          const std::vector<CopyRun>& runs, const std::vector<CopyRun>& fine) {
  BackendEnsemble b;
  b.backend = name;
  std::map<std::string, long> sequences;
  for (const CopyRun& c : runs) {
    if (c.status != Status::Ok) {
      if (b.failed++ == 0) b.first_failure = c.message;
      continue;
    }
    ++b.runs;
    ++sequences[c.sequence];
  }
  const CopyStates states = finished(runs);
  b.spread = state_spread(scene, states);
  b.amplification = ratio(b.spread.position, input.position);
  b.velocity_amplification = ratio(b.spread.velocity, input.velocity);
  b.sequences.assign(sequences.begin(), sequences.end());
  std::stable_sort(b.sequences.begin(), b.sequences.end(),
                   [](const auto& u, const auto& w) { return u.second > w.second; });
  b.clusters = cluster_count(scene, states);
  // The scatter: the moving body whose final position spreads most.
  double widest = -1.0;
  for (size_t i = 0; i < scene.bodies.size(); ++i) {
    if (scene.bodies[i].is_static) continue;
    const double sp = state_spread(scene, states, static_cast<int>(i)).position;
    if (sp <= widest) continue;
    widest = sp;
    b.scatter_body = scene.bodies[i].name;
    b.scatter.clear();
    for (const std::vector<BodyFinal>& c : states) b.scatter.push_back(c[i].position);
  }
  if (!fine.empty()) {
    b.step_tested = true;
    b.fine_spread = state_spread(scene, finished(fine));
    b.step_ratio = ratio(b.fine_spread.position, b.spread.position);
    // A spread that stays (within a factor of two) when the step shrinks ten times is the
    // physics'; one that shrinks or grows with the step is the engine's. No spread: no class.
    const bool stays = b.step_ratio >= 0.5 && b.step_ratio <= 2.0;
    b.verdict = b.spread.position > 0.0 ? (stays ? "physics" : "engine") : "none";
  }
  return b;
}

}  // namespace

Scene nudged_copy(const Scene& scene, const Nudge& nudge, uint64_t seed, uint64_t index) {
  Scene copy = scene;
  SampleRng rng(seed, index);
  for (BodySpec& b : copy.bodies) {
    if (b.is_static) continue;
    b.position += gaussian(rng, nudge.position);
    b.orientation = (rotation_by(gaussian(rng, nudge.orientation)) * b.orientation).normalized();
    b.velocity += gaussian(rng, nudge.velocity);
    b.angular_velocity += gaussian(rng, nudge.angular_velocity);
  }
  return copy;
}

std::string contact_sequence(const std::vector<CollisionEvent>& events) {
  std::vector<std::string> seen;
  for (const CollisionEvent& e : events) {
    const std::string item = e.body_a + "-" + e.body_b + ":" + e.contact.feature;
    if (std::find(seen.begin(), seen.end(), item) == seen.end()) seen.push_back(item);
  }
  if (seen.empty()) return "none";
  std::string text = seen[0];
  for (size_t i = 1; i < seen.size(); ++i) text += " > " + seen[i];
  return text;
}

StateSpread state_spread(const Scene& scene, const CopyStates& copies, int only) {
  StateSpread s;
  for (size_t i = 0; i < scene.bodies.size(); ++i) {
    if (scene.bodies[i].is_static || (only >= 0 && static_cast<int>(i) != only)) continue;
    std::vector<Vec3> p, v, w;
    std::vector<Quat> q;
    for (const std::vector<BodyFinal>& c : copies) {
      p.push_back(c.at(i).position);
      q.push_back(c.at(i).orientation);
      v.push_back(c.at(i).velocity);
      w.push_back(c.at(i).angular_velocity);
    }
    const auto [ps, pr] = vector_spread(p);
    const auto [qs, qr] = orientation_spread(q);
    const auto [vs, vr] = vector_spread(v);
    const auto [ws, wr] = vector_spread(w);
    s.position = std::max(s.position, ps);
    s.position_range = std::max(s.position_range, pr);
    s.orientation = std::max(s.orientation, qs);
    s.orientation_range = std::max(s.orientation_range, qr);
    s.velocity = std::max(s.velocity, vs);
    s.velocity_range = std::max(s.velocity_range, vr);
    s.angular_velocity = std::max(s.angular_velocity, ws);
    s.angular_velocity_range = std::max(s.angular_velocity_range, wr);
  }
  return s;
}

int cluster_count(const Scene& scene, const CopyStates& copies) {
  const size_t n = copies.size();
  if (n == 0) return 0;
  // One vector per copy: every moving body's final position.
  std::vector<std::vector<double>> x(n);
  for (size_t k = 0; k < n; ++k)
    for (size_t i = 0; i < scene.bodies.size(); ++i)
      if (!scene.bodies[i].is_static)
        for (int c = 0; c < 3; ++c) x[k].push_back(copies[k].at(i).position[c]);
  auto distance = [&](size_t a, size_t b) {
    double s = 0.0;
    for (size_t c = 0; c < x[a].size(); ++c) s += (x[a][c] - x[b][c]) * (x[a][c] - x[b][c]);
    return std::sqrt(s);
  };
  std::vector<double> nearest(n, n > 1 ? INFINITY : 0.0);
  for (size_t a = 0; a < n; ++a)
    for (size_t b = 0; b < n; ++b)
      if (a != b) nearest[a] = std::min(nearest[a], distance(a, b));
  std::vector<double> sorted = nearest;
  std::sort(sorted.begin(), sorted.end());
  const double link = 5.0 * sorted_quantile(sorted, 0.5);
  // Single linkage by union-find over the pairs within the link distance.
  std::vector<size_t> root(n);
  std::iota(root.begin(), root.end(), 0);
  std::function<size_t(size_t)> find = [&](size_t a) {
    return root[a] == a ? a : root[a] = find(root[a]);
  };
  for (size_t a = 0; a < n; ++a)
    for (size_t b = a + 1; b < n; ++b)
      if (distance(a, b) <= link) root[find(a)] = find(b);
  std::map<size_t, long> sizes;
  for (size_t a = 0; a < n; ++a) ++sizes[find(a)];
  const long least = std::max<long>(2, static_cast<long>(std::ceil(0.1 * static_cast<double>(n))));
  int clusters = 0;
  for (const auto& [r, size] : sizes) clusters += size >= least ? 1 : 0;
  return std::max(clusters, 1);
}

EnsembleResult run_ensemble(const Scene& scene, const std::vector<std::string>& backends,
                            const EnsembleSettings& settings, const ParallelRun& par) {
  EnsembleResult r;
  r.scene = scene.name;
  r.file = scene.file;
  r.settings = settings;
  r.dt = scene.sim.dt;
  r.duration = scene.sim.duration;
  const size_t copies = static_cast<size_t>(std::max(0L, settings.count));
  const size_t steps = settings.step_test ? 2 : 1;
  // The input spread: every copy's nudged initial state, as the engine's bodies (centre of mass).
  CopyStates initial;
  for (size_t k = 0; k < copies; ++k) {
    std::vector<BodyFinal> states;
    for (const RigidBody& b : make_bodies(nudged_copy(scene, settings.nudge, settings.seed, k)))
      states.push_back({b.name, b.position, b.orientation, b.velocity, b.angular_velocity});
    initial.push_back(std::move(states));
  }
  r.input = state_spread(scene, initial);
  // Item i: backend i / (steps * copies), step (i / copies) % steps (1: dt / 10), copy i % copies.
  const std::vector<std::string> raw =
      par.map(backends.size() * steps * copies, [&](size_t i) -> std::string {
        const std::string& name = backends[i / (steps * copies)];
        const bool fine = (i / copies) % steps == 1;
        const Scene copy = nudged_copy(scene, settings.nudge, settings.seed, i % copies);
        CopyRun c;
        const Backend* b = find_backend(name);
        const TimedDynamics t =
            run_dynamics_isolated(*b, copy, DynamicsOptions{fine ? scene.sim.dt / 10.0 : 0.0});
        c.status = t.result.status;
        c.message = t.result.message;
        c.finals = t.result.finals;
        c.sequence = contact_sequence(t.result.events);
        if (c.status == Status::Ok && c.finals.size() != scene.bodies.size()) {
          c.status = Status::Error;
          c.message = "the run returned no final state for every body";
        }
        return encode_copy(c);
      });
  if (!par.root()) return r;
  for (size_t k = 0; k < backends.size(); ++k) {
    std::vector<CopyRun> runs, fine;
    for (size_t j = 0; j < copies; ++j) runs.push_back(decode_copy(raw[(k * steps) * copies + j]));
    if (settings.step_test)
      for (size_t j = 0; j < copies; ++j)
        fine.push_back(decode_copy(raw[(k * steps + 1) * copies + j]));
    r.backends.push_back(summarise(scene, backends[k], r.input, runs, fine));
  }
  return r;
}

namespace {

Json spread_json(const StateSpread& s) {
  return Json{{"position_m", s.position},
              {"orientation_rad", s.orientation},
              {"velocity_m_s", s.velocity},
              {"angular_velocity_rad_s", s.angular_velocity},
              {"position_range_m", s.position_range},
              {"orientation_range_rad", s.orientation_range},
              {"velocity_range_m_s", s.velocity_range},
              {"angular_velocity_range_rad_s", s.angular_velocity_range}};
}

}  // namespace

std::vector<EnsembleResult> scaled_ensembles(const Scene& scene,
                                             const std::vector<std::string>& backends,
                                             const EnsembleSettings& settings,
                                             const std::vector<double>& factors,
                                             const ParallelRun& par) {
  std::vector<EnsembleResult> out;
  for (double f : factors) {
    EnsembleSettings scaled = settings;
    scaled.step_test = false;
    scaled.nudge = {f * settings.nudge.position, f * settings.nudge.orientation,
                    f * settings.nudge.velocity, f * settings.nudge.angular_velocity};
    out.push_back(run_ensemble(scene, backends, scaled, par));
  }
  return out;
}

Json ensemble_json(const EnsembleResult& r, const std::vector<EnsembleResult>& sizes) {
  Json doc;
  doc["scene"] = r.scene;
  doc["file"] = r.file;
  doc["count"] = r.settings.count;
  doc["seed"] = r.settings.seed;
  doc["dt"] = r.dt;
  doc["duration"] = r.duration;
  doc["perturb"] = Json{{"position", r.settings.nudge.position},
                        {"orientation", r.settings.nudge.orientation},
                        {"velocity", r.settings.nudge.velocity},
                        {"angular_velocity", r.settings.nudge.angular_velocity}};
  doc["input_spread"] = spread_json(r.input);
  Json backends = Json::object();
  for (const BackendEnsemble& b : r.backends) {
    Json j;
    j["runs"] = b.runs;
    j["failed"] = b.failed;
    if (b.failed > 0) j["first_failure"] = b.first_failure;
    j["spread"] = spread_json(b.spread);
    j["amplification"] = b.amplification;
    j["velocity_amplification"] = b.velocity_amplification;
    j["clusters"] = b.clusters;
    Json sequences = Json::array();
    for (const auto& [text, n] : b.sequences)
      sequences.push_back({{"sequence", text}, {"copies", n}});
    j["contact_sequences"] = sequences;
    Json scatter = Json::array();
    for (const Vec3& p : b.scatter) scatter.push_back(to_json(p));
    j["final_positions"] = Json{{"body", b.scatter_body}, {"positions_m", scatter}};
    if (b.step_tested) {
      j["step_test"] = Json{{"dt", r.dt / 10.0},
                            {"spread", spread_json(b.fine_spread)},
                            {"ratio", b.step_ratio},
                            {"verdict", b.verdict}};
    }
    backends[b.backend] = j;
  }
  doc["backends"] = backends;
  if (!sizes.empty()) {
    Json rows = Json::array();
    for (const EnsembleResult& e : sizes) {
      Json spread = Json::object();
      for (const BackendEnsemble& b : e.backends) spread[b.backend] = b.spread.position;
      rows.push_back({{"position_nudge_m", e.settings.nudge.position},
                      {"input_position_m", e.input.position},
                      {"position_m", spread}});
    }
    doc["nudge_sizes"] = rows;
  }
  return doc;
}

void apply_ensemble_table(Scene& scene, EnsembleSettings& settings, bool keep_count) {
  if (!scene.ensemble) return;
  if (!keep_count) settings.count = scene.ensemble->count;
  settings.step_test = settings.step_test || scene.ensemble->step_test;
  if (scene.ensemble->duration > 0) scene.sim.duration = scene.ensemble->duration;
}

void run_scene_ensembles(const std::vector<Scene>& scenes, const std::string& backends,
                         std::vector<SceneEvaluation>& evs, const ParallelRun& par) {
  for (size_t i = 0; i < scenes.size(); ++i) {
    if (!scenes[i].ensemble) continue;
    const std::vector<std::string> names =
        select_backends(scenes[i], backends, Capability::Dynamics);
    if (names.empty()) continue;
    EnsembleSettings settings;
    Scene scene = scenes[i];
    apply_ensemble_table(scene, settings, false);
    const EnsembleResult r = run_ensemble(scene, names, settings, par);
    if (par.root() && i < evs.size()) {
      evs[i].json["ensemble"] = ensemble_json(r);
      evs[i].ensemble = std::make_shared<const EnsembleResult>(r);
    }
  }
}

}  // namespace rbx
