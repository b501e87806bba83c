#include "comparisons/eval/trajectory.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace rbx {

size_t frame_budget(size_t moving_bodies) {
  const size_t by_numbers = kFrameNumberBudget / (7 * std::max<size_t>(moving_bodies, 1));
  return std::max<size_t>(2, std::min(kMaxFrames, by_numbers));
}

double round_sig5(double x) {
  if (x == 0.0 || !std::isfinite(x)) return x;
  const double scale = std::pow(10.0, 4 - static_cast<int>(std::floor(std::log10(std::abs(x)))));
  return std::round(x * scale) / scale;
}

namespace {

/// One moving body's pose in a frame: x, y, z, qw, qx, qy, qz.
using FramePose = std::array<double, 7>;

/// The pose a fraction `s` of the way from `pa` to `pb`, as the replay page draws it:
/// positions linearly, quaternions by normalised lerp on the short arc.
FramePose interpolate(const FramePose& pa, const FramePose& pb, double s) {
  FramePose out;
  for (int k = 0; k < 3; ++k) out[k] = pa[k] + (pb[k] - pa[k]) * s;
  double dot = 0.0;
  for (int k = 3; k < 7; ++k) dot += pa[k] * pb[k];
  const double sign = dot < 0.0 ? -1.0 : 1.0;
  double norm = 0.0;
  for (int k = 3; k < 7; ++k) {
    out[k] = pa[k] + (sign * pb[k] - pa[k]) * s;
    norm += out[k] * out[k];
  }
  norm = std::sqrt(norm);
  for (int k = 3; k < 7; ++k) out[k] /= norm > 0.0 ? norm : 1.0;
  return out;
}

/// True when every frame strictly between `a` and `b` is reproduced by interpolating a and b
/// within `pos_tol` (m) and kKeyFrameTolerance per quaternion component (either sign).
bool interpolable(const std::vector<double>& time, const std::vector<std::vector<FramePose>>& poses,
                  size_t a, size_t b, double pos_tol) {
  for (size_t i = a + 1; i < b; ++i) {
    const double s = (time[i] - time[a]) / (time[b] - time[a]);
    for (const std::vector<FramePose>& body : poses) {
      const FramePose p = interpolate(body[a], body[b], s);
      double same = 0.0, flipped = 0.0, dp = 0.0;
      for (int k = 0; k < 3; ++k) dp = std::max(dp, std::abs(p[k] - body[i][k]));
      for (int k = 3; k < 7; ++k) {
        same = std::max(same, std::abs(p[k] - body[i][k]));
        flipped = std::max(flipped, std::abs(p[k] + body[i][k]));
      }
      if (dp > pos_tol || std::min(same, flipped) > kKeyFrameTolerance) return false;
    }
  }
  return true;
}

/// `x` on the decimal grid of step 1 / `per_unit` (a power of ten, so that the shortest
/// decimal form of the result is the grid value; no negative zero).
double on_grid(double x, double per_unit) {
  const double r = std::round(x * per_unit) / per_unit;
  return r == 0.0 ? 0.0 : r;
}

}  // namespace

