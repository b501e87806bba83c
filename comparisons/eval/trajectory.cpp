#include "comparisons/eval/trajectory.h"

#include <algorithm>
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
  Json time = Json::array();
  Json bodies = Json::object();
  for (size_t i : picks) {
    time.push_back(round_sig5(samples[i].time));
    for (const BodyFinal& s : samples[i].bodies) {
      const auto in = std::find_if(inputs.begin(), inputs.end(),
                                   [&](const RigidBody& b) { return b.name == s.name; });
      if (in != inputs.end() && in->is_static) continue;
      const Quat q = s.orientation.normalized();
      bodies[s.name].push_back({round_sig5(s.position.x()), round_sig5(s.position.y()),
                                round_sig5(s.position.z()), round_sig5(q.w()), round_sig5(q.x()),
                                round_sig5(q.y()), round_sig5(q.z())});
    }
  }
  return {{"time", time}, {"bodies", bodies}};
}

Json results_scene_json(const Json& scene_result) {
  Json j = scene_result;
  if (!j.contains("backends")) return j;
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
