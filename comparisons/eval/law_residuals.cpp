#include "comparisons/eval/law_residuals.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "comparisons/eval/metrics.h"
#include "engine/polyhedron.h"
#include "reference/dynamics_recorder.h"

namespace rbx {

double LawScales::of(Law law) const {
  switch (law) {
    case Law::Penetration:
      return length;
    case Law::Pulling:
    case Law::Cone:
      return mass * speed;
    case Law::Complementarity:
    case Law::Dissipation:
      return mass * speed * speed;
  }
  return 1.0;
}

LawScales law_scales(const Scene& scene) {
  LawScales s;
  double length = std::numeric_limits<double>::infinity();
  double mass = std::numeric_limits<double>::infinity();
  double speed = 0.0;
  for (const RigidBody& b : make_bodies(scene)) {
    if (b.is_static) continue;
    const double size = shape_size(*b.shape);
    length = std::min(length, size);
    mass = std::min(mass, b.mass);
    // The fastest point: the centre's speed and the spin at half the size.
    speed = std::max(speed, b.velocity.norm() + 0.5 * size * b.angular_velocity.norm());
  }
  if (!std::isfinite(length)) return s;  // nothing moves
  s.length = length;
  s.mass = mass;
  // At least the speed of a fall through the smallest size: a resting scene still has one.
  s.speed = std::max(speed, std::sqrt(scene.sim.gravity.norm() * length));
  if (!(s.speed > 0.0)) s.speed = 1.0;
  return s;
}

SceneLaws scene_laws(const Scene& scene, const SceneEvaluation& ev, const std::string& backend) {
  SceneLaws s;
  if (!ev.json.contains("backends") || !ev.json["backends"].contains(backend)) return s;
  const Json& bj = ev.json["backends"][backend];
  if (!bj.contains("contact_laws")) return s;
  const Json& laws = bj["contact_laws"];
  const LawScales scales = law_scales(scene);
  if (!laws.value("measured", false)) {
    if (!laws.contains("penetration")) return s;
    const int pen = static_cast<int>(Law::Penetration);
    s.penetration_only = true;
    s.contacts = laws["contacts"].get<long>();
    s.worst[pen] = laws["penetration"]["worst"].get<double>();
    s.median[pen] = laws["penetration"]["median"].get<double>();
    s.relative[pen] = s.worst[pen] / scales.length;
    return s;
  }
  s.measured = true;
  s.contacts = laws["contacts"].get<long>();
  for (Law law : kAllLaws) {
    const int l = static_cast<int>(law);
    s.worst[l] = laws[to_string(law)]["worst"].get<double>();
    s.median[l] = laws[to_string(law)]["median"].get<double>();
    s.relative[l] = s.worst[l] / scales.of(law);
  }
  return s;
}

std::pair<Law, double> worst_relative(const SceneLaws& s) {
  std::pair<Law, double> w{Law::Penetration, s.relative[0]};
  for (Law law : kAllLaws)
    if (s.relative[static_cast<int>(law)] > w.second) w = {law, s.relative[static_cast<int>(law)]};
  return w;
}

std::vector<LawRow> law_rows(const std::vector<Scene>& scenes,
                             const std::vector<SceneEvaluation>& evs,
                             const std::vector<std::string>& backends) {
  std::vector<std::string> families;
  for (const SceneEvaluation& ev : evs)
    if (std::find(families.begin(), families.end(), ev.family) == families.end())
      families.push_back(ev.family);
  std::vector<LawRow> rows;
  for (const std::string& family : families)
    for (const std::string& b : backends) {
      LawRow row;
      row.backend = b;
      row.family = family;
      std::array<std::vector<double>, kLaws> medians;
      for (size_t i = 0; i < evs.size(); ++i) {
        const SceneEvaluation& ev = evs[i];
        if (ev.family != family || !ev.json["backends"].contains(b)) continue;
        const Json& bj = ev.json["backends"][b];
        if (bj.value("status", "") != "ok" || !bj.contains("contact_laws")) continue;
        const SceneLaws s = scene_laws(scenes[i], ev, b);
        if (!s.measured) {
          ++row.unmeasured;
          if (s.penetration_only)
            row.penetration_only =
                std::max(row.penetration_only, s.relative[static_cast<int>(Law::Penetration)]);
          continue;
        }
        ++row.scenes;
        row.contacts += s.contacts;
        for (int l = 0; l < kLaws; ++l) {
          row.worst[l] = std::max(row.worst[l], s.worst[l]);
          medians[l].push_back(s.median[l]);
          if (s.relative[l] > row.relative[l] || row.worst_scene[l].empty()) {
            row.relative[l] = std::max(row.relative[l], s.relative[l]);
            row.worst_scene[l] = family + "/" + scenes[i].name;
          }
        }
      }
      if (row.scenes == 0 && row.unmeasured == 0) continue;
      for (int l = 0; l < kLaws; ++l)
        if (!medians[l].empty()) row.median[l] = median_of(medians[l]);
      rows.push_back(std::move(row));
    }
  return rows;
}

}  // namespace rbx