Json trajectory_json(const std::vector<StateSample>& samples, const std::vector<RigidBody>& inputs,
                     size_t max_frames) {
  if (samples.empty()) return Json::object();
  // Evenly spaced sample indices, first and last included.
  std::vector<size_t> picks;
  const size_t n = samples.size(), frames = std::min(n, std::max<size_t>(max_frames, 2));
  for (size_t k = 0; k < frames; ++k) {
    const size_t i =
        frames == 1
            ? 0
            : static_cast<size_t>(std::llround(static_cast<double>(k) * (n - 1) / (frames - 1)));
    if (picks.empty() || picks.back() != i) picks.push_back(i);
  }
  // The moving bodies' poses at the picks (names in the first sample's order).
  std::vector<std::string> names;
  for (const BodyFinal& s : samples.front().bodies) {
    const auto in = std::find_if(inputs.begin(), inputs.end(),
                                 [&](const RigidBody& b) { return b.name == s.name; });
    if (in == inputs.end() || !in->is_static) names.push_back(s.name);
  }
  std::vector<double> time;
  std::vector<std::vector<FramePose>> poses(names.size());
  double extent = 0.0;
  for (size_t i : picks) {
    time.push_back(samples[i].time);
    for (size_t j = 0; j < names.size(); ++j) {
      const auto s = std::find_if(samples[i].bodies.begin(), samples[i].bodies.end(),
                                  [&](const BodyFinal& f) { return f.name == names[j]; });
      FramePose p{};
      if (s != samples[i].bodies.end()) {
        const Quat q = s->orientation.normalized();
        p = {s->position.x(), s->position.y(), s->position.z(), q.w(), q.x(), q.y(), q.z()};
      } else if (!poses[j].empty()) {
        p = poses[j].back();
      }
      for (int k = 0; k < 3; ++k) extent = std::max(extent, std::abs(p[k]));
      poses[j].push_back(p);
    }
  }
  // Key frames: from each kept frame, reach as far as interpolation holds (greedy).
  const double pos_tol = kKeyFrameTolerance * std::max(extent, 1e-9);
  std::vector<size_t> keys = {0};
  for (size_t i = 1; i + 1 < time.size(); ++i)
    if (!interpolable(time, poses, keys.back(), i + 1, pos_tol)) keys.push_back(i);
  if (time.size() > 1) keys.push_back(time.size() - 1);
  // Rounded output: positions on a decimal grid of 1e-4..1e-5 of the extent.
  const double per_unit = std::pow(10.0, 4.0 - std::floor(std::log10(std::max(extent, 1e-9))));
  Json jt = Json::array();
  Json bodies = Json::object();
  for (size_t k : keys) jt.push_back(round_sig5(time[k]));
  for (size_t j = 0; j < names.size(); ++j) {
    Json frames_json = Json::array();
    for (size_t k : keys) {
      const FramePose& p = poses[j][k];
      frames_json.push_back({on_grid(p[0], per_unit), on_grid(p[1], per_unit),
                             on_grid(p[2], per_unit), on_grid(p[3], 1e5), on_grid(p[4], 1e5),
                             on_grid(p[5], 1e5), on_grid(p[6], 1e5)});
    }
    bodies[names[j]] = frames_json;
  }
  return {{"time", jt}, {"bodies", bodies}};
}

namespace {

// The scene's `bodies`: per body and mass property, the value most backends report (ties: the
// first backend's); each backend's body entry then drops the properties equal to it.
void share_mass_properties(Json& scene) {
  Json shared = Json::object();
  for (const auto& [backend, b] : scene["backends"].items()) {
    if (!b.contains("bodies") || !b["bodies"].is_object()) continue;
    for (const auto& [body, entry] : b["bodies"].items())
      for (const char* key : kMassProperties) {
        if (!entry.contains(key)) continue;
        if (!shared.contains(body)) shared[body] = Json::object();
        if (shared[body].contains(key)) continue;
        // Count, over every backend, who reports this value; keep the first value with the most.
        size_t best = 0;
        Json best_value;
        for (const auto& [first, fb] : scene["backends"].items()) {
          if (!fb.contains("bodies") || !fb["bodies"].contains(body) ||
              !fb["bodies"][body].contains(key))
            continue;
          const Json& v = fb["bodies"][body][key];
          size_t n = 0;
          for (const auto& [other, ob] : scene["backends"].items())
            n += ob.contains("bodies") && ob["bodies"].contains(body) &&
                 ob["bodies"][body].contains(key) && ob["bodies"][body][key] == v;
          if (n > best) best = n, best_value = v;
        }
        shared[body][key] = best_value;
      }
  }
  if (shared.empty()) return;
  for (auto& [backend, b] : scene["backends"].items()) {
    if (!b.contains("bodies") || !b["bodies"].is_object()) continue;
    for (auto& [body, entry] : b["bodies"].items())
      for (const char* key : kMassProperties)
        if (entry.contains(key) && entry[key] == shared[body][key]) entry.erase(key);
  }
  scene["bodies"] = shared;
}

}  // namespace

Json results_scene_json(const Json& scene_result) {
  Json j = scene_result;
  j.erase("metrics");
  j.erase("error_vs_runtime");
  if (!j.contains("backends")) return j;
  share_mass_properties(j);
  for (auto& [name, b] : j["backends"].items()) {
    if (!b.contains("contacts") || !b["contacts"].is_array()) continue;
    const size_t total = b["contacts"].size();
    b["contacts_total"] = total;
    if (total > kResultsMaxEvents) {
      Json kept(b["contacts"].begin(), b["contacts"].begin() + kResultsMaxEvents);
      b["contacts"] = kept;
      b["contacts_truncated"] = true;
    }
  }
  return j;
}

}  // namespace rbx
